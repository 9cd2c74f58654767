"""``balloon-cg sweep`` over a tube scene (issue 38): each member is what ``balloon-cg run`` writes for the member's
scene alone, bit for bit (its branches and located points), serially and on two workers; the table holds per member
the uniform pressure maximum, the onset of bulging, the bulge's volume fold and Maxwell's pressure (those of its
branches); the same command again computes nothing (resume); a bad value exits 2 with one line and writes nothing."""
import json
import tomllib
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


@pytest.fixture(scope="module")
def alone(folder) -> list:
    """Each member's scene run alone by ``balloon-cg run`` (its tube run file), once for the tests that compare."""
    paths = [folder / f"alone_{index}.h5" for index in range(len(LENGTHS))]
    for path, length in zip(paths, LENGTHS):
        assert main(["run", str(folder / "t.toml"), "--set", f"geometry.length={length}", "-o", str(path),
                     "--quiet"]) == 0
    return paths


def sweep_argv(folder: Path, output: str, workers: str = "1") -> list:
    return ["sweep", str(folder / "t.toml"), *VARY, "-o", str(folder / output), "--workers", workers]


def test_each_member_is_the_run_of_its_scene_alone(folder, alone):
    sweep = bc.load(folder / "serial.h5")
    table = sweep.to_dataframe()
    assert list(table["geometry.length"]) == list(LENGTHS) and table.complete.all()
    for index, path in enumerate(alone):
        run = read_tube_run(path)
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


def test_inspect_summarises_every_member_by_its_tube_summary(folder, alone, capsys):
    """``inspect`` of a tube sweep (text and --json): per member its verdict, branches and the primary's summary,
    the one ``inspect`` gives the member's own run (app/tube_summary.py; a sphere's branch summary read attributes a
    tube branch does not store: KeyError, exit 3, before)."""
    from balloon_cg.app.tube_summary import summarise_tube

    assert main(["inspect", str(folder / "serial.h5")]) == 0
    text = capsys.readouterr().out
    assert main(["inspect", "--json", str(folder / "serial.h5")]) == 0
    members = json.loads(capsys.readouterr().out)["members"]
    sweep = bc.load(folder / "serial.h5")
    for index, length in enumerate(LENGTHS):
        member = members[str(index)]
        assert f"member {index:<4} geometry.length = {length:g}: complete" in text and member["complete"]
        whole = summarise_tube(read_tube_run(alone[index]))
        assert member["primary"] == json.loads(json.dumps(whole["branches"]["primary"]))
        assert (whole["complete"], whole["result"]) == (True, "complete")  # the run file's stored verdict
        assert member["branches"] == {name: len(b["pressure"]) for name, b in sweep.members[index].branches.items()}


def test_phase_draws_each_members_onset_maximum_fold_and_maxwell_pressure(folder):
    """``plot --what phase`` of a tube sweep: the table's P_onset, P_max, P_LV and P_M against the varied length
    (the sphere's pear pitchforks, which a tube has none of, drew only the LP before, under a pear title)."""
    from balloon_cg.post.plotting import TUBE_PHASE, plot_phase

    table = bc.load(folder / "serial.h5").to_dataframe()
    fig = plot_phase([folder / "serial.h5"])
    (ax,) = fig.axes
    lines = {line.get_label().split(": ", 1)[1]: line for line in ax.get_lines()}
    for column, label, _ in TUBE_PHASE:
        assert list(lines[label].get_xdata()) == list(LENGTHS)
        assert np.array_equal(lines[label].get_ydata(), table[column].to_numpy(), equal_nan=True)
    assert "onset of bulging" in ax.get_title() and "pear" not in ax.get_title()


def test_a_bad_value_exits_2_in_one_line_and_writes_nothing(folder, capsys):
    assert main(["sweep", str(folder / "t.toml"), "--vary", "geometry.length=-1,10", "-o",
                 str(folder / "bad.h5"), "--workers", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "geometry.length = -1: must be in [0.1, 1000]" in err[0]
    assert not (folder / "bad.h5").exists() and not (folder / "bad.h5.members").exists()


def test_a_member_whose_branch_stopped_unresolved_or_did_not_start_is_incomplete():
    """tube/picture.gaps, the verdict every tube run file stores (io/tube_file.write_tube), by which ``run`` exits 1
    and a sweep member is incomplete: the stage a signal stopped, every branch that did not start, every branch
    stopped unresolved (at its layout's cap, after its resolved points), nothing else."""
    from types import SimpleNamespace

    from balloon_cg.analysis.results import IntervalStop, StopCode
    from balloon_cg.analysis.verdict import Gap
    from balloon_cg.numerics.continuation import Stop, TraceStop
    from balloon_cg.tube.picture import Stage, TubePicture, gaps

    def branch(code):
        return SimpleNamespace(stop=Stop(code, f"stopped: {code.value}"), pressure=np.zeros(7))

    whole = TubePicture({"primary": branch(IntervalStop.HOOP_STRETCH), "bulge": branch(TraceStop.MAX_POINTS)}, None)
    assert gaps(whole) == []
    capped = TubePicture({"primary": branch(IntervalStop.HOOP_STRETCH), "bulge": branch(IntervalStop.UNRESOLVED)},
                         None, not_started=(("bulge_3", "its first step did not converge"),))
    assert [(g.gap, g.branch) for g in gaps(capped)] == [(Gap.NOT_STARTED, "bulge_3"), (Gap.STOPPED_SHORT, "bulge")]
    assert gaps(capped)[1].message == "stopped: unresolved, after 7 resolved points (its stop code unresolved)"
    stopped = TubePicture({"primary": branch(StopCode.INTERRUPTED)}, None, interrupted=Stage.PRIMARY)
    assert [(g.gap, g.branch) for g in gaps(stopped)] == [(Gap.INTERRUPTED, "primary")]


def test_a_tube_file_written_before_the_elements_default_reads_its_scene_as_flag():
    """A tube's solver.tube_resolution defaults to "elements" from readings revision scene.tables.ELEMENTS_SINCE on:
    a stored tube text without the key read under an older revision is "flag" (what it ran), under this one or as a
    new scene "elements"; a tube's normalised text always names it (sweep hashes of old and new members differ)."""
    from balloon_cg.io.legacy import READINGS
    from balloon_cg.scene import parse_scene
    from balloon_cg.scene.tables import ELEMENTS_SINCE, parse_stored

    assert "tube_resolution" not in tomllib.loads(SCENE)["solver"] and READINGS >= ELEMENTS_SINCE
    assert parse_stored(SCENE, written=ELEMENTS_SINCE - 1).solver.tube_resolution == "flag"
    assert parse_scene(SCENE, written=0).solver.tube_resolution == "flag"
    for written in (None, ELEMENTS_SINCE, READINGS):
        assert parse_stored(SCENE, written=written).solver.tube_resolution == "elements"
    explicit = SCENE.replace("[solver]", '[solver]\ntube_resolution = "refine"')
    assert parse_stored(explicit, written=0).solver.tube_resolution == "refine"
    assert 'tube_resolution = "elements"' in parse_scene(SCENE).to_toml()
    assert "tube_resolution" not in parse_scene('[material]\npreset = "spom1"\n').to_toml()
