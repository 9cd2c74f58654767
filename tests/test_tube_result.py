"""``balloon_cg.load`` of a tube run file (app/tube_result.py): every group of the file (each branch's points and
located points, the onset curve of ``critical``) as an xarray Dataset and as a pandas table holds the file's numbers
(io.tube_file.read_tube_run), the shape's parameters are attributes; a branch or part that is not there is named."""
import numpy as np
import pytest

import balloon_cg as bc
from balloon_cg.io.tube_file import read_tube_run

from shared_pictures import tube_critical_file, tube_run_file


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """`run` of the shipped tube (degree 16, to a hoop stretch of 3) and `critical --parameter M` of its coil scene,
    each written once per session (tests/shared_pictures.py)."""
    return tube_run_file(tmp_path_factory), tube_critical_file(tmp_path_factory)


def test_each_branch_as_xarray_holds_the_file(files):
    pytest.importorskip("xarray")
    tube = bc.load(files[0])
    stored = read_tube_run(files[0])
    assert isinstance(tube, bc.TubeResult) and tube.interrupted is None
    assert tube.geometry == {"shape": "tube", "length": 10.0, "ends": "sliding", "axial_stretch": None}
    assert tube.maxwell_pressure == stored["attrs"]["maxwell_pressure"]
    for name, branch in stored["branches"].items():
        points = tube.to_xarray(name)
        assert points.sizes["point"] == len(branch["pressure"]) and points.attrs["stop_code"] == \
            branch["attrs"]["stop_code"]
        for column in ("pressure", "volume", "unstable_pressure", "unstable_volume", "smallest_stress",
                       "crest_height"):
            assert np.array_equal(points[column].values, branch[column])
        assert np.array_equal(points["unknowns"].values, branch["unknowns"])
        special = tube.to_xarray(name, "special")
        assert list(special["kind"].values) == [s["kind"] for s in branch["special_points"]]
        assert np.array_equal(special["pressure"].values, [s["pressure"] for s in branch["special_points"]])
        assert np.array_equal(special["unknowns"].values, branch["special_unknowns"])
    assert "lowest_odd" in tube.to_xarray("primary") and tube.to_xarray("primary").attrs["length"] == 10.0
    with pytest.raises(KeyError, match="no branch 'pear' \\(branches: bulge, bulge_2, bulge_3, bulge_4, bulge_5, "
                                       "primary\\)"):
        tube.to_xarray("pear")
    with pytest.raises(ValueError, match="part = 'shapes': must be 'points' or 'special'"):
        tube.to_xarray("bulge", "shapes")
    with pytest.raises(KeyError, match="has no onset curve"):
        tube.to_xarray("onset")


def test_tables_hold_every_point_and_located_point(files):
    pytest.importorskip("pandas")
    tube = bc.load(files[0])
    stored = read_tube_run(files[0])
    points = tube.to_dataframe()
    for name, branch in stored["branches"].items():
        rows = points[points.branch == name]
        assert np.array_equal(rows.pressure.values, branch["pressure"]) and list(rows.point) == \
            list(range(len(branch["pressure"])))
    special = tube.to_dataframe("special")
    assert list(special.kind) == [s["kind"] for b in stored["branches"].values() for s in b["special_points"]]
    with pytest.raises(ValueError, match="must be 'points', 'special' or 'onset'"):
        tube.to_dataframe("curve")


def test_the_onset_curve_as_xarray_and_table(files):
    pytest.importorskip("xarray")
    tube = bc.load(files[1])
    onset = read_tube_run(files[1])["onset"]
    data = tube.to_xarray("onset")
    assert np.array_equal(data["M"].values, onset["q"]) and np.array_equal(data["pressure"].values, onset["pressure"])
    assert np.array_equal(data["modes"].values, onset["modes"]) and data.attrs["parameter"] == "M"
    assert np.array_equal(data["unknowns"].values, onset["unknowns"])
    table = tube.to_dataframe("onset")
    assert np.array_equal(table.M.values, onset["q"]) and np.array_equal(table.crest_height.values,
                                                                          onset["crest_height"])
    assert np.array_equal(table.hoop_stretch.values, onset["hoop_stretch"])  # read back from the unknowns
    assert np.array_equal(data["hoop_stretch"].values, onset["hoop_stretch"])
    assert "onset in M" in repr(tube)


def test_every_group_opens_with_xarray_with_named_dimensions(files):
    """xarray with h5netcdf opens each group of a tube run file alone, its axes named (the file's dimension
    scales) and its datasets described; the values are the file's."""
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    stored = read_tube_run(files[1])
    groups = {f"branches/{name}": ("point", "unknown") for name in stored["branches"]}
    groups |= {f"branches/{name}/special_points": ("special", "unknown") for name in stored["branches"]}
    groups |= {"onset": ("point", "unknown", "mode"), "onset/folds": ("special",)}
    for group, dims in groups.items():
        with xr.open_dataset(files[1], engine="h5netcdf", group=group) as ds:
            assert set(ds.sizes) == set(dims), (group, ds.sizes)
            assert all(ds[name].attrs["long_name"] for name in ds.data_vars), group
    with xr.open_dataset(files[1], engine="h5netcdf", group="onset") as ds:
        assert ds["modes"].dims == ("point", "mode") and np.array_equal(ds["q"].values, stored["onset"]["q"])
    with xr.open_dataset(files[1], engine="h5netcdf", group="branches/primary") as ds:
        assert ds["unknowns"].dims == ("point", "unknown") and ds["volume"].attrs["units"] == "1"
        assert np.array_equal(ds["unknowns"].values, stored["branches"]["primary"]["unknowns"])


def test_plot_draws_a_tube_from_its_result_or_its_path_as_the_command_does(files):
    """``bc.plot`` of a TubeResult or a tube file's path draws post.tube_plots' figure (the command's): the same
    lines as ``tube_figure`` of the file; a tube beside another source or into given Axes is refused in one line."""
    import matplotlib.pyplot as plt
    from balloon_cg.post.plotting import PlotError
    from balloon_cg.post.tube_plots import tube_figure

    tube = bc.load(files[0])
    expected = tube_figure(read_tube_run(files[0]), "profiles")
    for source in (tube, files[0], str(files[0])):
        fig = bc.plot(source, "profiles")
        assert [line.get_xydata().tolist() for line in fig.axes[0].lines] == \
            [line.get_xydata().tolist() for line in expected.axes[0].lines]
    assert bc.plot(tube).axes[0].get_xlabel() == tube_figure(tube.run, "pressure-volume").axes[0].get_xlabel()
    with pytest.raises(PlotError, match="alone"):
        bc.plot([tube, tube], "profiles")
    with pytest.raises(PlotError, match="ax"):
        bc.plot(tube, "profiles", ax=plt.figure().add_subplot())
    plt.close("all")
