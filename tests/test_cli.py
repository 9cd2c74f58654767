"""Command line: run, solve, inspect and the one-line errors for bad input."""
import json
from pathlib import Path

import pytest

from balloon_cg.app.cli import main
from balloon_cg.scene.materials import PRESETS

SPOM1 = Path(__file__).resolve().parents[1] / "scenes" / "spom1.toml"

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
    for item in ("points", "pressure", "LP", "EP", "stop reason", "max residual", "error estimate vs run time"):
        assert item in text

    assert main(["inspect", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["scene_name"] == "small"
    assert summary["provenance"]["command"] == f"balloon-cg run {scene_file} -o {out}"
    assert summary["provenance"]["format"] == "balloon-cg/2"
    branch = summary["branches"]["primary"]
    # SPOM1 up to stretch 2: the fold in P and the first pear pitchfork (λ = 1.6799), its pear branches
    assert [s["kind"] for s in branch["special_points"]] == ["EP", "LP", "BP", "EP"]
    assert branch["special_points"][2]["classification"] == "pitchfork-super"
    assert branch["special_points"][2]["block"] == "odd_held" and branch["special_points"][2]["status"] == "located"
    assert branch["stop_codes"] == {"up": "stop_stretch", "down": "min_stretch"}
    assert {"pear_0", "pear_0_mirror"} <= set(summary["branches"])
    assert summary["branches"]["pear_0"]["parent"] == ["primary", 0]
    assert summary["snap_throughs"][0]["from_branch"] == "primary"
    assert branch["lam2_north"][1] == pytest.approx(2.0, abs=1e-12)
    assert branch["max_residual"] < 1e-10 and branch["max_error_estimate"] < 1e-10
    assert branch["points"] > 10 and branch["wall_time"] > 0

    assert main(["inspect", str(out)]) == 0
    assert "branch primary" in capsys.readouterr().out


def test_run_keeps_existing_output(tmp_path, scene_file, capsys):
    out = tmp_path / "run.h5"
    out.write_bytes(b"keep me")
    assert main(["run", str(scene_file), "-o", str(out), "--quiet"]) == 2
    one_error_line(capsys, "run.h5", "--force")
    assert out.read_bytes() == b"keep me"
    assert main(["run", str(scene_file), "-o", str(out), "--quiet", "--force"]) == 0
    assert capsys.readouterr().out == ""
    assert main(["inspect", str(out), "--json"]) == 0


@pytest.mark.parametrize("stretch", [1.5, 3.0])
def test_solve_json_matches_sphere(stretch, capsys):
    assert main(["solve", str(SPOM1), "--pole-stretch", str(stretch), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert set(result) == {
        "pressure", "lam2_north", "lam2_south", "eta_north", "eta_south", "lam1_equator", "lam2_equator",
        "residual", "error_estimate", "wall_time",
    }
    assert result["pressure"] == pytest.approx(exact_sphere_pressure(stretch), rel=1e-10, abs=0)
    assert result["lam2_north"] == pytest.approx(stretch, rel=1e-12)
    for key in ("lam2_south", "lam1_equator", "lam2_equator", "eta_north"):
        assert result[key] == pytest.approx(stretch, rel=1e-10)
    assert result["eta_south"] == pytest.approx(-stretch, rel=1e-10)


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
    assert main(["solve", str(scene_file), "--pole-stretch", "0.5"]) == 2
    one_error_line(capsys, "--pole-stretch")


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
    assert "critical alpha1 = 1.73961964939" in capsys.readouterr().out
    assert main(["plot", str(out), "--what", "phase", "-o", str(tmp_path / "phase.png")]) == 0
    assert (tmp_path / "phase.png").stat().st_size > 1000
