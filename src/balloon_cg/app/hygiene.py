"""Pool workers that die with their parent: ``ProcessPoolExecutor(initializer=worker_hygiene, initargs=(pid,))``.

A worker whose parent is killed (SIGKILL, the OOM killer) would otherwise keep computing, blocked on the result
pipe. On Linux the worker asks the kernel for SIGKILL when its parent dies (``prctl(PR_SET_PDEATHSIG)``);
elsewhere a daemon thread polls ``os.getppid()`` once a second. Either way the worker then checks that the parent
it was started by is still its parent (it may have died before the request was made).
"""
import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time

PR_SET_PDEATHSIG = 1
POLL_SECONDS = 1.0


def worker_hygiene(parent_pid: int) -> None:
    """Initializer of a pool worker: exit when the process ``parent_pid`` stops being the parent."""
    if not (sys.platform.startswith("linux") and _pdeathsig()):
        threading.Thread(target=_watch, args=(parent_pid,), daemon=True, name="parent-watchdog").start()
    if os.getppid() != parent_pid:
        os._exit(1)


def _pdeathsig() -> bool:
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        return libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch(parent_pid: int) -> None:
    while os.getppid() == parent_pid:
        time.sleep(POLL_SECONDS)
    os._exit(1)
