"""Every reader checks what it reads (issue 42, item 4): the damage classes of the reliability harness (a row short,
a wrong dtype, a missing or virtual dataset, an external link, NaN or inf in a quantity that is always finite,
an attribute or a group deleted, bytes flipped inside a dataset's data, a dataset rewritten) are refused by
``inspect``, ``inspect --json`` and ``plot`` with exit 2 and one line naming the dataset, and by ``load()`` with a
RunFileError; every numeric dataset is written with HDF5's Fletcher32 checksum, and a file written without
checksums (an older version) still loads."""
import contextlib
import io
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

import balloon_cg as bc
from balloon_cg.app.cli import main
from balloon_cg.io import hdf5
from balloon_cg.io.layout import FileError, can_checksum
from balloon_cg.io.run_file import RunFileError
from balloon_cg.io.schema import FINITE

SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 1.5\n'  # no coils, a few seconds
P = "/branches/primary/"


@pytest.fixture(scope="module")
def good(tmp_path_factory) -> Path:
    """One small run file: the primary branch with its stability, special points and a snap-through."""
    scene = tmp_path_factory.mktemp("good") / "s.toml"
    scene.write_text(SCENE)
    assert main(["run", str(scene), "-o", str(scene.with_name("good.h5")), "--quiet"]) == 0
    return scene.with_name("good.h5")


def _replace(f, name, data, checksum=True):
    """``name`` written again with ``data``, checksummed as the writer does (so the layout check, not the
    checksum rule, must catch it) unless ``checksum`` is false."""
    parent, leaf = f[name].parent, name.rsplit("/", 1)[1]
    del parent[leaf]
    parent.create_dataset(leaf, data=data, fletcher32=checksum)


def _virtual(f, name):
    """``name`` as a virtual dataset whose source file does not exist (h5py reads the fill value, NaN)."""
    parent, leaf, n = f[name].parent, name.rsplit("/", 1)[1], f[name].shape[0]
    del parent[leaf]
    layout = h5py.VirtualLayout(shape=(n,), dtype="f8")
    layout[:] = h5py.VirtualSource("/nonexistent/source.h5", "x", shape=(n,))
    parent.create_virtual_dataset(leaf, layout, fillvalue=np.nan)


def _external(f, name):
    parent, leaf = f[name].parent, name.rsplit("/", 1)[1]
    del parent[leaf]
    parent[leaf] = h5py.ExternalLink("/nonexistent/other.h5", name)


def _set(f, name, index, value):
    f[name][index] = value  # in place: HDF5 computes the checksum of the new data


def flip_a_byte(path: Path, name: str) -> None:
    """One bit flipped inside the stored data of dataset ``name`` (its first chunk)."""
    with h5py.File(path, "r") as f:
        offset = f[name].id.get_chunk_info(0).byte_offset
    raw = bytearray(path.read_bytes())
    raw[offset + 3] ^= 0x10
    path.write_bytes(bytes(raw))


#: damage class: (what it does to an open file, the name the error must give)
DAMAGE = {
    "point row short": (lambda f: _replace(f, P + "point", np.arange(len(f[P + "point"]) - 1)), "point"),
    "pressure row short": (lambda f: _replace(f, P + "pressure", f[P + "pressure"][:-1]), "pressure"),
    "profile row short": (lambda f: _replace(f, P + "profiles/rho", f[P + "profiles/rho"][:-1]), "rho"),
    "point as floats": (lambda f: _replace(f, P + "point", f[P + "point"][()].astype(float)), "point"),
    "point deleted": (lambda f: f.__delitem__(P + "point"), "point"),
    "pressure virtual": (lambda f: _virtual(f, P + "pressure"), "pressure"),
    "pressure an external link": (lambda f: _external(f, P + "pressure"), "pressure"),
    "NaN in unknowns": (lambda f: _set(f, P + "unknowns", (2, 3), np.nan), "unknowns"),
    "inf in a profile": (lambda f: _set(f, P + "profiles/eta", (1, 5), np.inf), "eta"),
    "NaN in a special point's pressure": (lambda f: _set(f, P + "special_points/pressure", 0, np.nan), "pressure"),
    "root complete deleted": (lambda f: f.attrs.__delitem__("complete"), "complete"),
    "branch assessed deleted": (lambda f: f[P].attrs.__delitem__("assessed"), "assessed"),
    "units of pressure deleted": (lambda f: f[P + "pressure"].attrs.__delitem__("units"), "pressure"),
    "stability group deleted": (lambda f: f.__delitem__(P + "stability"), "stability"),
    "snap_throughs group deleted": (lambda f: f.__delitem__("snap_throughs"), "snap_throughs"),
    "pressure rewritten without checksum": (lambda f: _replace(f, P + "pressure", f[P + "pressure"][()], False),
                                            "pressure"),
    "flipped bytes in pressure": (None, "pressure"),
}
READERS = {
    "inspect": lambda path: ["inspect", str(path)],
    "inspect --json": lambda path: ["inspect", "--json", str(path)],
    "plot": lambda path: ["plot", str(path), "--what", "pressure-pole", "-o", str(path.with_suffix(".png"))],
}


