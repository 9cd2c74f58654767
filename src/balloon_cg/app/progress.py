"""Progress on stderr: one tqdm bar per phase of the analysis, whose final count is what the phase stored.

A progress setting is True (drawn), False (nothing) or ``ON_TERMINAL`` (None: drawn only when stderr is a
terminal; tqdm's documented ``disable=None``, off on a non-TTY, so a log file or a pipe gets no carriage
returns and cursor codes). The commands use ``ON_TERMINAL`` unless ``--quiet``.

Where it is drawn (``Display``, from ``tqdm.auto``): in a Jupyter kernel with ipywidgets a widget per phase, replaced
in place by the phase's finished line when it ends (one output per phase, also in a saved notebook); in a kernel
without ipywidgets a text bar per phase (tqdm's meter) in an output of its own, updated in place at most every
TEXT_INTERVAL seconds and replaced by the finished line (no carriage returns or cursor moves: stacked text bars on
a notebook's stderr garble, and tqdm.auto falls back to them there); on a terminal a text bar per phase giving way
to its finished line; elsewhere with progress True (a log file, a pipe) only the finished lines.
"""
import enum
import sys
import time
import warnings

from ..analysis.picture import Phase, Progress
from ..model.compile_notice import jupyter_kernel

ON_TERMINAL = None
TEXT_INTERVAL = 0.5  # seconds between two updates of a notebook's text bar (each is a message to the front end)


def shown(quiet: bool) -> bool | None:
    """A command's progress setting: nothing with --quiet, else drawn when stderr is a terminal."""
    return False if quiet else ON_TERMINAL


def tqdm_disable(progress: bool | None) -> bool | None:
    """tqdm's ``disable`` for a progress setting (None: tqdm disables the bar on a non-TTY)."""
    return None if progress is ON_TERMINAL else not progress


def auto_tqdm():
    """``tqdm.auto.tqdm``: the widget bar in a Jupyter kernel with ipywidgets, else the text bar. Imported without
    tqdm's warning for a kernel without ipywidgets ('IProgress not found'), where ``PhaseBars`` draws its own text
    bars (Display.TEXT)."""
    from tqdm import TqdmWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TqdmWarning)
        from tqdm.auto import tqdm
    return tqdm


class Display(enum.Enum):
    """How progress is drawn (module docstring)."""
    NONE = "none"
    WIDGETS = "widgets"  # a Jupyter kernel with ipywidgets: tqdm.notebook
    TEXT = "text"  # a Jupyter kernel without ipywidgets: tqdm's meter in an output updated in place
    BARS = "bars"  # a terminal: text bars
    LINES = "lines"  # progress asked for where text bars garble: the finished lines only


def display(progress: bool | None, stream) -> Display:
    """The Display of a progress setting on ``stream`` (module docstring)."""
    if progress is False:
        return Display.NONE
    if any(cls.__module__ == "tqdm.notebook" for cls in auto_tqdm().__mro__):
        return Display.WIDGETS
    if jupyter_kernel():
        return Display.TEXT
    if stream.isatty():
        return Display.BARS
    return Display.NONE if progress is ON_TERMINAL else Display.LINES


