"""Command line: run, solve, inspect, critical and the one-line errors for bad input."""
import json
from pathlib import Path

import numpy as np
import pytest

import balloon_cg as bc
from balloon_cg.app.cli import main
from balloon_cg.io.curve_file import read_curve
from balloon_cg.scene.materials import PRESETS
from netcdf_groups import uncoordinated

SCENES = Path(__file__).resolve().parents[1] / "scenes"
SPOM1 = SCENES / "spom1.toml"

SMALL = """
[material]
preset = "SPOM1"
[continuation]
stop_stretch = 2.0
"""


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    return path


def exact_sphere_pressure(lam):
    m = PRESETS["SPOM1"]
    return 2 * sum(mu * (lam ** (a - 3) - lam ** (-2 * a - 3)) for mu, a in zip(m.mu, m.alpha))


def one_error_line(capsys, *words):
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("balloon-cg: error: ") and "Traceback" not in err
    for word in words:
        assert word in err
    return err


def test_run_then_inspect(tmp_path, scene_file, capsys):
    out = tmp_path / "run.h5"
    assert main(["run", str(scene_file), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    for item in ("points", "pressure", "LP", "EP", "stop reason", "max residual", "error estimate vs trace time",
                 "run time"):
        assert item in text

    assert main(["inspect", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["scene_name"] == "small"
    assert summary["provenance"]["command"] == f"balloon-cg run {scene_file} -o {out}"
    assert summary["provenance"]["format"] == "balloon-cg/6"
    branch = summary["branches"]["primary"]
    # SPOM1 up to stretch 2: the fold in P and the first pear pitchfork (λ = 1.6799), its pear branches
    assert [s["kind"] for s in branch["special_points"]] == ["EP", "LP", "BP", "EP"]
    assert branch["special_points"][2]["classification"] == "pitchfork-super"
    assert branch["special_points"][2]["block"] == "odd_held" and branch["special_points"][2]["status"] == "located"
    assert branch["stop_codes"] == {"up": "stop_stretch", "down": "min_stretch"}
    assert {"pear_0", "pear_0_mirror"} <= set(summary["branches"])
    assert summary["branches"]["pear_0"]["parent"] == ["primary", 0]
    pear, mirror = summary["branches"]["pear_0"], summary["branches"]["pear_0_mirror"]
    assert (pear["origin"], pear["reflection_of"]) == ("traced", "")
    assert (mirror["origin"], mirror["reflection_of"]) == ("reflected", "pear_0") and mirror["parent"] == ["primary", 0]
    assert mirror["lam2_top"] == pytest.approx(pear["lam2_bottom"], rel=1e-12)
    assert summary["snap_throughs"][0]["from_branch"] == "primary"
    assert branch["lam2_top"][1] == pytest.approx(2.0, abs=1e-12)
    assert branch["max_residual"] < 1e-10 and branch["max_error_estimate"] < 1e-10
    assert branch["points"] > 10 and branch["wall_time"] > 0
    timing = summary["run_time"]  # every phase that ran, writing included, within the whole run's time
    assert {"trace", "stability", "branch points", "pear branches", "writing"} <= set(timing["phases"])
    assert 0 < sum(timing["phases"].values()) <= timing["total"]

    assert main(["inspect", str(out)]) == 0
    text = capsys.readouterr().out
    assert "branch primary" in text
    assert "the reflection z → −z of pear_0" in text.split("branch pear_0_mirror")[1]
    # an EP is a stored point, an LP or BP lies between two (docs/hdf5.md: index); counts named by control
    primary = text.split("branch primary")[1].split("branch ")[0]
    lp, bp = (branch["special_points"][k]["index"] for k in (1, 2))
    assert "EP                  point 0 " in primary and f"LP                  points {lp}-{lp + 1} " in primary
    assert f"BP pitchfork-super  points {bp}-{bp + 1} " in primary
    stable = branch["stable_points"]
    assert (f"stable points        pressure control {stable['stable_pressure']}, gas control "
            f"{stable['stable_gas']}, volume control {stable['stable_volume']} (of {branch['points']}") in primary


def test_run_keeps_existing_output(tmp_path, scene_file, capsys):
    out = tmp_path / "run.h5"
    out.write_bytes(b"keep me")
    assert main(["run", str(scene_file), "-o", str(out), "--quiet"]) == 2
    one_error_line(capsys, "run.h5", "--force")
    assert out.read_bytes() == b"keep me"
    assert main(["run", str(scene_file), "-o", str(out), "--quiet", "--force"]) == 0
    assert capsys.readouterr().out == ""
    assert main(["inspect", str(out), "--json"]) == 0


@pytest.mark.parametrize("stretch", [1.005, 1.5, 3.0])  # 1.005: below the scene's start_stretch 1.01
def test_solve_json_matches_sphere(stretch, capsys):
    assert main(["solve", str(SPOM1), "--pole-stretch", str(stretch), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert set(result) == {
        "pressure", "lam2_top", "lam2_bottom", "eta_top", "eta_bottom", "lam1_equator", "lam2_equator",
        "residual", "error_estimate", "wall_time",
    }
    assert result["pressure"] == pytest.approx(exact_sphere_pressure(stretch), rel=1e-10, abs=0)
    assert result["lam2_top"] == pytest.approx(stretch, rel=1e-12)
    for key in ("lam2_bottom", "lam1_equator", "lam2_equator", "eta_top"):
        assert result[key] == pytest.approx(stretch, rel=1e-10)
    assert result["eta_bottom"] == pytest.approx(-stretch, rel=1e-10)


def test_solve_table(scene_file, capsys):
    assert main(["solve", str(scene_file), "--pole-stretch", "1.5"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[0] == "pressure" and len(lines) == 10


def test_solve_not_reached(tmp_path, capsys):
    path = tmp_path / "short.toml"
    path.write_text(SMALL + "max_points = 5\n")
    assert main(["solve", str(path), "--pole-stretch", "3"]) == 1
    one_error_line(capsys, "did not reach north pole stretch 3", "largest stretch reached")


def test_solve_bad_stretch(scene_file, capsys):
    for stretch in ("0.5", "1", "nan"):
        assert main(["solve", str(scene_file), "--pole-stretch", stretch]) == 2
        one_error_line(capsys, "--pole-stretch", "must be > 1")


def test_bad_scene(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text('[material]\npreset = "SPOM1"\n[solver]\ndegree = 3\n')
    out = tmp_path / "run.h5"
    assert main(["run", str(path), "-o", str(out)]) == 2
    one_error_line(capsys, "bad.toml", "solver.degree")
    assert not out.exists()


def test_missing_and_unreadable_files(tmp_path, capsys):
    assert main(["run", str(tmp_path / "missing.toml"), "-o", str(tmp_path / "x.h5")]) == 2
    one_error_line(capsys, "missing.toml")
    assert main(["inspect", str(tmp_path / "missing.h5")]) == 2
    one_error_line(capsys, "missing.h5")
    junk = tmp_path / "junk.h5"
    junk.write_text("not hdf5")
    assert main(["inspect", str(junk)]) == 2
    one_error_line(capsys, "junk.h5", "HDF5")
    assert list(tmp_path.iterdir()) == [junk]


def test_critical_alpha1_from_the_command_line(tmp_path, capsys):
    """`critical` continues the pear pitchfork in alpha1 and reports where the isola closes (closed form:
    1.739619649392, tests/test_two_parameter.py); `plot --what phase` draws the curve."""
    scene = tmp_path / "spom1.toml"
    scene.write_text('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 4.0\n')
    out = tmp_path / "curve.h5"
    assert main(["critical", str(scene), "--parameter", "alpha1", "-o", str(out)]) == 0
    captured = capsys.readouterr()
    assert "critical alpha1 = 1.73961964939" in captured.out
    assert "continuing it in alpha1" in captured.err and "ended: isola_merge" in captured.err  # progress
    assert read_curve(out)["attrs"]["end"] == "isola_merge"
    assert main(["plot", str(out), "--what", "phase", "-o", str(tmp_path / "phase.png")]) == 0
    assert (tmp_path / "phase.png").stat().st_size > 1000
    capsys.readouterr()
    assert main(["inspect", str(out), "--json"]) == 0  # inspect reads curve files; strict JSON (NaN -> null)
    summary = json.loads(capsys.readouterr().out, parse_constant=lambda c: pytest.fail(c))
    assert summary["kind"] == "curve" and summary["curves"]["pear"]["critical_q"] == pytest.approx(1.739619649392)
    xr = pytest.importorskip("xarray")
    with xr.open_dataset(out, engine="h5netcdf", group="two_parameter/pear") as ds:
        assert ds.mode.dims == ("point", "mode_unknown") and all("long_name" in v.attrs for v in ds.variables.values())
        assert "alpha1" in ds.coords and ds.alpha1.dims == ("point",) and ds.pressure.alpha1.size == ds.sizes["point"]
        assert "α1" in ds.alpha1.attrs["long_name"] and ds.alpha1.attrs["units"] == "1"
        assert "units" not in ds.point.attrs
    assert uncoordinated(out) == []  # special_points/state opened alone: special, unknown


def test_critical_M_of_the_single_coil_scene(tmp_path, capsys):
    """The shipped single-coil scene (coil radius 4): the pitchforks merge at M = 4.1876946802 (as
    tests/test_two_parameter.py), at P > 0, and the curve returns to the partner; --quiet: nothing on stderr."""
    out = tmp_path / "single.h5"
    assert main(["critical", str(SCENES / "spom1_single_coil.toml"), "--parameter", "M", "-o", str(out),
                 "--quiet"]) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("critical M = 4.187694680") and captured.err == ""
    attrs = read_curve(out)["attrs"]
    assert attrs["end"] == "isola_merge" and attrs["stop_code"] == "partner"
    assert attrs["critical_q"] == pytest.approx(4.1876946802, abs=1e-9)


@pytest.mark.parametrize("M", ["0.001", "0.002"])
def test_critical_M_between_two_coils_is_not_claimed(M, tmp_path, capsys):
    """Issue 11: between the two opposed coils the pitchfork curve reaches P = 0 (near M = 0.28) before it turns
    back in M (at P ≈ −1.8): no isola closes, so no critical M: one line saying how the curve ended, exit 1, and
    the curve file is still written."""
    out = tmp_path / "curve.h5"
    assert main(["critical", str(SCENES / f"spom1_two_coils_M{M}.toml"), "--parameter", "M", "-o", str(out),
                 "--quiet"]) == 1
    err = one_error_line(capsys, "no critical M", "P reached 0 at M = 0.2", "before the curve turned back in M",
                         "nonpositive_pressure", "written to", str(out))
    assert "critical M =" not in err
    data = read_curve(out)
    assert data["attrs"]["end"] == "nonpositive_pressure" and data["attrs"]["stop_code"] == "nonpositive_pressure"
    assert np.isnan(data["attrs"]["critical_q"]) and (data["pressure"] > 0).all()


def test_critical_refuses_a_scene_without_equator_symmetry(tmp_path, capsys):
    scene = tmp_path / "offset.toml"
    scene.write_text('[material]\npreset = "SPOM1"\n[field]\nM = 0.002\n'
                     '[[field.coils]]\nradius = 4.0\nheight = 0.5\ncurrent = 1.0\n')
    out = tmp_path / "curve.h5"
    for parameter in ("M", "alpha1"):
        assert main(["critical", str(scene), "--parameter", parameter, "-o", str(out)]) == 2
        one_error_line(capsys, "critical needs an equator-symmetric scene", "offset.toml", "coil 0", "height 0.5")
    assert not out.exists()


def test_critical_in_M_needs_coils(tmp_path, capsys):
    out = tmp_path / "curve.h5"
    assert main(["critical", str(SPOM1), "--parameter", "M", "-o", str(out)]) == 2
    one_error_line(capsys, "--parameter M needs coils", "spom1.toml")
    assert not out.exists()


def test_critical_without_a_pear_pitchfork(tmp_path, capsys):
    scene = tmp_path / "short.toml"
    scene.write_text('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 1.5\n')  # first pear: 1.68
    out = tmp_path / "curve.h5"
    assert main(["critical", str(scene), "--parameter", "alpha1", "-o", str(out), "--quiet"]) == 1
    one_error_line(capsys, "no pear-shaped pitchfork on the primary branch", "short.toml")
    assert not out.exists()


def test_a_set_material_is_stored_as_computed_not_as_its_preset(tmp_path):
    """``--set material.mu[0]=1`` on TPOM2 (μ1 = 2.0202): the file names the material ``TPOM2 (mu1 = 1)``, stores
    μ1 = 1, and its pressures are those of μ1 = 1 (the sphere's closed form, MODEL.md §4, P = 2 μ1 (λ^(α1 − 3) −
    λ^(−2α1 − 3)), here with α1 = 1.98)."""
    out = tmp_path / "tpom2_mu1.h5"
    assert main(["run", str(SCENES / "tpom2.toml"), "--set", "material.mu[0]=1", "--set", "stop_stretch=1.3",
                 "-o", str(out), "--quiet"]) == 0
    result = bc.load(out)
    material = result.scene.material
    assert material.name == "TPOM2 (mu1 = 1)" and material.mu == (1.0,) and material.alpha == (1.98,)
    assert material != PRESETS["TPOM2"] and material.name != PRESETS["TPOM2"].name
    primary = result.branches["primary"]
    lam, pressure = primary["lam2_top"], primary["pressure"]
    assert len(lam) > 5
    assert np.allclose(pressure, 2 * 1.0 * (lam ** (1.98 - 3) - lam ** (-2 * 1.98 - 3)), rtol=1e-9, atol=0)
    assert not np.allclose(pressure, 2 * 2.0202 * (lam ** (1.98 - 3) - lam ** (-2 * 1.98 - 3)), rtol=1e-3)
