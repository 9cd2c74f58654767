"""Progress on stderr: one tqdm bar per phase of the analysis, whose final count is what the phase stored
(``tqdm.auto``: a widget in a Jupyter notebook).

A progress setting is True (drawn), False (nothing) or ``ON_TERMINAL`` (None: drawn only when stderr is a
terminal; tqdm's documented ``disable=None``, off on a non-TTY, so a log file or a pipe gets no carriage
returns and cursor codes). The commands use ``ON_TERMINAL`` unless ``--quiet``."""
import sys

from ..analysis.picture import Phase, Progress

ON_TERMINAL = None


def shown(quiet: bool) -> bool | None:
    """A command's progress setting: nothing with --quiet, else drawn when stderr is a terminal."""
    return False if quiet else ON_TERMINAL


def tqdm_disable(progress: bool | None) -> bool | None:
    """tqdm's ``disable`` for a progress setting (None: tqdm disables the bar on a non-TTY)."""
    return None if progress is ON_TERMINAL else not progress


class PhaseBars(Progress):
    """A bar per ``Phase``, opened at its first point; when the phase finishes its bar gives way to one clean line,
    'LABEL: PHASE: N points [elapsed]', N the number of points it stored (the summary's count). Phases overlap
    (stability is assessed while pear branches are traced), so their bars stack; a bar closed in place would be
    redrawn on the first bar's line and leave the tail of the longer one ('…points/s]ts/s]'): ``tqdm.write``
    prints the finished line above the bars still running. ``enabled``: a progress setting (module docstring);
    False: no tqdm at all. Use as a context manager (an unfinished phase, at an interrupt, gets its line too)."""

    def __init__(self, label: str = "", enabled: bool | None = True):
        self.label, self.enabled, self.bars, self.finished = label, enabled is not False, {}, set()
        self.disable = tqdm_disable(enabled)

    def _bar(self, phase: Phase):
        if phase not in self.bars:
            from tqdm.auto import tqdm

            self.bars[phase] = tqdm(desc=self._desc(phase), unit=" points", file=sys.stderr, leave=False,
                                    disable=self.disable)
        return self.bars[phase]

    def _desc(self, phase: Phase) -> str:
        return f"{self.label}: {phase.value}" if self.label else phase.value

    def tick(self, phase: Phase) -> None:
        if self.enabled and phase not in self.finished:  # disabled: no tqdm at all (not even its lock)
            self._bar(phase).update()

    def expect(self, phase: Phase, count: int) -> None:
        """A total for the phase's bar (its fraction and ETA), grown by ``count``."""
        if self.enabled and phase not in self.finished:
            bar = self._bar(phase)
            bar.total = (bar.total or 0) + count
            bar.refresh()

    def finish(self, phase: Phase, count: int) -> None:
        if not self.enabled or phase in self.finished or (phase not in self.bars and count == 0):
            return
        self._close(phase, count)

    def _close(self, phase: Phase, count: int) -> None:
        """Close the phase's bar and print its finished line (nothing when the bar is not drawn)."""
        bar = self._bar(phase)
        self.finished.add(phase)
        if bar.disable:  # not drawn (not a terminal): no line either
            bar.close()
            return
        line = f"{self._desc(phase)}: {count} points [{bar.format_interval(bar.format_dict['elapsed'])}]"
        bar.close()
        bar.write(line, file=sys.stderr)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for phase, bar in self.bars.items():
            if phase not in self.finished:
                self._close(phase, bar.n)
