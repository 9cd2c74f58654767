"""BLAS threads inside balloon-cg's hot loops only.

The dense systems here are small (a few hundred unknowns at most), where multi-threaded BLAS only adds
synchronisation cost (measured: the SPOM1 M = 0 stability picture took 4.4 s with one BLAS thread and 83 s
with two on a loaded 2-core machine). The entry points of the computation (tracing, stability, two-parameter
continuation) therefore run under ``blas_threads()``: BLAS limited to BALLOON_CG_BLAS_THREADS threads
(default 1) for their duration, restored on exit. Importing balloon_cg changes nothing in the process.
"""
import functools
import os
import threading
from contextlib import contextmanager

_state = threading.local()


@contextmanager
def blas_threads():
    """Limit every loaded BLAS to BALLOON_CG_BLAS_THREADS (default 1) threads; re-entrant (nested calls are free)."""
    if getattr(_state, "depth", 0):
        _state.depth += 1
        try:
            yield
        finally:
            _state.depth -= 1
        return
    from threadpoolctl import threadpool_limits

    with threadpool_limits(int(os.environ.get("BALLOON_CG_BLAS_THREADS", "1")), user_api="blas"):
        _state.depth = 1
        try:
            yield
        finally:
            _state.depth = 0


def limited_blas(function):
    """Decorator: run ``function`` under ``blas_threads()``."""
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with blas_threads():
            return function(*args, **kwargs)
    return wrapper
