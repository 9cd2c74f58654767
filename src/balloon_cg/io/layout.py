"""Checks of what a stored file must hold, before anything reads it: one typed error naming file and problem.

A column spec maps a dataset name to its kind (``float``, ``int``, ``bool``, ``str``) and rank; every column of
one spec has the same first dimension n (``check_columns`` returns it). Kinds are numpy dtype kinds:
float 'f', int 'iu', bool 'b', str an HDF5 string type.
"""
import contextlib
import errno
import math
import os
import stat

import h5py
import numpy as np

from .legacy import current


class FileError(ValueError):
    """A file that is not a readable balloon-cg file of its kind: ``path`` and ``problem`` (exit code 2)."""

    def __init__(self, path, problem: str):
        self.path, self.problem = str(path), problem
        super().__init__(f"{path}: {problem}")


_KINDS = {"float": "f", "int": "iu", "bool": "b"}


def _kind_ok(dtype, kind: str) -> bool:
    """float: float64 exactly, or an integer of at most 8 bytes (exact floats); int: at most 8 bytes (a long double
    or a 16-byte integer read as data gave wrong numbers and unbounded recursion in JSON)."""
    if kind == "str":
        return h5py.check_string_dtype(dtype) is not None
    if kind == "float":
        return dtype == np.float64 or (dtype.kind in "iu" and dtype.itemsize <= 8)
    if kind == "int":
        return dtype.kind in "iu" and dtype.itemsize <= 8
    return dtype.kind in _KINDS[kind]


# A dataset may declare at most this many bytes per byte of its file, and always MIN_DECLARED (gzip'd profiles of
# a smooth shape compress by 5-20; a damaged header declaring 1e11 doubles in 200 KB must not be allocated).
DECLARED_PER_FILE_BYTE = 1000
MIN_DECLARED = 64 * 1024**2


def check_size(item, where, error=FileError) -> None:
    """``error`` when the dataset ``item`` declares more bytes than its file can hold (the bound above)."""
    shape = item.shape
    declared = (math.prod(shape) if shape is not None else 0) * item.dtype.itemsize
    try:
        size = h5py.h5i.get_file_id(item.id).get_filesize()  # not item.file: it builds a File each time
    except (OSError, RuntimeError, ValueError):
        size = 0
    if declared > max(MIN_DECLARED, DECLARED_PER_FILE_BYTE * size):
        raise error(where, f"dataset {item.name} declares {declared / 1024**2:.3g} MiB in a file of "
                           f"{size / 1024:.3g} KiB (damaged)")


def check_sizes(group, where, error=FileError) -> None:
    """check_size for every dataset directly in ``group`` (those a reader loads wholesale)."""
    for item in group.values():
        if isinstance(item, h5py.Dataset):
            check_size(item, where, error)


def can_checksum(dtype, size: int) -> bool:
    """Whether HDF5's Fletcher32 filter can guard a dataset: numbers, at least one element (a filter needs a
    chunked layout, which an empty dataset or variable-length strings cannot have)."""
    return size > 0 and h5py.check_string_dtype(dtype) is None and dtype.kind in "biuf"


def stored_objects(group, path, error=FileError, prefix: str | None = None):
    """(the path it was reached by, it) for every group and dataset below ``group`` (at the path ``prefix``, default
    its name), depth first, reached by hard links only: a soft or external link, a named datatype, a virtual dataset
    (its data in other files, read as fill values when they are missing) or a dataset stored in external files is
    ``error`` naming it (balloon-cg writes none of them)."""
    prefix = group.name.rstrip("/") if prefix is None else prefix
    for name in group:
        where = f"{prefix}/{name}"
        with naming(where, path, error):
            link = group.get(name, getlink=True)
            if not isinstance(link, h5py.HardLink):
                raise error(path, f"{where} is a {type(link).__name__} (refused: a balloon-cg file holds its own data)")
            item = group[name]
            if isinstance(item, h5py.Dataset) and (item.is_virtual or item.id.get_create_plist().get_external_count()):
                raise error(path, f"dataset {where} is {'virtual' if item.is_virtual else 'stored in external files'} "
                                  "(refused: a balloon-cg file holds its own data)")
            if not isinstance(item, (h5py.Group, h5py.Dataset)):
                raise error(path, f"{where} is a {type(item).__name__}, not a group or a dataset")
        yield where, item
        if isinstance(item, h5py.Group):
            yield from stored_objects(item, path, error, where)


