"""Each kernel compiled once across processes: numba's on-disk cache (``cache=True``) has no lock between
processes, so two that need the same uncompiled kernel at once both compile it (the default run's two scenes
compiled the eigensolver's reflections twice, ~3 s each: benchmarks/results/make_run.txt).

``install()`` wraps numba's ``Dispatcher.compile`` for the kernels of balloon_cg that have an on-disk cache: a
signature this process has not compiled is looked up in the cache, and compiled on a miss, under an exclusive
``flock`` on ``<the kernel's cache index>.lock``; a process that waited for it finds the other's result in the
cache and loads it. The locks are taken in the order numba compiles (a kernel, then the kernels it calls, while
the caller's lock is held); kernels do not call themselves or each other in a circle, so no two processes wait
for each other. A lock belongs to an open file: a process that ends, however (Ctrl-C, a kill), releases its locks.
Inside one process numba's own compiler lock is held around the file lock, and a lock this process holds already
(a kernel's second signature typed while its first compiles) is not taken again.
"""
import fcntl
import os
from contextlib import contextmanager

from numba.core import sigutils
from numba.core.compiler_lock import global_compiler_lock
from numba.core.dispatcher import Dispatcher

PACKAGE = __name__.split(".")[0]
_held = {}  # lock path -> depth, in this process (under numba's compiler lock)


def lock_path(dispatcher) -> str | None:
    """``<cache index>.lock`` of a balloon_cg kernel with an on-disk cache (its folder created), else None."""
    cache = getattr(dispatcher, "_cache", None)
    index = getattr(getattr(cache, "_cache_file", None), "_index_path", None)
    if index is None or not dispatcher.py_func.__module__.startswith(PACKAGE + "."):
        return None
    cache._impl.locator.ensure_cache_path()
    return index + ".lock"


@contextmanager
def held(path: str):
    """The exclusive lock on ``path`` (created if missing) for the duration; re-entered freely in this process."""
    if path in _held:
        _held[path] += 1
        try:
            yield
        finally:
            _held[path] -= 1
        return
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        _held[path] = 1
        try:
            yield
        finally:
            del _held[path]
    finally:
        os.close(fd)  # releases the lock


def _compiled_here(dispatcher, sig) -> bool:
    args, _ = sigutils.normalize_signature(sig)
    return tuple(args) in dispatcher.overloads


def install() -> None:
    """Wrap ``Dispatcher.compile`` (module docstring); idempotent."""
    original = Dispatcher.compile
    if getattr(original, "locked", False):
        return

    def compile(self, sig):
        path = None if _compiled_here(self, sig) else lock_path(self)
        if path is None:
            return original(self, sig)
        with global_compiler_lock, held(path):
            return original(self, sig)

    compile.locked, compile.unlocked = True, original
    Dispatcher.compile = compile
