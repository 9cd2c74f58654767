"""The public API: Results are short to print, save and load exactly, and tabulate what the run file holds
(docs/api.md's example runs end to end in tests/test_api_notebook.py)."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import balloon_cg as bc
from balloon_cg.io.run_file import read_run

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "scenes"


@pytest.fixture(scope="module")
def result():
    scene = bc.Scene.from_toml(SCENES / "spom1.toml").with_overrides({"continuation.stop_stretch": 3.0})
    return bc.analyse(scene)


def test_result_tables_match_the_run_file(result, tmp_path):
    path = result.save(tmp_path / "r.h5")
    stored = read_run(path)
    table = result.to_dataframe()
    assert set(table.branch) == set(stored["branches"])
    for name, data in stored["branches"].items():
        rows = table[table.branch == name]
        assert np.array_equal(rows.pressure.to_numpy(), data["pressure"])
        assert np.array_equal(rows.stable_pressure.to_numpy(), data["stability"]["stable_pressure"])
    special = result.to_dataframe("special")
    assert len(special) == sum(len(b["special_points"]) for b in stored["branches"].values())
    assert set(special.kind) <= {"LP", "TP", "BP", "EP", "UZ"} and all(isinstance(k, str) for k in special.kind)


def test_save_load_round_trip_is_exact(result, tmp_path):
    path = result.save(tmp_path / "r.h5")
    assert path.read_bytes() == result.image
    again = bc.load(path)
    assert again.scene == result.scene and again.complete == result.complete
    assert again.to_dataframe().equals(result.to_dataframe())
    with pytest.raises(FileExistsError):
        result.save(path)


def test_reprs_are_one_short_line(result):
    """Every object a notebook shows prints as one line of at most ~2 × 80 characters (the scene's was 712)."""
    objects = [result, result.picture, result.scene, result.special_points, *result.branches.values(),
               *(b.special_points for b in result.branches.values()), *result.picture.branches,
               *(s for b in result.picture.branches for s in b.special)]
    for item in objects:
        text = repr(item)
        assert "\n" not in text and len(text) <= 160, text
    assert repr(result.scene) == "Scene('spom1': SPOM1, no field, pressure control, stop_stretch 3)"


def test_results_show_as_html_tables(result):
    """Result: a row per branch; a branch: its row and its special points; special points: a row each."""
    html = result._repr_html_()
    assert html.count("<table") == 1 and html.count("<tr") == 1 + len(result.branches)
    assert all(f"<td>{name}</td>" in html for name in result.branches)
    primary = result.branches["primary"]._repr_html_()
    assert primary.count("<table") == 2 and "<td>BP</td>" in primary
    special = result.special_points._repr_html_()
    assert special.count("<tr") == 1 + len(result.special_points) and "<th>kind</th>" in special


def test_special_points_are_one_table(result, tmp_path):
    """One row per special point, in Python and in the file: special_points opens with xarray as a table of the
    special points alone (its X rows in special_points/state: issue 29 found 9 points expanded into 828 rows)."""
    xr = pytest.importorskip("xarray")
    points = result.special_points
    table = points.to_dataframe()
    assert len(table) == len(points) == sum(len(b.special_points) for b in result.branches.values()) > 3
    assert list(table.columns[:3]) == ["branch", "kind", "classification"]
    assert table.kind.tolist() == [p["kind"] for p in points] and isinstance(points[0], dict)
    ds = points.to_xarray()
    assert dict(ds.sizes) == {"special": len(points)} and ds.pressure.attrs["units"] == "1"
    path = result.save(tmp_path / "r.h5")
    stored = read_run(path)["branches"]["primary"]
    with xr.open_dataset(path, engine="h5netcdf", group="branches/primary/special_points") as ds:
        assert dict(ds.sizes) == {"special": len(stored["special_points"])}
        assert len(ds.to_dataframe()) == len(stored["special_points"])
        assert ds.kind.values.tolist() == [p["kind"] for p in stored["special_points"]]
    with xr.open_dataset(path, engine="h5netcdf", group="branches/primary/special_points/state") as ds:
        assert ds.unknowns.dims == ("special", "unknown")
        assert np.array_equal(ds.unknowns.values, stored["special_unknowns"])
    assert dict(result.to_xarray("primary", "special").sizes) == {"special": len(stored["special_points"])}


def test_bad_plot_arguments_are_plot_errors(result):
    for points in ([], 5, ["a"]):
        with pytest.raises(bc.PlotError, match="points"):
            bc.plot(result, "shapes", points=points)
    with pytest.raises(bc.PlotError, match="not matplotlib Axes"):
        bc.plot(result, "shapes", ax=42)


def test_plot_panels_must_match(result):
    import matplotlib.figure

    fig = matplotlib.figure.Figure()
    ax = fig.add_subplot()
    with pytest.raises(bc_plot_error(), match="2 panels"):
        bc.plot(result, "pressure-equator", ax=ax)
    assert bc.plot(result, "pressure-equator", ax=fig.subplots(1, 2)) is fig


def bc_plot_error():
    from balloon_cg.post.plotting import PlotError
    return PlotError


def test_trace_and_load_from_paths(tmp_path):
    traced = bc.trace(SCENES / "spom1.toml")
    assert list(traced.branches) == ["primary"] and traced.complete
    assert bc.plot(traced.save(tmp_path / "t.h5"), "pressure-pole").axes


def test_import_is_light():
    code = "import sys, balloon_cg; print(sorted(m for m in ('numpy', 'numba', 'matplotlib', 'h5py') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
    assert "numpy" not in dir(bc) and {"analyse", "trace", "load", "plot", "Scene"} <= set(dir(bc))


def test_inspect_of_a_run_file_loads_neither_numba_nor_scipy(tmp_path):
    """`inspect` of a run file of the current format without surface branches, in a fresh interpreter, imports
    neither numba nor scipy (app/cli.py: inspect starts fast; ~0.6 s of CPU of every such process, issue 37): the
    reader builds no solver and writes no provenance."""
    from balloon_cg.app.cli import main

    assert main(["run", str(SCENES / "spom1.toml"), "--set", "continuation.stop_stretch=1.4", "-o",
                 str(tmp_path / "r.h5"), "--quiet"]) == 0
    code = ("import sys\nfrom balloon_cg.app.cli import main\nassert main(['inspect', 'r.h5']) == 0\n"
            "print(sorted(m for m in ('numba', 'scipy', 'matplotlib') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=tmp_path)
    assert out.stdout.strip().splitlines()[-1] == "[]", out.stdout


def test_a_run_loads_no_plotting_nor_the_scipy_it_does_not_use(tmp_path):
    """`run` in a fresh interpreter imports neither matplotlib, SymPy, pandas nor scipy's optimize, sparse,
    integrate and interpolate: each is start-up time of every command (scipy.optimize alone ~0.2 s of CPU, a fifth
    of the run path's imports)."""
    heavy = ("matplotlib", "sympy", "pandas", "scipy.optimize", "scipy.sparse", "scipy.integrate", "scipy.interpolate")
    code = (f"import sys\nfrom balloon_cg.app.cli import main\n"
            f"assert main(['run', {str(SCENES / 'spom1.toml')!r}, '--set', 'continuation.stop_stretch=1.4', '-o', "
            f"'r.h5', '--quiet']) == 0\nprint(sorted(m for m in {heavy!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=tmp_path)
    assert out.stdout.strip() == "[]"
