"""Checks of what a stored file must hold, before anything reads it: one typed error naming file and problem.

A column spec maps a dataset name to its kind (``float``, ``int``, ``bool``, ``str``) and rank; every column of
one spec has the same first dimension n (``check_columns`` returns it). Kinds are numpy dtype kinds:
float 'f', int 'iu', bool 'b', str an HDF5 string type.
"""
import h5py
import numpy as np


class FileError(ValueError):
    """A file that is not a readable balloon-cg file of its kind: ``path`` and ``problem`` (exit code 2)."""

    def __init__(self, path, problem: str):
        self.path, self.problem = str(path), problem
        super().__init__(f"{path}: {problem}")


_KINDS = {"float": "f", "int": "iu", "bool": "b"}


def _kind_ok(dtype, kind: str) -> bool:
    if kind == "str":
        return h5py.check_string_dtype(dtype) is not None
    if kind == "float":
        return dtype.kind in "fiu"  # integers are exact floats
    return dtype.kind in _KINDS[kind]


def require_attrs(attrs, where, keys, kinds: dict | None = None, error=FileError) -> None:
    """Every key of ``keys`` present in ``attrs`` (and of the kind ``kinds[key]`` where given)."""
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
        elif kind == "float[]":
            ok = isinstance(value, np.ndarray) and value.ndim == 1 and value.dtype.kind in "fiu"
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
        if len(item.shape) != ndim or not _kind_ok(item.dtype, kind):
            raise error(where, f"dataset {name} has shape {item.shape} and type {item.dtype}, expected "
                               f"{ndim}-d {kind}")
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
