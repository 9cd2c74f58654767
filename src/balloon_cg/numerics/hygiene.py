"""Pool workers that die with their parent: ``ProcessPoolExecutor(initializer=worker_hygiene, initargs=(pid,))``
(a sweep's members, ``app.sweep``; the points of a branch, ``workers``).

A worker whose parent is killed (SIGKILL, the OOM killer) would otherwise keep computing, blocked on the result
pipe. On Linux the worker asks the kernel for SIGKILL when the process that started it dies
(``prctl(PR_SET_PDEATHSIG)``: the parent with the fork start method, or the forkserver, which exits
with it); elsewhere a daemon thread polls ``os.getppid()`` once a second. Either way the worker then exits at
once if the parent ``pid`` died before the request was made (also where it is a zombie, not yet reaped).
"""
import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time
from pathlib import Path

PR_SET_PDEATHSIG = 1
POLL_SECONDS = 1.0


def worker_hygiene(parent_pid: int, terminable: bool = True) -> None:
    """Initializer of a pool worker: exit when its parent dies, or now if the process ``parent_pid`` is gone;
    Ctrl-C (SIGINT to the terminal's process group) is left to the parent, which stops the workers itself with
    SIGTERM, whose default (die) is restored here (a forked worker inherits the parent's handlers); not
    ``terminable``: SIGTERM is left to the parent too (which then stops the workers with SIGKILL)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL if terminable else signal.SIG_IGN)
    if not (sys.platform.startswith("linux") and _pdeathsig()):
        threading.Thread(target=_watch, args=(os.getppid(),), daemon=True, name="parent-watchdog").start()
    if not _alive(parent_pid):
        os._exit(1)


def _pdeathsig() -> bool:
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        return libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _alive(pid: int) -> bool:
    """Whether the process ``pid`` runs: a zombie (killed, not yet reaped by its own parent) does not. A worker that
    starts while its parent is one asked for the death signal too late, and ``os.kill`` still finds the pid."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):  # no /proc (not Linux): the pid answered
        return True


def _watch(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(POLL_SECONDS)
    os._exit(1)
