"""Progress on stderr: one tqdm bar per phase of the analysis, whose final count is what the phase stored.

A progress setting is True (drawn), False (nothing) or ``ON_TERMINAL`` (None: drawn only when stderr is a
terminal; tqdm's documented ``disable=None``, off on a non-TTY, so a log file or a pipe gets no carriage
returns and cursor codes). The commands use ``ON_TERMINAL`` unless ``--quiet``.

Where it is drawn (``Display``, from ``tqdm.auto``): in a Jupyter kernel with ipywidgets a widget per phase, replaced
in place by the phase's finished line when it ends (one output per phase, also in a saved notebook); on a terminal a
text bar per phase giving way to its finished line; elsewhere with progress True (a notebook without ipywidgets, a
log file) only the finished lines, since a text bar's carriage returns and cursor moves garble there (a notebook
says why once: NO_WIDGETS).
"""
import enum
import sys
import time
import warnings

from ..analysis.picture import Phase, Progress
from ..model.compile_notice import jupyter_kernel

ON_TERMINAL = None
NO_WIDGETS = ("balloon-cg: progress as one line per finished phase (ipywidgets is not installed: pip install "
              "ipywidgets for live bars)")
_told = []  # NO_WIDGETS printed in this process


def shown(quiet: bool) -> bool | None:
    """A command's progress setting: nothing with --quiet, else drawn when stderr is a terminal."""
    return False if quiet else ON_TERMINAL


def tqdm_disable(progress: bool | None) -> bool | None:
    """tqdm's ``disable`` for a progress setting (None: tqdm disables the bar on a non-TTY)."""
    return None if progress is ON_TERMINAL else not progress


def auto_tqdm():
    """``tqdm.auto.tqdm``: the widget bar in a Jupyter kernel with ipywidgets, else the text bar. Imported without
    tqdm's warning for a kernel without ipywidgets ('IProgress not found'), where ``display`` prints lines instead."""
    from tqdm import TqdmWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TqdmWarning)
        from tqdm.auto import tqdm
    return tqdm


class Display(enum.Enum):
    """How progress is drawn (module docstring)."""
    NONE = "none"
    WIDGETS = "widgets"  # a Jupyter kernel with ipywidgets: tqdm.notebook
    BARS = "bars"  # a terminal: text bars
    LINES = "lines"  # progress asked for where text bars garble: the finished lines only


def display(progress: bool | None, stream) -> Display:
    """The Display of a progress setting on ``stream`` (module docstring)."""
    if progress is False:
        return Display.NONE
    if any(cls.__module__ == "tqdm.notebook" for cls in auto_tqdm().__mro__):
        return Display.WIDGETS
    if stream.isatty():
        return Display.BARS
    return Display.NONE if progress is ON_TERMINAL else Display.LINES


class PhaseBars(Progress):
    """A bar per ``Phase``, opened at its first point; when the phase finishes it gives way to one clean line,
    'LABEL: PHASE: N points [elapsed]', N the number of points it stored (the summary's count). Phases overlap
    (stability is assessed while pear branches are traced), so their text bars stack; a bar closed in place would
    be redrawn on the first bar's line and leave the tail of the longer one ('…points/s]ts/s]'): ``tqdm.write``
    prints the finished line above the bars still running. A widget is replaced by its line (its display updated).
    ``enabled``: a progress setting (module docstring; drawn as ``display`` says); False: no tqdm at all. Use as a
    context manager (an unfinished phase, at an interrupt, gets its line too)."""

    def __init__(self, label: str = "", enabled: bool | None = True):
        self.label, self.bars, self.handles, self.finished = label, {}, {}, set()
        self.display = display(enabled, sys.stderr)
        self.enabled = self.display != Display.NONE
        self.started, self.counts = {}, {}
        if self.display == Display.LINES and jupyter_kernel() and not _told:
            _told.append(True)
            print(NO_WIDGETS, file=sys.stderr, flush=True)

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

    def _desc(self, phase: Phase) -> str:
        return f"{self.label}: {phase.value}" if self.label else phase.value

    def tick(self, phase: Phase) -> None:
        if self.enabled and phase not in self.finished:  # disabled: no tqdm at all (not even its lock)
            self._open(phase)
            self.counts[phase] += 1
            if phase in self.bars:
                self.bars[phase].update()

    def expect(self, phase: Phase, count: int) -> None:
        """A total for the phase's bar (its fraction and ETA), grown by ``count``."""
        if self.enabled and phase not in self.finished:
            self._open(phase)
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
        """Close the phase's bar and print its finished line (a widget: replaced by it)."""
        self._open(phase)
        self.finished.add(phase)
        elapsed = auto_tqdm().format_interval(time.monotonic() - self.started[phase])
        line = f"{self._desc(phase)}: {count} points [{elapsed}]"
        bar = self.bars.get(phase)
        if bar is None:
            print(line, file=sys.stderr, flush=True)
            return
        bar.close()
        if phase in self.handles:
            self.handles[phase].update({"text/plain": line}, raw=True)
        else:
            bar.write(line, file=sys.stderr)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for phase in list(self.started):
            if phase not in self.finished:
                self._close(phase, self.counts[phase])