@contextlib.contextmanager
def naming(where: str, path, error):
    """What h5py raises on a damaged object (its header, its type, its data) as ``error`` naming it."""
    try:
        yield
    except (OSError, RuntimeError, ValueError, KeyError, TypeError) as e:
        if isinstance(e, FileError):
            raise
        text = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise error(path, f"{where}: unreadable, damaged ({text[:120]})") from None


def check_data(group, path, error=FileError, finite=frozenset()) -> None:
    """Read every dataset below ``group`` once (``stored_objects``; the declared size bounded first,
    ``check_size``): a checksum that does not match (HDF5's Fletcher32 filter) or a damaged chunk is ``error``
    naming the dataset, and so is NaN or inf in a float dataset whose name is in ``finite``."""
    for where, item in stored_objects(group, path, error):
        if not isinstance(item, h5py.Dataset):
            continue
        with naming(f"dataset {where}", path, error):
            check_size(item, path, error)
            data = item[()]
        name = where.rsplit("/", 1)[-1]
        if name in finite and item.dtype.kind == "f" and not np.isfinite(data).all():
            bad = np.argwhere(~np.isfinite(np.atleast_1d(data)))[0]
            raise error(path, f"dataset {where} holds NaN or inf (at {tuple(int(i) for i in bad)}), a "
                              "quantity that is always finite")


def carries_checksums(group) -> bool:
    """Whether datasets below ``group`` carry Fletcher32 checksums: written by a balloon-cg that checksums and
    describes everything it writes, so its whole layout is required (an older file has none)."""
    return bool(group.visititems(lambda name, item: isinstance(item, h5py.Dataset) and item.fletcher32 or None))


