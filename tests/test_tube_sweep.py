"""``balloon-cg sweep`` over a tube scene (issue 38): each member is what ``balloon-cg run`` writes for the member's
scene alone, bit for bit (its branches and located points), serially and on two workers; the table holds per member
the uniform pressure maximum, the onset of bulging, the bulge's volume fold and Maxwell's pressure (those of its
branches); the same command again computes nothing (resume); a bad value exits 2 with one line and writes nothing."""
from pathlib import Path

import numpy as np
import pytest

import balloon_cg as bc
from balloon_cg.app.cli import main
from balloon_cg.io.tube_file import read_tube_run

ROOT = Path(__file__).resolve().parents[1]
SCENE = ((ROOT / "scenes" / "tube_spom1_L10.toml").read_text()
         .replace("degree = 40", "degree = 16").replace("stop_stretch = 9.0", "stop_stretch = 3.0"))  # ~2 s a member
LENGTHS = (8.0, 10.0)
VARY = ["--vary", "geometry.length=8,10"]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("tube_sweep")
    (folder / "t.toml").write_text(SCENE)
    assert main(["sweep", str(folder / "t.toml"), *VARY, "-o", str(folder / "serial.h5"), "--workers", "1",
                 "--quiet"]) == 0
    return folder


def sweep_argv(folder: Path, output: str, workers: str = "1") -> list:
    return ["sweep", str(folder / "t.toml"), *VARY, "-o", str(folder / output), "--workers", workers]


def test_each_member_is_the_run_of_its_scene_alone(folder):
    sweep = bc.load(folder / "serial.h5")
    table = sweep.to_dataframe()
    assert list(table["geometry.length"]) == list(LENGTHS) and table.complete.all()
    for index, length in enumerate(LENGTHS):
        alone = folder / f"alone_{index}.h5"
        assert main(["run", str(folder / "t.toml"), "--set", f"geometry.length={length}", "-o", str(alone),
                     "--quiet"]) == 0
        run = read_tube_run(alone)
        member = sweep.members[index]
        assert set(member.branches) == set(run["branches"]) and {"primary", "bulge"} < set(run["branches"])
        for name, branch in run["branches"].items():
            stored = member.branches[name]
            assert np.array_equal(stored["unknowns"], branch["unknowns"])
            assert np.array_equal(stored["pressure"], branch["pressure"])
            assert stored["special_points"] == branch["special_points"]
        primary, bulge = run["branches"]["primary"]["special_points"], run["branches"]["bulge"]["special_points"]
        onset = next(s for s in primary if (s["kind"], s["block"]) == ("BP", "odd"))
        row = table.loc[index]
        assert row.P_max == next(s for s in primary if s["kind"] == "LP")["pressure"]
        assert (row.P_onset, row.V_onset) == (onset["pressure"], onset["volume"])
        assert row.P_LV == next(s for s in bulge if s["kind"] == "LV")["pressure"]
        assert row.P_M == run["attrs"]["maxwell_pressure"]
    # the onset of the mode cos(πS/L) falls towards the pressure maximum as the tube grows longer
    assert table.P_onset[0] < table.P_onset[1] < table.P_max[1]


def test_the_same_command_resumes_and_two_workers_give_the_same_members(folder, capsys):
    before = {p.name: p.read_bytes() for p in (folder / "serial.h5.members").iterdir()}
    assert main(sweep_argv(folder, "serial.h5")) == 0
    out = capsys.readouterr().out
    assert "members        2: 0 computed, 2 already in the file, 0 failed" in out
    assert "P_max" in out and "P_onset" in out and "P_M" in out
    assert {p.name: p.read_bytes() for p in (folder / "serial.h5.members").iterdir()} == before
    assert main(sweep_argv(folder, "pool.h5", "2") + ["--quiet"]) == 0
    serial, pool = bc.load(folder / "serial.h5"), bc.load(folder / "pool.h5")
    for index in range(len(LENGTHS)):
        for name, branch in serial.members[index].branches.items():
            assert np.array_equal(pool.members[index].branches[name]["unknowns"], branch["unknowns"])
    assert serial.to_dataframe().equals(pool.to_dataframe())


def test_a_bad_value_exits_2_in_one_line_and_writes_nothing(folder, capsys):
    assert main(["sweep", str(folder / "t.toml"), "--vary", "geometry.length=-1,10", "-o",
                 str(folder / "bad.h5"), "--workers", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "geometry.length = -1: must be in [0.1, 1000]" in err[0]
    assert not (folder / "bad.h5").exists() and not (folder / "bad.h5.members").exists()
