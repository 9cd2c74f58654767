"""Dataset names of older files, read under this version's names.

Files written before session 21 name the meridian's two ends after a sphere's poles: ``lam2_north``, ``lam2_south``,
``eta_north``, ``eta_south`` (run files up to balloon-cg/5, sweep files up to balloon-cg-sweep/2, their curves and
members). This version writes the shape-neutral ``lam2_top``, ``lam2_bottom``, ``eta_top``, ``eta_bottom`` (the
ends at θ = 0 and θ = π, the top and bottom of the axis). ``current`` gives a reader the file under the new names:
the file itself where it has no old name, else an in-memory copy of its image with those datasets renamed (the file
on disk is never written).
"""
import contextlib
import io

import h5py

OLD_NAMES = {"lam2_north": "lam2_top", "lam2_south": "lam2_bottom", "eta_north": "eta_top", "eta_south": "eta_bottom"}


def old_datasets(f) -> list[str]:
    """The paths of the datasets of ``f`` stored under an old name (and not also under the new one)."""
    found = []

    def visit(name):  # by name: only an old name's object is opened
        base = name.rsplit("/", 1)[-1]
        if base in OLD_NAMES and isinstance(item := f[name], h5py.Dataset) and OLD_NAMES[base] not in item.parent:
            found.append(name)

    f.visit(visit)
    return found


def renamed(path: str) -> str:
    head, _, base = path.rpartition("/")
    return f"{head}/{OLD_NAMES[base]}" if head else OLD_NAMES[base]


@contextlib.contextmanager
def current(f):
    """``f`` (an h5py File open for reading) with this version's dataset names: ``f`` itself, or an in-memory copy
    of its image where old names were renamed (``OLD_NAMES``)."""
    old = old_datasets(f)
    if not old:
        yield f
        return
    with h5py.File(io.BytesIO(f.id.get_file_image()), "r+") as copy:
        for path in old:
            copy.move(path, renamed(path))
        yield copy
