"""Exclusive ownership of an output path: ``with claim(path):`` before computing anything for it.

The claim is an advisory ``flock`` on ``.NAME.lock`` beside the output, holding the owner's PID. The kernel
drops the lock when its owner dies (SIGKILL included), so a lock file left by a killed process is stale by
construction and the next claim takes it over; a live owner makes the claim fail at once with
``OutputInUse`` ("in use by PID …"). Forked children inherit the lock until they exit (a sweep's pool
workers die with their parent, app.sweep).

Holding the claim, the owner removes the debris of earlier owners that were killed (``.NAME.<hex>.tmp`` files
of io.hdf5.atomic_file), on entry and on exit.
"""
import contextlib
import errno
import fcntl
import os
import re
from pathlib import Path

from .output import check_folder


class OutputInUse(OSError):
    """Another live process owns this output (exit code 2: wait for it, or choose another output)."""


def lock_path(path) -> Path:
    path = Path(path)
    return path.with_name(f".{path.name}.lock")


def _holder(fd: int) -> str:
    os.lseek(fd, 0, os.SEEK_SET)
    text = os.read(fd, 200).decode("utf-8", "replace").split()
    return text[0] if text else "unknown"


@contextlib.contextmanager
def claim(path, what: str = "balloon-cg"):
    """Own ``path`` for the block (OutputInUse if a live process owns it); debris is removed on entry and exit."""
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    check_folder(path)  # a folder we cannot write in names the output, not the lock file
    lock = lock_path(path)
    while True:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            raise OutputInUse(errno.EBUSY, f"in use by PID {holder} (another balloon-cg writes it; wait for it "
                                           "to finish or choose another output)", str(path)) from None
        # the lock file may have been unlinked by its previous owner between our open and flock: retry on the new one
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(lock))
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    try:
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()} {what}\n".encode())
        remove_debris(path)
        yield path
        remove_debris(path)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(lock)
        os.close(fd)


def debris(path) -> list[Path]:
    """Temporary files of interrupted atomic writes of ``path`` (``.NAME.<hex>.tmp``)."""
    path = Path(path)
    pattern = re.compile(rf"\.{re.escape(path.name)}\.[0-9a-f]+\.tmp")
    if not path.parent.is_dir():
        return []
    return sorted(p for p in path.parent.iterdir() if pattern.fullmatch(p.name))


def remove_debris(path) -> None:
    """Remove ``debris(path)``: only called by the owner of ``path``, so no live writer owns these files."""
    for p in debris(path):
        with contextlib.suppress(FileNotFoundError):
            p.unlink()
