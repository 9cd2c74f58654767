"""Progress on stderr: one tqdm bar per phase of the analysis, whose final count is what the phase stored."""
import sys

from ..analysis.picture import Phase, Progress


class PhaseBars(Progress):
    """A bar per ``Phase``, opened at its first point and closed with the number of points it stored (the
    summary's count). ``enabled=False``: nothing is drawn. Use as a context manager (closes open bars)."""

    def __init__(self, label: str = "", enabled: bool = True):
        self.label, self.enabled, self.bars = label, enabled, {}

    def _bar(self, phase: Phase):
        if phase not in self.bars:
            from tqdm import tqdm

            desc = f"{self.label}: {phase.value}" if self.label else phase.value
            self.bars[phase] = tqdm(desc=desc, unit=" points", file=sys.stderr, leave=True)
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
