"""What every balloon-cg HDF5 file shares: the checked output path, the atomic write, the provenance and the copy of
a group into another file (``copy_tree``: dimension scales kept valid).

A file is written to a temporary file in the same directory and renamed over the target (``os.replace``) only
when complete: an existing file is never left half-written, and on any failure the temporary file is removed.
Which outputs may be written or replaced is io.output's one rule.
"""
import contextlib
import datetime
import shlex
import sys
from pathlib import Path

import h5py
import numpy as np

import balloon_cg

from .legacy import READINGS
from .layout import can_checksum
from .output import replacing


@contextlib.contextmanager
def atomic_file(path, force: bool = False, keep_store: bool = False):
    """``with atomic_file(path) as f:`` a new h5py.File that replaces ``path`` when the block completes
    (io.output.replacing: the one rule for outputs; ``keep_store`` only for a sweep's own view)."""
    with replacing(path, force, keep_store=keep_store) as tmp, h5py.File(tmp, "x") as f:
        yield f


def atomic_bytes(path, data: bytes, force: bool = False) -> Path:
    """Write ``data`` (a file image) to ``path`` as atomically as ``atomic_file``."""
    with replacing(path, force) as tmp, open(tmp, "xb") as f:
        f.write(data)
    return Path(path)


CONVENTIONS = "CF-1.10"  # the netCDF conventions the files follow (units, long_name, dimensions, history)


def provenance(command: str | None = None) -> dict:
    """Attributes naming what wrote a file: package version, digest of the generated kernels, the revision of
    its readings' meaning (``legacy.READINGS``), time, command, and the CF global attributes ``Conventions`` and
    ``history`` (time, command and version, one line)."""
    from ..model.kernels import generated_digest  # here: model/ imports numba, which reading does not need

    created = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    command = command if command is not None else command_line()
    return {
        "package_version": balloon_cg.__version__,
        "generated_digest": generated_digest(),
        "readings": READINGS,
        "created": created,
        "command": command,
        "Conventions": CONVENTIONS,
        "history": f"{created}: {command} (balloon-cg {balloon_cg.__version__})",
    }


def command_line() -> str:
    """What was typed: ``python -m module args`` for a module run with -m (sys.argv[0] is then its file)."""
    spec = getattr(sys.modules.get("__main__"), "__spec__", None)
    if spec is None or not spec.name:
        return shlex.join(sys.argv)
    return shlex.join(["python", "-m", spec.name.removesuffix(".__main__"), *sys.argv[1:]])


def checksummed(group, name: str, data, **options):
    """``group.create_dataset(name, data=data, **options)`` guarded by HDF5's Fletcher32 checksum wherever HDF5
    can (``layout.can_checksum``: numbers, at least one element): a flipped byte in the stored data is then an
    error of HDF5's own when it is read, not a wrong number."""
    data = np.asarray(data)
    return group.create_dataset(name, data=data, fletcher32=can_checksum(data.dtype, data.size), **options)


def write_strings(group, name: str, values) -> None:
    """A dataset of variable-length UTF-8 strings."""
    group.create_dataset(name, data=np.array(list(values), dtype=object), dtype=h5py.string_dtype())


def plain(value):
    """numpy scalars as Python numbers/bools, for printing and JSON."""
    if not isinstance(value, np.generic):
        return value
    item = value.item()  # a long double stays a numpy scalar: its nearest Python number
    return item if not isinstance(item, np.generic) else complex(item) if np.iscomplexobj(item) else float(item)


SCALE_BOOKKEEPING = ("DIMENSION_LIST", "REFERENCE_LIST")  # HDF5 dimension-scale attributes: object references


def copy_attrs(src, dst) -> None:
    """Every attribute of ``src`` onto ``dst``, with its stored type."""
    for name in src.attrs:
        dst.attrs.create(name, src.attrs[name], dtype=src.attrs.get_id(name).dtype)


def copy_tree(src, dst) -> None:
    """Copy the group ``src`` (its attributes and everything in it) into the group ``dst`` of another file, its
    dimension scales attached again in ``dst``: HDF5's object copy across files keeps the scales' references as
    addresses in the source file, which dangle in the copy (h5py, xarray and netCDF readers then fail). Each scale
    is found by its object (``ObjectID``), not by its name: asking HDF5 for an object's name searches the file,
    which made a sweep's view (``io.sweep_file.consolidate``) cost ~0.3 s of CPU per member."""
    copy_attrs(src, dst)
    for name in src:
        src.copy(src[name], dst, name)
    paths, datasets, copies = {}, {}, {}

    def note(name, item):
        paths[item.id] = name
        if isinstance(item, h5py.Dataset):
            datasets[name] = item

    src.visititems(note)
    dst.visititems(lambda name, item: copies.__setitem__(name, item) if isinstance(item, h5py.Dataset) else None)
    for name in datasets:
        for key in SCALE_BOOKKEEPING:
            if key in copies[name].attrs:
                del copies[name].attrs[key]
    for name, dataset in datasets.items():
        for axis, dimension in enumerate(dataset.dims):
            for attached in _scales(dimension):
                copies[name].dims[axis].attach_scale(copies[paths[attached.id]])


def _scales(dimension) -> list:
    """The scales attached to a dimension; none when its references dangle (a sweep file written by an earlier
    version copied them so): the copy then has no scale on that axis."""
    try:
        return dimension.values()
    except (KeyError, RuntimeError, ValueError):
        return []
