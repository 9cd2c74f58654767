"""Cooperative interrupts: SIGINT or SIGTERM asks the computation to stop at its next point.

``with stop_on_signals():`` installs handlers that only set a flag; the continuation driver's callers check
``requested()`` at every point and end their work there (``StopCode.INTERRUPTED``), so what is finished can
still be written. A second signal while the first is pending raises KeyboardInterrupt at once. On exit the
previous handlers are restored and the flag cleared.

A KeyboardInterrupt raised where Python cannot propagate it (inside a weakref callback or a ``__del__``) would be
printed as "Exception ignored in ..." with a traceback; while the handlers are installed it is dropped instead
(``sys.unraisablehook``): its signal has set the flag, which the loops check.
"""
import signal
import sys
import threading
from contextlib import contextmanager

_flag = threading.Event()
SIGNALS = (signal.SIGINT, signal.SIGTERM)


def requested() -> bool:
    """Whether a stop was asked for (by a signal or ``request``)."""
    return _flag.is_set()


def request() -> None:
    _flag.set()


class Interrupted(Exception):
    """Raised by ``check`` where a stop was asked for in the middle of a unit of work (a branch's assessment):
    the unit is abandoned, what was finished before it is kept."""


def check() -> None:
    """Raise ``Interrupted`` if a stop was asked for (``requested()``)."""
    if _flag.is_set():
        raise Interrupted


def _handler(signum, frame):
    if _flag.is_set():
        raise KeyboardInterrupt
    _flag.set()


def _raise(signum, frame):
    _flag.set()  # kept: a KeyboardInterrupt raised inside a callback (a weakref's, a __del__) is only printed
    raise KeyboardInterrupt


@contextmanager
def _handled_by(handler):
    """SIGINT and SIGTERM go to ``handler`` for the duration (main thread only; elsewhere a no-op); on exit the
    previous handlers are restored and the flag cleared."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, handler) for s in SIGNALS}
    hook = sys.unraisablehook
    sys.unraisablehook = _dropping_interrupts(hook)
    try:
        yield
    finally:
        for s, old in previous.items():
            signal.signal(s, old)
        sys.unraisablehook = hook
        _flag.clear()


def _dropping_interrupts(hook):
    """An unraisable hook that drops KeyboardInterrupt (the flag is set) and passes everything else to ``hook``."""
    def unraisable(info):
        if not isinstance(info.exc_value, KeyboardInterrupt):
            hook(info)
    return unraisable


def sigterm_raises():
    """SIGINT and SIGTERM raise KeyboardInterrupt for the duration: for work that stops at once and cleans up in
    ``finally`` blocks rather than at its next point. The signal also sets ``requested()``, for loops to check
    where the exception could have been swallowed."""
    return _handled_by(_raise)


def stop_on_signals():
    """Turn SIGINT/SIGTERM into ``requested()`` for the duration."""
    return _handled_by(_handler)


class Held:
    """``with Held() as held: ... held.start() ...``: from ``start`` to the block's end SIGINT and SIGTERM only set the
    flag (a second signal, the flag set, still raises KeyboardInterrupt at once); the block's end restores the handlers
    and raises KeyboardInterrupt if a signal came meanwhile. For the last short steps of an output that must complete
    once begun (a sweep's view: the member being copied, its table, its rename), whatever the handler around."""

    def __init__(self):
        self.previous, self.came = None, False

    def __enter__(self):
        return self

    def start(self) -> None:
        if threading.current_thread() is threading.main_thread():
            self.previous = {s: signal.signal(s, self._hold) for s in SIGNALS}

    def _hold(self, signum, frame):
        if _flag.is_set():
            raise KeyboardInterrupt
        _flag.set()
        self.came = True

    def __exit__(self, kind, value, traceback):
        if self.previous is not None:
            for s, old in self.previous.items():
                signal.signal(s, old)
        if kind is None and self.came:
            raise KeyboardInterrupt
        return False
