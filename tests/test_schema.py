"""Self-describing run files: named dimensions and units on every variable (xarray + h5netcdf), the volume per
point against the sphere's closed form, and files of the previous format still read."""
from pathlib import Path

import h5py
import numpy as np
import pytest

from balloon_cg.analysis.results import StopCode
from balloon_cg.io.legacy import OLD_NAMES
from balloon_cg.io.run_file import FORMAT, RunFileError, read_run
from balloon_cg.io.schema import VARIABLES
from balloon_cg.post.plotting import plot
from balloon_cg.scene import parse_scene
from balloon_cg.scene.events import Quantity
from netcdf_groups import uncoordinated
from shared_pictures import small_run_file

xr = pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")
DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    """The session's run of the scene small (shared_pictures.small_run_file: read here, or copied to change it)."""
    return small_run_file(tmp_path_factory)


def groups(path):
    with h5py.File(path, "r") as f:
        names = []
        f["branches"].visit(lambda name: names.append(name) if isinstance(f["branches"][name], h5py.Group) else None)
        return [f"branches/{n}" for n in names]


def test_every_variable_has_named_dimensions_and_units(run_file):
    found = groups(run_file) + ["snap_throughs"]
    assert {"branches/primary", "branches/primary/profiles", "branches/primary/special_points",
            "branches/primary/stability", "branches/pear_0"} <= set(found)
    for group in found:
        with xr.open_dataset(run_file, engine="h5netcdf", group=group) as ds:
            assert not [d for d in ds.dims if str(d).startswith("phony")], (group, ds.dims)
            for name, variable in ds.variables.items():
                assert variable.attrs["long_name"], (group, name)
                quantity = variable.dtype.kind == "f" and name not in ("newton_iterations",)
                assert ("units" in variable.attrs) == quantity, (group, name)  # indices, flags, labels: none
    with xr.open_dataset(run_file, engine="h5netcdf", group="branches/primary/profiles") as ds:
        assert ds.rho.dims == ("point", "theta")
    with xr.open_dataset(run_file, engine="h5netcdf", group="branches/primary") as ds:
        assert ds.unknowns.dims == ("point", "unknown") and ds.theta.attrs["units"] == "rad"


def test_every_group_opened_alone_carries_its_coordinates(run_file):
    """``xr.open_dataset(f, group="branches/primary/profiles")`` (stability, special_points/state, …): the point
    index and θ as coordinates, equal to the branch's own (issue 40: subgroups repeat their enclosing scales)."""
    assert uncoordinated(run_file) == []
    with xr.open_dataset(run_file, engine="h5netcdf", group="branches/primary/profiles") as ds, \
            xr.open_dataset(run_file, engine="h5netcdf", group="branches/primary") as branch:
        assert ds.rho.dims == ("point", "theta") and ds.theta.attrs["units"] == "rad"
        np.testing.assert_array_equal(ds.theta.values, branch.theta.values)
        np.testing.assert_array_equal(ds.point.values, branch.point.values)
        assert ds.rho.sel(theta=np.pi / 2, method="nearest").size == branch.sizes["point"]
    with xr.open_dataset(run_file, engine="h5netcdf", group="branches/pear_0/special_points/state") as ds:
        assert ds.unknowns.dims == ("special", "unknown") and list(ds.special.values) == list(range(ds.sizes["special"]))
    assert set(read_run(run_file)["branches"]["primary"]["profiles"]) == {"lam1", "lam2", "rho", "eta"}


def test_a_coordinate_that_does_not_repeat_its_own_is_refused(run_file, tmp_path):
    """A subgroup's copy of θ that differs from the branch's: the reader names it (xarray would draw on it)."""
    damaged = tmp_path / "damaged.h5"
    damaged.write_bytes(Path(run_file).read_bytes())
    with h5py.File(damaged, "r+") as f:
        f["branches/primary/profiles/theta"][3] += 1e-3
    with pytest.raises(RunFileError, match="profiles/theta does not repeat /branches/primary/theta"):
        read_run(damaged)


