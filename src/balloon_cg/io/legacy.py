"""What older files mean under this version: their dataset names, and readings stored before they changed.

Files written before session 21 name the meridian's two ends after a sphere's poles: ``lam2_north``, ``lam2_south``,
``eta_north``, ``eta_south`` (run files up to balloon-cg/5, sweep files up to balloon-cg-sweep/2, their curves and
members). This version writes the shape-neutral ``lam2_top``, ``lam2_bottom``, ``eta_top``, ``eta_bottom`` (the
ends at θ = 0 and θ = π, the top and bottom of the axis). ``current`` gives a reader the file under the new names:
the file itself where it has no old name, else an in-memory copy of its image with those datasets renamed (the file
on disk is never written).

Stored readings whose meaning changed (a stability block that held another constraint) are told apart by the root
attribute ``readings`` (``READINGS``, written with the provenance; a file without it has revision 0):
``stale_readings`` says which of ``CHANGED_READINGS`` a file of a given shape predates, for ``inspect`` to say so.
"""
import contextlib
import io

import h5py

READINGS = 3  # 3: a tube scene's solver.tube_resolution defaults to "elements" (scene.tables.ELEMENTS_SINCE)

CHANGED_READINGS = (  # (revision, the shapes whose stored readings it changed, what changed)
    (1, ("spheroid",), "a spheroid's m = 1 blocks kept a rotation of the reference that is no zero mode of a "
     "spheroid, and its held m = 0 blocks and pear points held the sphere's centroid, not the spheroid's "
     "(docs/shapes.md)"),
    (2, ("spheroid", "capsule"), "a held spheroid's or capsule's equilibrium (its pear branches, its general "
     "basis) and a capsule's held m = 0 readings and pear points hold the reference surface's area centroid; they "
     "held b_0, or dropped the capsule's constant function, before (docs/shapes.md)"),
)

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


def inherited_readings(attrs) -> int:
    """The ``readings`` revision of a file continued from the one whose root attributes are ``attrs``: the older of
    the two (its start point and the branches it copies were read under that file's revision)."""
    return min(int(attrs.get("readings", 0)), READINGS)


def stale_readings(attrs, shape: str) -> list[str]:
    """What changed, since the file whose root attributes are ``attrs`` was written, in the readings it stores of
    a ``shape`` scene (``CHANGED_READINGS``; empty when none did)."""
    revision = int(attrs.get("readings", 0))
    return [what for changed, shapes, what in CHANGED_READINGS if changed > revision and shape in shapes]