def check_input(path, error=FileError) -> None:
    """``path`` is a regular file (FileNotFoundError, IsADirectoryError, or ``error`` for a FIFO, a device, a
    socket: opening one could block forever or never end)."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise FileNotFoundError(errno.ENOENT, "no such file", str(path)) from None
    if stat.S_ISDIR(mode):
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    if not stat.S_ISREG(mode):
        raise error(path, "not a regular file (a FIFO, a device or a socket)")


@contextlib.contextmanager
def reading(path, error=FileError):
    """Map what h5py raises on a damaged file while it is read (OSError, RuntimeError: bit flips, corrupted
    chunks, a truncated file; RecursionError on absurd types; KeyError "Unable to open object" on a damaged
    object header) to ``error(path, ...)``; a missing file or folder stays an OSError naming it."""
    try:
        yield
    except (FileNotFoundError, IsADirectoryError, PermissionError):
        raise
    except (OSError, RuntimeError, KeyError) as e:
        text = str(e).strip("'\"").splitlines()[0] if str(e) else type(e).__name__
        if isinstance(e, KeyError) and not text.startswith("Unable to"):
            raise  # a KeyError not from HDF5's error stack (h5py's "Unable to open object ...") is a bug
        raise error(path, f"damaged: unreadable data ({text[:160]})") from None


def require_attrs(attrs, where, keys, kinds: dict | None = None, error=FileError) -> None:
    """Every key of ``keys`` present in ``attrs`` (and of the kind ``kinds[key]`` where given)."""
    keys = list(keys)
    missing = [k for k in keys if k not in attrs]
    if missing:
        raise error(where, f"missing attribute{'s' if len(missing) > 1 else ''} {', '.join(missing)}")
    for key, kind in (kinds or {}).items():
        if key not in attrs:
            continue
        value = attrs[key]
        if kind == "str":
            ok = isinstance(value, (str, bytes))
        elif kind == "str[]":
            ok = isinstance(value, np.ndarray) and value.ndim == 1 and (value.dtype == object or value.size == 0)
        elif kind in ("float[]", "int[]"):
            ok = isinstance(value, np.ndarray) and value.ndim == 1 and _kind_ok(value.dtype, kind[:-2])
        else:
            ok = np.ndim(value) == 0 and _kind_ok(np.asarray(value).dtype, kind)
        if not ok:
            raise error(where, f"attribute {key} is not of kind {kind} (found {_describe(value)})")


def check_columns(group, where, spec: dict, error=FileError, rows: int | None = None, min_rows: int = 0) -> int:
    """Check the datasets of ``spec`` ({name: (kind, ndim)}) in ``group``; returns their common length n."""
    if not isinstance(group, h5py.Group):
        raise error(where, "is not a group")
    for name, (kind, ndim) in spec.items():
        item = group.get(name)
        if item is None:
            raise error(where, f"missing dataset {name}")
        if not isinstance(item, h5py.Dataset):
            raise error(where, f"{name} is not a dataset")
        if item.shape is None or len(item.shape) != ndim or not _kind_ok(item.dtype, kind):
            raise error(where, f"dataset {name} has shape {item.shape} and type {item.dtype}, expected "
                               f"{ndim}-d {kind}")
        check_size(item, where, error)
        if rows is None and ndim >= 1:
            rows = item.shape[0]
        elif ndim >= 1 and item.shape[0] != rows:
            raise error(where, f"dataset {name} has {item.shape[0]} rows, expected {rows}")
    rows = 0 if rows is None else rows
    if rows < min_rows:
        raise error(where, f"{rows} points (at least {min_rows} needed)")
    return rows


def require_group(parent, name: str, where, error=FileError):
    item = parent.get(name)
    if item is None:
        raise error(where, f"missing group {name}")
    if not isinstance(item, h5py.Group):
        raise error(where, f"{name} is not a group")
    return item


def _describe(value) -> str:
    if isinstance(value, np.ndarray):
        return f"{value.ndim}-d {value.dtype}"
    return type(value).__name__


class _OpenedOnce:
    """An h5py group of a file open for reading whose members are opened once: ``group[name]`` (and ``get``,
    ``items``, ``visititems``; a path, member by member) opens the object, and builds a File for its mode, every
    time it is called (a run file's checks and reading looked each of its ~500 objects up ~9 times: ~1 s of CPU
    for the two-coil scene's). A member group is one of these too."""

    def _get(self, name, lapl=None):
        parts = name.split("/") if isinstance(name, str) and lapl is None else [""]
        if any(part in ("", ".", "..") for part in parts):  # an absolute path, a link's own or none: h5py's
            return super()._get(name, lapl)
        members = self.__dict__.setdefault("_members", {})
        if parts[0] not in members:
            item = super()._get(parts[0])
            members[parts[0]] = _ReadGroup(item.id) if type(item) is h5py.Group else item
        item = members[parts[0]]
        if len(parts) == 1:
            return item
        if not isinstance(item, _ReadGroup):  # a path through a dataset: h5py's error
            return super()._get(name)
        return item._get("/".join(parts[1:]))


class _ReadGroup(_OpenedOnce, h5py.Group):
    pass


class _ReadFile(_OpenedOnce, h5py.File):
    pass


@contextlib.contextmanager
def opened(path, error=FileError):
    """``with opened(path) as f:`` the HDF5 file ``path`` open for reading (``check_input`` first), what h5py
    raises while it is read mapped by ``reading``, under this version's dataset names (``legacy.current``); ``error``
    when it is not a readable HDF5 file."""
    check_input(path, error)
    try:
        f = _ReadFile(path, "r")
    except (OSError, RuntimeError):
        raise error(path, "not a readable HDF5 file") from None
    with f, reading(path, error), current(f) as named:
        yield named


def file_kind(path, error=FileError) -> str:
    """'sweep', 'tube', 'curve' or 'run': what a balloon-cg file holds, by its format and content (a curve file is a
    run file with /two_parameter curves; a tube's run file has its own format, io/tube_file.py)."""
    with opened(path, error) as f:
        if str(f.attrs.get("format", "")).startswith("balloon-cg-sweep"):
            return "sweep"
        if str(f.attrs.get("format", "")).startswith("balloon-cg-tube"):
            return "tube"
        return "curve" if len(f.get("two_parameter", {})) else "run"