def without_repeated_coordinates(path) -> list:
    """Make ``path`` a file of the current format as written before its subgroups repeated their coordinates
    (issue 40, f2f2dde): every variable of a subgroup attached to its enclosing group's dimension scale of the same
    name, the subgroup's own removed; the (subgroup, scale) pairs removed."""
    removed = []
    with h5py.File(path, "r+") as f:
        scales = []
        f.visititems(lambda name, item: scales.append(item) if isinstance(item, h5py.Dataset) and item.is_scale
                     else None)
        for inner in scales:
            name, outer = inner.name.rsplit("/", 1)[-1], inner.parent.parent
            while outer.name != "/" and not isinstance(outer.get(name), h5py.Dataset):
                outer = outer.parent
            enclosing = outer.get(name)
            if inner.parent.name == "/" or not isinstance(enclosing, h5py.Dataset) or not enclosing.is_scale:
                continue  # a group's own coordinate, repeated by none
            users = []
            inner.parent.visititems(lambda _, item: users.append(item) if isinstance(item, h5py.Dataset) else None)
            for data in users:
                for dim in data.dims:
                    if any(scale == inner for scale in dim.values()):
                        dim.detach_scale(inner)
                        dim.attach_scale(enclosing)
            removed.append((inner.parent.name, name))
        for group, name in removed:
            del f[group][name]
    return removed


def test_a_file_whose_subgroups_do_not_repeat_their_coordinates_still_reads(run_file, tmp_path):
    """A balloon-cg/5 file written before the subgroups carried their coordinates (their variables attached to the
    enclosing group's scales; its ends named lam2_north, …) reads as the file it was made from, loads, opens with
    xarray and draws (a file written by f2f2dde^ was checked alike by hand)."""
    import balloon_cg as bc

    old = tmp_path / "before.h5"
    old.write_bytes(Path(run_file).read_bytes())
    removed = without_repeated_coordinates(old)
    assert ("/branches/primary/profiles", "theta") in removed and uncoordinated(old)  # as such files were
    assert _with_old_names(old, "balloon-cg/5")  # and their ends named after the poles
    new, before = read_run(run_file), read_run(old)
    for name, branch in new["branches"].items():
        np.testing.assert_array_equal(before["branches"][name]["unknowns"], branch["unknowns"])
        np.testing.assert_array_equal(before["branches"][name]["profiles"]["rho"], branch["profiles"]["rho"])
        assert repr(before["branches"][name]["special_points"]) == repr(branch["special_points"])  # nan: nan
    assert bc.load(old).to_xarray().sizes["point"] == len(new["branches"]["primary"]["pressure"])
    assert plot([old], "shapes").axes


def test_kinds_read_as_strings(run_file):
    with xr.open_dataset(run_file, engine="h5netcdf", group="branches/primary/special_points") as ds:
        assert [str(k) for k in ds.kind.values] == ["EP", "LP", "BP", "EP"]
    assert all(isinstance(s["kind"], str) for s in read_run(run_file)["branches"]["primary"]["special_points"])


def test_volume_is_the_sphere_volume_on_the_primary_branch(run_file):
    """M = 0: the primary branch is the sphere of radius λ, V = 4π λ³/3 (closed form), to the Newton tolerance
    (1e-11 on the unknowns: 9e-12 seen)."""
    primary = read_run(run_file)["branches"]["primary"]
    assert np.allclose(primary["volume"], 4 * np.pi / 3 * primary["lam2_top"] ** 3, rtol=5e-11, atol=0)
    pear = read_run(run_file)["branches"]["pear_0"]
    assert np.all(np.diff(pear["volume"]) != 0)  # a column per point on every branch


def test_every_stored_name_is_described(run_file):
    with h5py.File(run_file, "r") as f:
        names = set()
        f.visititems(lambda name, item: names.add(name.rsplit("/", 1)[-1]) if isinstance(item, h5py.Dataset) else None)
    undescribed = {n for n in names if n not in VARIABLES and not n.startswith("lowest_")} - {
        "from_branch", "to_branch", "from_index", "to_index"}  # /snap_throughs: a table of its own (docs/hdf5.md)
    assert not undescribed


