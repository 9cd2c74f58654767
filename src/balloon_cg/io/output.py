"""The one rule for outputs, for every command and every kind of file (run, sweep, curve, image).

- An output is a path to a regular file in an existing folder this process can write in; the folder is checked
  before anything is computed for it.
- An existing output (a file of any kind, or the member store of a sweep written there, ``NAME.members/``) is
  replaced only with ``force`` (``--force``), and never when it is not a regular file (a folder, a FIFO, a
  device) or not writable (read-only, immutable).
- A sweep's member store belongs to its sweep file: writing anything but that sweep over the file removes the
  store with it (``replacing``), and without ``force`` a store in the way is an existing output.
- A sweep may resume its own file without ``force``: ``check_output(path, force, sweep=True)`` accepts an
  existing sweep file or store (io.sweep_file then checks that it holds the same sweep), not any other file.

Writes are atomic: a temporary ``.NAME.<hex>.tmp`` beside the output, renamed over it when complete.
"""
import contextlib
import errno
import os
import secrets
import shutil
import stat
from pathlib import Path

IMAGE_FORMATS = (".png", ".pdf", ".svg", ".eps", ".tif", ".tiff")  # what plot and figure write
STORE_SUFFIXES = (".members", ".members-new", ".members-old")  # the store, a --force sweep's staging, a retired one


def store_path(path) -> Path:
    """The member store of a sweep file ``path`` (``NAME.members``)."""
    path = Path(path)
    return path.with_name(f"{path.name}.members")


def companions(path) -> list[Path]:
    """The folders that belong to the file ``path`` when it is a sweep: its store, staging and retired stores."""
    path = Path(path)
    return [path.with_name(path.name + suffix) for suffix in STORE_SUFFIXES]


def check_output(path, force: bool, *, sweep: bool = False) -> Path:
    """``path`` as a Path if an output may be written there under the rule above, else an OSError naming it
    (FileExistsError, IsADirectoryError, FileNotFoundError, PermissionError)."""
    if str(path) == "":
        raise FileNotFoundError(errno.ENOENT, "an empty output path (give a file name)", "''")
    path = Path(path)
    check_folder(path)
    exists = path.exists() or path.is_symlink()
    if exists and not stat.S_ISREG(path.stat().st_mode if path.exists() else path.lstat().st_mode):
        what = "a directory" if path.is_dir() else "not a regular file"
        raise IsADirectoryError(errno.EISDIR, f"is {what}: an output is a regular file", str(path))
    store = next((c for c in companions(path) if c.exists()), None)
    if sweep and ((exists and _is_sweep(path) is not False) or (store is not None and not exists)):
        return path  # the sweep resumes its own file (io.sweep_file checks it is the same sweep, or unreadable)
    if exists and not force:
        kind = " (a sweep file)" if not sweep and _is_sweep(path) else ""
        raise FileExistsError(errno.EEXIST, f"already exists{kind} (use --force to replace it)", str(path))
    if store is not None and not force:
        raise FileExistsError(errno.EEXIST, f"the member store {store.name} of a sweep written to {path.name} "
                                            "exists (use --force to replace the sweep with it)", str(path))
    if exists and not os.access(path, os.W_OK):
        raise PermissionError(errno.EACCES, "exists and is not writable (read-only or immutable): not replaced, "
                                            "even with --force", str(path))
    return path


def check_folder(path) -> None:
    """The folder of the output ``path`` exists and this process can create files in it (else an OSError
    naming the output)."""
    path = Path(path)
    folder = path.parent
    if not folder.is_dir():
        raise FileNotFoundError(errno.ENOENT, f"no such folder {str(folder)!r} for the output", str(path))
    if not os.access(folder, os.W_OK | os.X_OK):
        raise PermissionError(errno.EACCES, f"cannot write in its folder {str(folder)!r} (permission denied or "
                                            "read-only)", str(path))


@contextlib.contextmanager
def replacing(path, force: bool, *, keep_store: bool = False):
    """``with replacing(path, force) as tmp:`` a temporary path beside ``path`` (checked by check_output),
    renamed over it when the block completes and removed on any failure. Unless ``keep_store`` (the sweep's
    own view), a sweep's store beside ``path`` is removed once the new file is in place: it belonged to the
    file just replaced."""
    path = check_output(path, force) if not keep_store else Path(path)
    tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp"
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    if not keep_store:
        for folder in companions(path):
            shutil.rmtree(folder, ignore_errors=True)


def _is_sweep(path: Path) -> bool | None:
    """Whether ``path`` is a balloon-cg sweep file (its root ``format`` attribute); None when it is a damaged HDF5
    file (the sweep's reader then names the damage)."""
    import h5py

    try:
        if not h5py.is_hdf5(path):
            return False
        with h5py.File(path, "r") as f:
            fmt = f.attrs.get("format", "")
    except (OSError, RuntimeError, ValueError):
        return None
    fmt = fmt.decode("utf-8", "replace") if isinstance(fmt, bytes) else str(fmt)
    return fmt.startswith("balloon-cg-sweep/")