def damaged(good: Path, folder: Path, damage: str) -> Path:
    path = folder / "damaged.h5"
    shutil.copy(good, path)
    change, _ = DAMAGE[damage]
    if change is None:
        flip_a_byte(path, P + "pressure")
    else:
        with h5py.File(path, "a") as f:
            change(f)
    return path


@pytest.mark.parametrize("reader", READERS)
@pytest.mark.parametrize("damage", DAMAGE)
def test_each_damage_is_exit_2_naming_the_dataset(good, tmp_path, capsys, damage, reader):
    path = damaged(good, tmp_path, damage)
    assert main(READERS[reader](path)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("balloon-cg: error: ") and "Traceback" not in err, err
    assert str(path) in err and DAMAGE[damage][1] in err.removeprefix(f"balloon-cg: error: {path}"), err


@pytest.mark.parametrize("damage", DAMAGE)
def test_each_damage_is_a_run_file_error_in_load(good, tmp_path, damage):
    path = damaged(good, tmp_path, damage)
    with pytest.raises(RunFileError) as refused:
        bc.load(path)
    assert DAMAGE[damage][1] in refused.value.problem


def _holders(f) -> list:
    found = [f]
    f.visititems(lambda name, item: found.append(item))
    return found


def _deletions(good: Path, every: bool) -> list:
    """(label, change) deleting one attribute or one group of the file: every attribute of every object
    (``every``), or each attribute name once, on the first object that has it; and every group."""
    with h5py.File(good, "r") as f:
        holders = _holders(f)
        attributes = [(item.name, key) for item in holders for key in item.attrs]
        groups = [item.name for item in holders if isinstance(item, h5py.Group) and item.name != "/"]
    if not every:
        attributes = list({key: (name, key) for name, key in reversed(attributes)}.values())
    return _deleting(attributes, groups)


OLDER = {"readings"}  # attributes whose absence reads as a file of an older version (revision 0 of its readings:
#                     io.legacy.stale_readings, flagged OUTDATED where that matters: test_storage), never refused


def _deleting(attributes: list, groups: list) -> list:
    """(label, change) deleting each (object, attribute) of ``attributes`` but ``OLDER``'s, then each group of
    ``groups``."""
    return [(f"{name} attribute {key}", lambda f, n=name, k=key: f[n].attrs.__delitem__(k))
            for name, key in attributes if key not in OLDER] + [(name, lambda f, n=name: f.__delitem__(n))
                                                                 for name in groups]


def _accepted(good: Path, folder: Path, deletions: list) -> list:
    path = folder / "damaged.h5"
    accepted = []
    for label, change in deletions:
        shutil.copy(good, path)
        with h5py.File(path, "a") as f:
            change(f)
        with contextlib.suppress(FileError):  # RunFileError, SweepFileError
            bc.load(path)
            accepted.append(label)
    return accepted


def test_each_attribute_and_group_deletion_is_refused(good, tmp_path):
    """Each attribute name of the file (root, groups, datasets) deleted from the first object that has it, and
    each group: refused."""
    deletions = _deletions(good, every=False)
    assert len(deletions) > 40
    assert _accepted(good, tmp_path, deletions) == []


@pytest.mark.slow
def test_every_attribute_deletion_is_refused(good, tmp_path):
    """All of them (280 attributes of every object, one at a time)."""
    deletions = _deletions(good, every=True)
    assert len(deletions) > 250
    assert _accepted(good, tmp_path, deletions) == []


def test_nan_in_every_finite_dataset_is_refused(good, tmp_path):
    """NaN written into each float dataset the schema says is always finite (FINITE): refused, naming it."""
    with h5py.File(good, "r") as f:
        names = [item.name for item in _holders(f) if isinstance(item, h5py.Dataset) and item.dtype.kind == "f"
                 and item.size and item.name.rsplit("/", 1)[1] in FINITE]
    assert len(names) >= 20
    path = tmp_path / "damaged.h5"
    for name in names:
        shutil.copy(good, path)
        with h5py.File(path, "a") as f:
            _set(f, name, (0,) * f[name].ndim, np.nan)
        with pytest.raises(RunFileError, match=f"dataset {name} holds NaN or inf"):
            bc.load(path)


def test_every_numeric_dataset_is_checksummed(good):
    with h5py.File(good, "r") as f:
        datasets = [item for item in _holders(f) if isinstance(item, h5py.Dataset)]
        unguarded = [d.name for d in datasets if can_checksum(d.dtype, d.size) and not d.fletcher32]
        assert unguarded == [] and sum(d.fletcher32 for d in datasets) > 50


def test_a_file_without_checksums_still_loads(good, tmp_path, monkeypatch):
    """A file as an older version wrote it (no checksums, no ``assessed`` or ``snap_throughs`` attribute) reads
    as the same result; its rows are still checked."""
    monkeypatch.setattr(hdf5, "can_checksum", lambda dtype, size: False)
    (tmp_path / "s.toml").write_text(SCENE)
    old = tmp_path / "old.h5"
    assert main(["run", str(tmp_path / "s.toml"), "-o", str(old), "--quiet"]) == 0
    with h5py.File(old, "a") as f:
        assert not any(isinstance(d, h5py.Dataset) and d.fletcher32 for d in _holders(f))
        del f["branches"].attrs["snap_throughs"], f[P].attrs["assessed"]
    then, now = bc.load(old), bc.load(good)
    assert then.complete and np.array_equal(then.branches["primary"]["pressure"], now.branches["primary"]["pressure"])
    with h5py.File(old, "a") as f:
        _replace(f, P + "point", np.arange(len(f[P + "point"]) - 1), checksum=False)
    with pytest.raises(RunFileError, match="dataset point has"):
        bc.load(old)


@pytest.fixture(scope="module")
def sweep(tmp_path_factory) -> Path:
    """A sweep view of two members (its store removed: the view alone is what the readers read)."""
    scene = tmp_path_factory.mktemp("sweep") / "s.toml"
    scene.write_text(SCENE)
    view = scene.with_name("sweep.h5")
    assert main(["sweep", str(scene), "--vary", "stop_stretch=1.3,1.4", "--primary-only", "--workers", "1",
                 "--quiet", "-o", str(view)]) == 0
    shutil.rmtree(view.with_name(view.name + ".members"))
    return view


def test_a_sweep_member_with_a_flipped_byte_is_refused(sweep, tmp_path, capsys):
    """The sweep view reads its members through the same checks: a flipped byte in a member's data is exit 2
    naming the dataset."""
    path = tmp_path / "sweep.h5"
    shutil.copy(sweep, path)
    capsys.readouterr()
    flip_a_byte(path, "/members/1/branches/primary/lam2_top")
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["inspect", str(path)]) == 2
    assert "dataset /members/1/branches/primary/lam2_top: unreadable, damaged" in capsys.readouterr().err


def test_each_sweep_attribute_and_group_deletion_is_refused(sweep, tmp_path):
    """Each attribute name of a sweep view at each depth (root, member, branch, dataset), and each group but a
    whole member (a view may hold fewer members than the sweep: an unfinished sweep), deleted: refused."""
    with h5py.File(sweep, "r") as f:
        holders = _holders(f)
        attributes = list({(item.name.count("/"), key): (item.name, key) for item in reversed(holders)
                           for key in item.attrs}.values())
        groups = [item.name for item in holders if isinstance(item, h5py.Group)
                  and item.name.rsplit("/", 1)[0] not in ("", "/members")]
    assert len(attributes) > 60 and len(groups) >= 8
    assert _accepted(sweep, tmp_path, _deleting(attributes, groups)) == []