def test_previous_format_still_reads_and_draws():
    old = DATA / "spom1_format2.h5"  # written by balloon-cg at format balloon-cg/2 (commit 5efbb22)
    with h5py.File(old, "r") as f:
        assert f.attrs["format"] == "balloon-cg/2" != FORMAT
    run = read_run(old)
    assert "volume" not in run["branches"]["primary"] and len(run["branches"]["primary"]["pressure"]) > 10
    assert plot([old], "pressure-pole").axes


def test_cf_global_attributes(run_file):
    with xr.open_dataset(run_file, engine="h5netcdf") as ds:
        assert ds.attrs["Conventions"] == "CF-1.10" and ds.attrs["title"] == "balloon-cg run of scene small"
        assert ds.attrs["history"].startswith(ds.attrs["created"]) and "balloon-cg 0.1.0" in ds.attrs["history"]
    with xr.open_dataset(run_file, engine="h5netcdf", group="branches/primary") as ds:
        assert ds.pressure.attrs["units"] == "1" and "units" not in ds.point.attrs
        assert "units" not in ds.converged.attrs and "units" not in ds.newton_iterations.attrs


def test_format4_special_points_still_read(run_file, tmp_path):
    """A balloon-cg/4 file kept each special point's X rows among the columns (special_points/unknowns): it reads
    as the file it was made from."""
    old = tmp_path / "format4.h5"
    old.write_bytes(Path(run_file).read_bytes())
    with h5py.File(old, "r+") as f:
        f.attrs["format"] = "balloon-cg/4"
        for branch in f["branches"].values():
            branch["special_points"].move("state/unknowns", "unknowns")
            del branch["special_points/state"]
    now, then = read_run(run_file)["branches"], read_run(old)["branches"]
    assert FORMAT == "balloon-cg/6" and list(now) == list(then)
    for name in now:
        assert np.array_equal(now[name]["special_unknowns"], then[name]["special_unknowns"])
        assert repr(now[name]["special_points"]) == repr(then[name]["special_points"])  # NaN E2..E4 read alike


def _with_old_names(path, fmt: str) -> int:
    """Rename every dataset of ``path`` to its name before balloon-cg/6 and stamp ``fmt``; the datasets renamed."""
    new_to_old = {new: old for old, new in OLD_NAMES.items()}
    with h5py.File(path, "r+") as f:
        found = []
        f.visititems(lambda name, item: found.append(name) if isinstance(item, h5py.Dataset)
                     and name.rsplit("/", 1)[-1] in new_to_old else None)
        for name in found:
            head, _, base = name.rpartition("/")
            f.move(name, f"{head}/{new_to_old[base]}")
        f.attrs["format"] = fmt
    return len(found)


def test_format5_names_of_the_ends_read_as_top_and_bottom(run_file, tmp_path):
    """A balloon-cg/5 file names the meridian's ends after the sphere's poles (lam2_north, eta_south, …): it reads
    as the file it was made from, under today's names, and the file is not written."""
    old = tmp_path / "format5.h5"
    old.write_bytes(Path(run_file).read_bytes())
    assert _with_old_names(old, "balloon-cg/5") >= 8  # the primary's and the pear's columns and special points
    before = old.read_bytes()
    now, then = read_run(run_file)["branches"], read_run(old)["branches"]
    assert old.read_bytes() == before
    assert list(now) == list(then)
    for name in now:
        for key in ("lam2_top", "lam2_bottom", "eta_top", "eta_bottom"):
            assert np.array_equal(now[name][key], then[name][key])
            assert [s[key] for s in now[name]["special_points"]] == [s[key] for s in then[name]["special_points"]]
        assert not {"lam2_north", "lam2_south", "eta_north", "eta_south"} & set(then[name])


def test_the_old_names_of_a_stop_and_an_event_still_read():
    """A stop code and an event quantity stored (or written in a scene) before the ends were named top and bottom."""
    assert StopCode("south_stop_stretch") is StopCode.BOTTOM_STOP_STRETCH
    scene = parse_scene('[material]\npreset = "SPOM1"\n[[events]]\nquantity = "lam2_north"\nvalue = 1.5\n'
                        '[[events]]\nquantity = "lam2_south"\nvalue = 1.6\n', "old")
    assert [e.quantity for e in scene.events] == [Quantity.LAM2_TOP, Quantity.LAM2_BOTTOM]