class PhaseBars(Progress):
    """A bar per ``Phase``, opened at its first point; when the phase finishes it gives way to one clean line,
    'LABEL: PHASE: N points [elapsed]', N the number of points it stored (the summary's count). Phases overlap
    (stability is assessed while pear branches are traced), so their text bars stack; a bar closed in place would
    be redrawn on the first bar's line and leave the tail of the longer one ('…points/s]ts/s]'): ``tqdm.write``
    prints the finished line above the bars still running. A widget or a notebook's text bar is replaced by its
    line (its display updated). ``enabled``: a progress setting (module docstring; drawn as ``display`` says);
    False: no tqdm at all. Use as a context manager (an unfinished phase, at an interrupt, gets its line too)."""

    def __init__(self, label: str = "", enabled: bool | None = True):
        self.label, self.bars, self.handles, self.finished = label, {}, {}, set()
        self.display = display(enabled, sys.stderr)
        self.enabled = self.display != Display.NONE
        self.started, self.counts, self.totals, self.shown = {}, {}, {}, {}

    def _open(self, phase: Phase) -> None:
        """The phase's clock, count and (widgets, text bars) bar, at its first point or total."""
        if phase in self.started:
            return
        self.started[phase], self.counts[phase] = time.monotonic(), 0
        if self.display == Display.BARS:
            self.bars[phase] = auto_tqdm()(desc=self._desc(phase), unit=" points", file=sys.stderr, leave=False)
        elif self.display == Display.WIDGETS:
            from IPython.display import display as show

            bar = auto_tqdm()(desc=self._desc(phase), unit=" points", leave=False, display=False)
            self.bars[phase], self.handles[phase] = bar, show(bar.container, display_id=True)
        elif self.display == Display.TEXT:
            from IPython.display import display as show

            self.shown[phase] = time.monotonic()
            self.handles[phase] = show({"text/plain": self._meter(phase)}, raw=True, display_id=True)

    def _desc(self, phase: Phase) -> str:
        return f"{self.label}: {phase.value}" if self.label else phase.value

    def _meter(self, phase: Phase) -> str:
        """A notebook's text bar of the phase: tqdm's meter (count, fraction and time left where a total is known)."""
        return auto_tqdm().format_meter(self.counts[phase], self.totals.get(phase), time.monotonic() -
                                        self.started[phase], prefix=self._desc(phase), unit=" points")

    def _redraw(self, phase: Phase, now: bool = False) -> None:
        """A notebook's text bar drawn again, at most every TEXT_INTERVAL seconds unless ``now``."""
        if self.display == Display.TEXT and (now or time.monotonic() - self.shown[phase] >= TEXT_INTERVAL):
            self.shown[phase] = time.monotonic()
            self.handles[phase].update({"text/plain": self._meter(phase)}, raw=True)

    def tick(self, phase: Phase) -> None:
        if self.enabled and phase not in self.finished:  # disabled: no tqdm at all (not even its lock)
            self._open(phase)
            self.counts[phase] += 1
            if phase in self.bars:
                self.bars[phase].update()
            self._redraw(phase)

    def expect(self, phase: Phase, count: int) -> None:
        """A total for the phase's bar (its fraction and ETA), grown by ``count``."""
        if self.enabled and phase not in self.finished:
            opened, self.totals[phase] = phase in self.started, self.totals.get(phase, 0) + count
            self._open(phase)
            if opened:
                self._redraw(phase, now=True)
            bar = self.bars.get(phase)
            if bar is not None:
                bar.total = (bar.total or 0) + count
                if phase in self.handles:  # a widget's maximum (tqdm.notebook sets it only in reset)
                    progress = bar.container.children[1]
                    progress.max, progress.bar_style, progress.layout.width = max(bar.total, 1), "", None
                bar.refresh()

    def finish(self, phase: Phase, count: int) -> None:
        if not self.enabled or phase in self.finished or (phase not in self.started and count == 0):
            return
        self._close(phase, count)

    def _close(self, phase: Phase, count: int) -> None:
        """Close the phase's bar and print its finished line (a widget or a notebook's text bar: replaced by it)."""
        self._open(phase)
        self.finished.add(phase)
        elapsed = auto_tqdm().format_interval(time.monotonic() - self.started[phase])
        line = f"{self._desc(phase)}: {count} points [{elapsed}]"
        bar = self.bars.get(phase)
        if bar is not None:
            bar.close()
        if phase in self.handles:
            self.handles[phase].update({"text/plain": line}, raw=True)
        elif bar is not None:
            bar.write(line, file=sys.stderr)
        else:
            print(line, file=sys.stderr, flush=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for phase in list(self.started):
            if phase not in self.finished:
                self._close(phase, self.counts[phase])
