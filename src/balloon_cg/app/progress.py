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
    """A bar per ``Phase``, opened at its first point and closed with the number of points it stored (the
    summary's count). ``enabled``: a progress setting (module docstring); False: no tqdm at all. Use as a
    context manager (closes open bars)."""

    def __init__(self, label: str = "", enabled: bool | None = True):
        self.label, self.enabled, self.bars = label, enabled is not False, {}
        self.disable = tqdm_disable(enabled)

    def _bar(self, phase: Phase):
        if phase not in self.bars:
            from tqdm.auto import tqdm

            desc = f"{self.label}: {phase.value}" if self.label else phase.value
            self.bars[phase] = tqdm(desc=desc, unit=" points", file=sys.stderr, leave=True, disable=self.disable)
        return self.bars[phase]

    def tick(self, phase: Phase) -> None:
        if self.enabled:  # disabled: no tqdm at all (not even its multiprocessing lock)
            self._bar(phase).update()

    def finish(self, phase: Phase, count: int) -> None:
        if not self.enabled or (phase not in self.bars and count == 0):
            return
        bar = self._bar(phase)
        bar.n = count
        bar.refresh()
        bar.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for bar in self.bars.values():
            bar.close()
