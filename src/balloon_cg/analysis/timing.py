"""Where the time of a run goes: seconds per phase, each phase's own (a phase nested in another, the stability of a
pear branch inside the pear tracing, is charged to itself and paused in the outer), and the total from the start
of the computation to the end of the write, so that the phases and the total are the run a user waits for
(stored in the run file: io.run_file, shown by ``inspect``).
"""
import enum
import time
from contextlib import contextmanager


class Step(enum.StrEnum):
    """The timed phases of a run, in the order they run."""

    TRACE = "trace"  # the primary branch
    STABILITY = "stability"  # the assessment of every point of the axisymmetric branches
    BRANCH_POINTS = "branch points"  # m = 0: detected, located, classified
    PEAR_BRANCHES = "pear branches"  # traced (their stability is STABILITY's)
    FREE_BALLOON = "free balloon"  # the free balloon's primary branch without equator symmetry (its stability is
    #                                STABILITY's)
    CROSSINGS = "m >= 1 crossings"  # the branch points of the non-axisymmetric blocks, located
    SURFACE_BRANCHES = "non-axisymmetric branches"  # on the whole sphere, assessed (as Phase.SURFACE names them)
    SNAP_THROUGHS = "snap-throughs"
    FREQUENCIES = "frequencies"  # [dynamics]: the natural frequencies of every axisymmetric branch
    WRITING = "writing"  # the run file


class Clock:
    """Seconds per Step (``seconds``, exclusive: nested steps pause the outer) since ``start``;
    ``total()`` the seconds since then."""

    def __init__(self):
        self.start = time.perf_counter()
        self.seconds = {}
        self._running = []  # the open steps, innermost last
        self._since = self.start
        self._last = None  # the step entered last

    @property
    def current(self) -> "Step | None":
        """The innermost open step, else the one entered last (None before any)."""
        return self._running[-1] if self._running else self._last

    @contextmanager
    def step(self, step: Step):
        """``with clock.step(Step.X):`` charges the block's time, less that of steps nested in it, to X."""
        self._charge()
        self._running.append(step)
        self._last = step
        try:
            yield
        finally:
            self._charge()
            self._running.pop()

    def _charge(self):
        now = time.perf_counter()
        if self._running:
            top = self._running[-1]
            self.seconds[top] = self.seconds.get(top, 0.0) + now - self._since
        self._since = now

    def total(self) -> float:
        return time.perf_counter() - self.start
