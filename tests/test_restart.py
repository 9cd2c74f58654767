"""Labels and ``continue`` (app/restart.py): every special point of a run file has a unique label; restarting from
one reproduces the branch, and from a fold in a second parameter gives the fold curve ``critical --of`` gives."""
import json
import re
import shutil

import numpy as np
import pytest

from balloon_cg.analysis.branches.problem import branch_system
from balloon_cg.app.cli import main
from balloon_cg.app.restart import find_label, stored_branch
from balloon_cg.io.curve_file import read_curve
from balloon_cg.io.run_file import read_run
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import load_scene
from shared_pictures import two_coil_run_file, two_coil_scene_to

GENT = '[material]\npreset = "Gent"\n[continuation]\nstart_stretch = 1.01\nmin_stretch = 1.005\nstop_stretch = 5.0\n'
EVENTS = '\n[[events]]\nquantity = "volume"\nvalue = 20\n'


def special(path, kind):
    """(label, dict) of every special point of ``kind`` in a run file, in file order."""
    return [(s["label"], s) for b in read_run(path)["branches"].values() for s in b["special_points"]
            if s["kind"] == kind]


def on_branch(original, X):
    """P of the point of the stored branch ``original`` at the north pole stretch of X (Newton from its stored
    point nearest in (λ2(0), P): past a turning point of λ2(0) two points share it), to compare a restarted point
    with the branch it came from."""
    system, solver = branch_system(original), original.scene.solver
    north = np.append(original.disc.pole_rows()["lam2_top"], 0.0)
    nearest = original.X[np.argmin(np.hypot(original.X @ north - north @ X, original.X[:, -1] - X[-1]))]
    result = newton(system.residual, system.jacobian, nearest, north, north @ X, solver.tol, solver.max_newton)
    assert result.converged
    return result.x[-1]


@pytest.fixture(scope="module")
def gent_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("gent")
    (folder / "gent.toml").write_text(GENT)
    assert main(["run", str(folder / "gent.toml"), "--primary-only", "-o", str(folder / "gent.h5"), "--quiet"]) == 0
    return folder


def test_labels_are_unique_and_shown_by_inspect(gent_run, capsys):
    path = gent_run / "gent.h5"
    labels = [s["label"] for b in read_run(path)["branches"].values() for s in b["special_points"]]
    assert labels == list(range(1, len(labels) + 1)) and len(labels) == 4  # EP, LP, LP, EP
    capsys.readouterr()
    assert main(["inspect", str(path)]) == 0
    lines = [line.split() for line in capsys.readouterr().out.splitlines()]
    assert [(int(line[0]), line[1]) for line in lines if len(line) > 2 and line[0].isdigit()] == \
        [(1, "EP"), (2, "LP"), (3, "LP"), (4, "EP")]


def test_continue_from_a_fold_in_Jm_gives_the_cusp(gent_run, capsys):
    """`continue RUN LABEL --parameter Jm` from the maximum of P (an LP label): the LP curve and its cusp, the same
    as `critical --of LP` (tests/test_fold_curve.py checks it against the closed form)."""
    (label, point), _ = special(gent_run / "gent.h5", "LP")
    out = gent_run / "lp.h5"
    assert main(["continue", str(gent_run / "gent.h5"), str(label), "--parameter", "material.parameters.Jm",
                 "--direction", "-1", "-o", str(out)]) == 0
    assert "LP curve from label 2 in Jm" in capsys.readouterr().out
    attrs = read_curve(out, "LP")["attrs"]
    assert attrs["end"] == "cusp" and attrs["critical_q"] == pytest.approx(17.6380800759137, abs=1e-9)


def test_continue_from_a_fold_in_P_reproduces_the_branch(gent_run):
    """Without --parameter: the branch through the labelled point traced again; every point lies on the stored
    branch (P at its pole stretch) to 1e-10, and the two folds are found again to 1e-10."""
    path, out = gent_run / "gent.h5", gent_run / "again.h5"
    (label, _), _ = special(path, "LP")
    assert main(["continue", str(path), str(label), "-o", str(out), "--quiet"]) == 0
    run, again = read_run(path), read_run(out)
    original, continued = stored_branch(run, "primary"), stored_branch(again, "primary")
    assert np.abs([on_branch(original, X) - X[-1] for X in continued.X]).max() < 1e-10
    folds = [s["pressure"] for _, s in special(path, "LP")]
    assert np.abs(np.array([s["pressure"] for _, s in special(out, "LP")]) - folds).max() < 1e-10
    assert json.loads(json.dumps(again["attrs"]["continued_from"])) == f"{path} label {label}"


def test_continue_from_a_user_point_of_the_two_coil_branch(tmp_path):
    """Two coils, M = 0.002, mapped basis: the restart from the UZ point (volume 20, an ordinary point of the
    branch) reproduces the primary branch to 1e-10 (every point, its LP and its UZ point). Its TP agrees only to
    the discretisation's error bound solver.max_error = 1e-9 (measured 1.9e-10; the cause is not isolated:
    presumably each trace locates the TP on the wire map in use when it passes the turn, re-centred near the
    coils, and the two traces reach it on different maps)."""
    scene = tmp_path / "two_coils.toml"
    scene.write_text(load_scene("spom1_two_coils_M0.002").to_toml() + EVENTS)
    path, out = tmp_path / "run.h5", tmp_path / "again.h5"
    assert main(["run", str(scene), "--primary-only", "-o", str(path), "--quiet"]) == 0
    [(label, point)] = special(path, "UZ")
    assert main(["continue", str(path), str(label), "-o", str(out), "--quiet"]) == 0
    original, continued = stored_branch(read_run(path), "primary"), stored_branch(read_run(out), "primary")
    assert continued.disc.mapping is not None
    assert np.abs([on_branch(original, X) - X[-1] for X in continued.X]).max() < 1e-10
    for kind, tolerance in (("LP", 1e-10), ("UZ", 1e-10), ("TP", original.scene.solver.max_error)):
        before, after = [s["pressure"] for _, s in special(path, kind)], [s["pressure"] for _, s in special(out, kind)]
        assert len(before) == len(after) == 1 and abs(before[0] - after[0]) < tolerance, kind
    assert "stability" not in read_run(out)["branches"]["primary"]  # as the stored branch: traced, not assessed


def test_continue_from_the_pear_pitchfork_gives_the_critical_curve(tmp_path, capsys):
    """SPOM1 at M = 0: `continue RUN LABEL --parameter alpha1` from the first pear BP label (its mode recomputed,
    not stored) traces the same curve as `critical --parameter alpha1` (every point to 1e-10) and its isola closes
    at the same critical α1 (1.739619649392: tests/test_two_parameter.py, closed form)."""
    scene = tmp_path / "spom1.toml"
    scene.write_text('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 4.0\n[surface]\nbranches = "none"\n')
    run, again, curve = tmp_path / "run.h5", tmp_path / "again.h5", tmp_path / "curve.h5"
    assert main(["run", str(scene), "-o", str(run), "--quiet"]) == 0
    (label, _), _ = special(run, "BP")
    assert main(["continue", str(run), str(label), "--parameter", "alpha1", "-o", str(again), "--quiet"]) == 0
    assert main(["critical", str(scene), "--parameter", "alpha1", "-o", str(curve), "--quiet"]) == 0
    capsys.readouterr()
    restarted, traced = read_curve(again), read_curve(curve)
    assert restarted["attrs"]["end"] == traced["attrs"]["end"] == "isola_merge"
    assert abs(restarted["attrs"]["critical_q"] - 1.739619649392) < 1e-11
    assert abs(restarted["attrs"]["critical_q"] - traced["attrs"]["critical_q"]) < 1e-10
    assert restarted["q"].shape == traced["q"].shape
    assert np.abs(restarted["q"] - traced["q"]).max() < 1e-10
    assert np.abs(restarted["pressure"] - traced["pressure"]).max() < 1e-10


def test_continue_with_set_finishes_a_run_that_stopped_at_max_points(gent_run, tmp_path, capsys):
    """A run stopped short at max_points = 30 (one fold of two, exit 1): `continue RUN LABEL --set
    continuation.max_points=200` from its fold reaches both ends, and its two folds are the full run's to 1e-10; a
    key that changes the equations is refused in one line (exit 2, nothing written)."""
    scene, short, out = tmp_path / "short.toml", tmp_path / "short.h5", tmp_path / "long.h5"
    scene.write_text(GENT + "max_points = 30\n")
    assert main(["run", str(scene), "--primary-only", "-o", str(short), "--quiet"]) == 1
    [(label, _)] = special(short, "LP")
    assert main(["continue", str(short), str(label), "-o", str(out), "--quiet"]) == 1  # max_points again
    assert main(["continue", str(short), str(label), "-o", str(out), "--quiet", "--force",
                 "--set", "continuation.max_points=200"]) == 0
    full = [s["pressure"] for _, s in special(gent_run / "gent.h5", "LP")]
    assert len(full) == 2 and np.abs(np.array([s["pressure"] for _, s in special(out, "LP")]) - full).max() < 1e-10
    capsys.readouterr()
    refused = tmp_path / "refused.h5"
    assert main(["continue", str(short), str(label), "-o", str(refused), "--set", "material.parameters.Jm=50"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--set material.parameters.Jm: continue keeps the stored point's" in err
    assert not refused.exists()


def test_continue_names_a_curve_file_and_a_direction_without_a_parameter(gent_run, capsys):
    """A curve file (no branches) and --direction without --parameter: one line each saying why, exit 2."""
    path, curve = gent_run / "gent.h5", gent_run / "cusp.h5"
    (label, _), _ = special(path, "LP")
    assert main(["continue", str(path), str(label), "--parameter", "material.parameters.Jm", "--direction", "-1",
                 "-o", str(curve), "--quiet"]) == 0
    capsys.readouterr()
    assert main(["continue", str(curve), "1", "-o", str(gent_run / "x.h5")]) == 2
    assert "has no branches (a curve file: continue starts from a point of a run file" in capsys.readouterr().err
    assert main(["continue", str(path), str(label), "--direction", "-1", "-o", str(gent_run / "x.h5")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--direction -1 starts a curve in a second parameter" in err
    assert not (gent_run / "x.h5").exists()


def test_continue_refuses_what_it_cannot_start_from(gent_run, capsys):
    """A label the file does not have, a second parameter from an end point: one line, exit 2, nothing written."""
    path = gent_run / "gent.h5"
    assert main(["continue", str(path), "9", "-o", str(gent_run / "x.h5")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "label 9: no special point has it" in err and "1..4" in err
    assert main(["continue", str(path), "1", "--parameter", "material.parameters.Jm", "-o", str(gent_run / "x.h5")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "label 1 is a EP" in err
    assert not (gent_run / "x.h5").exists()
    with pytest.raises(Exception):
        find_label(read_run(path), 0)


def test_continue_exits_1_when_the_branch_it_wrote_is_incomplete(tmp_path, capsys):
    """A restarted branch that stops short (max_points, as the run's did) is written flagged incomplete, and
    `continue` says so as `run` does: exit 1 with the verdict on stderr (it exited 0), `--allow-partial` exit 0."""
    scene = tmp_path / "short.toml"
    scene.write_text('[material]\npreset = "SPOM1"\n[continuation]\nmax_points = 5\n')
    run = tmp_path / "short.h5"
    assert main(["run", str(scene), "--primary-only", "-o", str(run), "--quiet"]) == 1
    capsys.readouterr()
    [(label, _)] = [(label, s) for label, s in special(run, "EP") if s["index"] > 0]
    out = tmp_path / "again.h5"
    assert main(["continue", str(run), str(label), "-o", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "stopped_short" in err and "maximum number of points (5)" in err
    assert not read_run(out)["attrs"]["complete"]
    assert main(["continue", str(run), str(label), "-o", str(out), "--force", "--quiet", "--allow-partial"]) == 0


def test_continue_from_python(gent_run):
    """``balloon_cg.continue_from``: the same as the command, a Result for the branch, the curve for a fold."""
    import balloon_cg as bc

    path = gent_run / "gent.h5"
    (label, point), _ = special(path, "LP")
    result = bc.continue_from(path, label)
    assert list(result.branches) == ["primary"] and result.complete
    lp = [s for s in result.special_points if s["kind"] == "LP"]
    assert abs(lp[0]["pressure"] - point["pressure"]) < 1e-10
    curve = bc.continue_from(path, label, "material.parameters.Jm", direction=-1.0)
    assert curve.end.value == "cusp" and abs(curve.critical[0] - 17.6380800759137) < 1e-9



@pytest.fixture(scope="module")
def two_coils(tmp_path_factory):
    """The shipped two-coil scene (M = 0.002) up to λ2(0) = 1.7, past its first held and free pear pitchforks (1.669,
    1.681), without surface branches: a folder with its run file (primary, pear branches; the session's
    ``shared_pictures.two_coil_run_file``, copied) and the scene file."""
    folder = tmp_path_factory.mktemp("two_coils")
    shutil.copyfile(two_coil_run_file(tmp_path_factory), folder / "run.h5")
    (folder / "two_coils.toml").write_text(two_coil_scene_to(1.7).to_toml())
    return folder


def leaves(group, prefix=""):
    """(path, value) of every dataset of a read group (nested dicts), e.g. a branch's stability."""
    for key, value in group.items():
        if isinstance(value, dict):
            yield from leaves(value, f"{prefix}{key}/")
        else:
            yield prefix + key, value


def first(path, kind, block=""):
    """The label of the first special point of ``kind`` (and ``block``) of the primary branch of a run file."""
    return next(s["label"] for s in read_run(path)["branches"]["primary"]["special_points"]
                if s["kind"] == kind and s["block"] == block)


@pytest.mark.parametrize("of, block", [("BP", "odd_held"), ("LP", "")])
def test_continue_in_M_from_a_two_coil_label_gives_the_critical_curve(two_coils, of, block, capsys):
    """Two coils: `continue RUN LABEL --parameter M` from the first pear pitchfork (its mode recomputed from the
    stored point) and from the LP traces the curve `critical --of BP|LP --parameter M` traces from its own primary
    branch: the same points (q and P to 1e-10: measured 7e-13 for the pitchforks, identical for the folds), ending
    alike (P reaches 0 before M turns back)."""
    run, again, curve = two_coils / "run.h5", two_coils / f"again_{of}.h5", two_coils / f"critical_{of}.h5"
    label = first(run, of, block)
    assert main(["continue", str(run), str(label), "--parameter", "M", "-o", str(again), "--quiet"]) == 0
    main(["critical", str(two_coils / "two_coils.toml"), "--of", of, "--parameter", "M", "-o", str(curve), "--quiet"])
    capsys.readouterr()
    group = "pear" if of == "BP" else of
    restarted, traced = read_curve(again, group), read_curve(curve, group)
    assert restarted["attrs"]["end"] == traced["attrs"]["end"]
    assert restarted["q"].shape == traced["q"].shape and len(traced["q"]) > 5
    assert abs(traced["q"][-1] - traced["q"][0]) > 1e-3  # the curve went somewhere in M
    assert np.abs(restarted["q"] - traced["q"]).max() < 1e-10
    assert np.abs(restarted["pressure"] - traced["pressure"]).max() < 1e-10


def test_continue_from_the_fold_of_an_assessed_run_locates_its_special_points_again(two_coils):
    """Restart in P from the LP of a run that was assessed: the branch is assessed again and its special points
    (LP, the held and free pear pitchforks, the m = 1 points, the ends) are the run's, in kind, block and
    classification, at the same P to 1e-10 (measured 3.3e-13). The restart starts one step away from the fold
    (``restart.step_away``): from the fold itself the even block's zero eigenvalue at the first point had a
    rounding sign, and a spurious transcritical BP was located there."""
    run, out = two_coils / "run.h5", two_coils / "from_lp.h5"
    assert main(["continue", str(run), str(first(run, "LP")), "-o", str(out), "--quiet"]) == 0
    before, after = [read_run(path)["branches"]["primary"] for path in (run, out)]
    assert "stability" in after
    key = [(s["kind"], s["block"], s["classification"]) for s in before["special_points"]]
    assert len(key) == 7 and key == [(s["kind"], s["block"], s["classification"]) for s in after["special_points"]]
    assert max(abs(a["pressure"] - b["pressure"])
               for a, b in zip(before["special_points"], after["special_points"])) < 1e-10
    # and its snap-through (the assessment's, as run lists it: at the LP to no stable state); it had none
    [snap], [again] = [read_run(path)["snap_throughs"] for path in (run, out)]
    assert (again["from_branch"], again["to_branch"]) == (snap["from_branch"], snap["to_branch"]) == ("primary", "")
    assert abs(again["pressure"] - snap["pressure"]) < 1e-3
    import balloon_cg as bc

    result = bc.continue_from(run, first(run, "LP"))  # the same from Python
    assert len(result.snap_throughs) == 1 and result.snap_throughs[0]["pressure"] == again["pressure"]


def test_a_restarted_pear_branch_stops_where_the_run_stops_pear_branches(two_coils, capsys):
    """Restart in P from the end of the held pear branch pear_0 (λ2(0) = stop_stretch 1.7): back through the
    pitchfork onto its mirror half, the branch stops where its south pole stretch reaches stop_stretch, landed on it,
    as `run` stops pear branches (pear_0_mirror there). It went on to λ2(π) = 3.0 and the wire instead, the north
    pole rule of a primary branch only, where the stability degree no longer resolved it."""
    run, out = two_coils / "run.h5", two_coils / "from_pear_end.h5"
    [(label, end)] = [(s["label"], s) for s in read_run(run)["branches"]["pear_0"]["special_points"]
                      if s["kind"] == "EP"]
    main(["continue", str(run), str(label), "-o", str(out), "--quiet", "--allow-partial"])
    branch = read_run(out)["branches"]["pear_0"]
    assert list(branch["attrs"]["leg_stop_codes"]) == ["stop_stretch", "bottom_stop_stretch"]
    assert abs(max(branch["lam2_bottom"]) - 1.7) < 1e-12 and abs(max(branch["lam2_top"]) - 1.7) < 1e-12
    mirror = read_run(run)["branches"]["pear_0_mirror"]
    assert abs(branch["pressure"][np.argmax(branch["lam2_bottom"])] - mirror["pressure"][-1]) < 1e-10
    # what is not searched on it: its branch points' branches; no "broken pitchfork" in a scene whose coils are
    # mirror-symmetric (the verdict said the pear branch of a broken pitchfork was not traced)
    capsys.readouterr()
    assert main(["inspect", str(out)]) == 0
    verdict = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("result"))
    assert "the branches at its branch points are not traced" in verdict and "broken" not in verdict


@pytest.mark.parametrize("block, name", [("odd_held", "pear_0"), ("odd_free", "pear_free_1")])
def test_continue_at_a_pear_pitchfork_switches_to_the_pear_branch(two_coils, block, name, capsys):
    """`continue RUN LABEL` at a pear pitchfork, held or free (no --parameter): the pear branch and its mirror
    image, the same as `run` traced from the same point (every stored unknown to 1e-10: measured 1.2e-13), after
    the branch of the point; the free one with its translation free."""
    run, out = two_coils / "run.h5", two_coils / f"switched_{block}.h5"
    label = first(run, "BP", block)
    assert main(["continue", str(run), str(label), "-o", str(out)]) == 0
    assert f"branches switched to at label {label}: {name} (" in capsys.readouterr().out
    stored, switched = read_run(run)["branches"], read_run(out)["branches"]
    assert list(switched) == ["primary", name, f"{name}_mirror"]
    for branch in (name, f"{name}_mirror"):
        a, b = np.asarray(stored[branch]["unknowns"]), np.asarray(switched[branch]["unknowns"])
        assert a.shape == b.shape and np.abs(a - b).max() < 1e-10
        assert switched[branch]["attrs"]["gauge"] == stored[branch]["attrs"]["gauge"]
        assert switched[branch]["attrs"]["parent_branch_point"] == stored[branch]["attrs"]["parent_branch_point"]
        stability, again = dict(leaves(stored[branch]["stability"])), dict(leaves(switched[branch]["stability"]))
        assert sorted(stability) == sorted(again) and any(k.startswith("lowest_m1") for k in stability)
        for key, value in stability.items():  # assessed as run assesses it (measured 4.5e-13)
            assert np.asarray(value).shape == np.asarray(again[key]).shape
            assert np.allclose(value, again[key], rtol=0, atol=1e-10, equal_nan=True), key
        assert [(s["kind"], s["block"]) for s in stored[branch]["special_points"]] == [
            (s["kind"], s["block"]) for s in switched[branch]["special_points"]]
    assert np.array_equal(switched["primary"]["unknowns"], stored["primary"]["unknowns"])
    if block == "odd_held":  # the same from Python
        import balloon_cg as bc

        result = bc.continue_from(run, label)
        assert list(result.branches) == ["primary", name, f"{name}_mirror"] and result.complete
        assert np.abs(np.asarray(result.branches[name].data["unknowns"]) - stored[name]["unknowns"]).max() < 1e-10


@pytest.mark.parametrize("name, block", [("pear_0", "odd_held"), ("pear_free_1", "odd_free")])
def test_continue_from_the_end_of_a_pear_branch_passes_its_pitchfork_into_the_mirror_image(two_coils, name, block):
    """Restart in P from the end point of a pear branch (held or free): the branch runs back to its pitchfork on
    the primary branch and through it into its mirror image, as a pitchfork's pear branch does (P is even in the
    pear amplitude). The fold of P there is that pitchfork (the primary's point, of the branch's own reading),
    not an LP whose root search fails at the singular point; the far end is the run's mirror branch's end
    (reflected in run, traced here) to 1e-10; exit 0."""
    run, out = two_coils / "run.h5", two_coils / f"from_{name}_end.h5"
    stored = read_run(run)["branches"]
    end = next(s for s in stored[name]["special_points"] if s["kind"] == "EP" and s["index"] > 0)
    assert main(["continue", str(run), str(end["label"]), "-o", str(out), "--quiet"]) == 0
    written = read_run(out)["branches"]
    assert list(written) == ["primary", name]  # the parent as read, the pear branch under its name
    again = written[name]
    assert again["attrs"]["parent_branch_point"] == stored[name]["attrs"]["parent_branch_point"]
    kinds = [(s["kind"], s["block"]) for s in again["special_points"]]
    assert kinds == [("EP", ""), ("BP", block), ("EP", "")]
    pitchfork = next(s for s in stored["primary"]["special_points"] if s["kind"] == "BP" and s["block"] == block)
    assert again["special_points"][1]["pressure"] == pitchfork["pressure"]
    mirror_end = next(s for s in stored[f"{name}_mirror"]["special_points"] if s["kind"] == "EP" and s["index"] > 0)
    far = max(again["special_points"][::2], key=lambda s: abs(s["lam2_top"] - end["lam2_top"]))
    for key in ("pressure", "lam2_top", "lam2_bottom"):
        assert abs(far[key] - mirror_end[key]) < 1e-10, key


def test_continue_refuses_a_switch_or_a_curve_it_does_not_build(two_coils, capsys):
    """From an m = 1 point in a second parameter: one line, exit 2, nothing written (a free m = 1 point switches
    now: the test above)."""
    run, out = two_coils / "run.h5", two_coils / "refused.h5"
    held_m1 = first(run, "BP", "m1_held")
    assert main(["continue", str(run), str(held_m1), "--parameter", "M", "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "is a BP of block m1_held; only pear points (odd_held, odd_free)" in err
    assert not out.exists()


@pytest.mark.slow
def test_continue_at_a_held_m1_point_switches_to_the_surface_branch(two_coils, tmp_path, capsys):
    """`continue RUN LABEL` at the first held m = 1 point of the two-coil branch (from a run without surface
    branches): the non-axisymmetric branch and its image under the rotation by π, the same as `run` traces with
    [surface] branches = "first" (every coefficient and P to 1e-12: measured equal; the critical mode taken at the
    degree the point was located at, ``surface_branches.located_degree``), its parent point classified alike.
    A few minutes: ``pytest -m slow``."""
    run, full, out = two_coils / "run.h5", tmp_path / "full.h5", tmp_path / "switched.h5"
    assert main(["run", str(two_coils / "two_coils.toml"), "--set", "surface.branches=first", "-o", str(full),
                 "--quiet"]) == 0
    label = first(run, "BP", "m1_held")
    assert main(["continue", str(run), str(label), "-o", str(out), "--quiet"]) == 0
    capsys.readouterr()
    stored, switched = read_run(full)["branches"], read_run(out)["branches"]
    assert list(switched) == ["primary", "m1_bp1", "m1_bp1_rotated"]
    for name in ("m1_bp1", "m1_bp1_rotated"):
        a, b = stored[name], switched[name]
        assert a["coefficients"].shape == b["coefficients"].shape and len(a["pressure"]) > 10
        assert np.abs(np.asarray(a["coefficients"]) - np.asarray(b["coefficients"])).max() < 1e-12
        assert np.abs(np.asarray(a["pressure"]) - np.asarray(b["pressure"])).max() < 1e-12
        assert [(s["kind"], s["classification"]) for s in a["special_points"]] == \
            [(s["kind"], s["classification"]) for s in b["special_points"]]


def test_continue_at_a_free_m1_point_switches_to_the_free_surface_branch(two_coils, tmp_path, capsys):
    """`continue RUN LABEL` at the first free m = 1 point (issue 41): the free balloon's branch and its image,
    stored with the free reading (gauge "free"), every point with zero net field force (its centre moves instead)."""
    run, out = two_coils / "run.h5", tmp_path / "free.h5"
    label = first(run, "BP", "m1_free")
    assert main(["continue", str(run), str(label), "-o", str(out), "--set", "surface.max_points=4", "--quiet"]) == 0
    capsys.readouterr()
    switched = read_run(out)["branches"]
    assert list(switched) == ["primary", "m1_bp3", "m1_bp3_rotated"]
    for name in ("m1_bp3", "m1_bp3_rotated"):
        assert switched[name]["attrs"]["gauge"] == "free" and len(switched[name]["pressure"]) == 4


def test_continue_in_M_from_the_free_pitchfork_gives_free_pitchforks(two_coils, capsys):
    """Two coils: `continue RUN LABEL --parameter M` from the free balloon's pitchfork (odd_free: the pear block
    with the axial translation) traces its curve (group pear_free); it turns back in M near 0.0144 and ends at a
    wire. At a curve point of the first leg (M = 0.0109) the free pitchfork located on a primary branch traced at
    that M (Werner–Spence at fixed M, from its own detection) is at the curve's P to 1e-10 (measured 8e-15)."""
    from balloon_cg.analysis.points import branch_points as bifurcation
    from balloon_cg.analysis.branches.primary import trace_primary
    from balloon_cg.analysis.results import Block, Status
    from balloon_cg.analysis.stability.axisymmetric import assess_branch

    run, out = two_coils / "run.h5", two_coils / "free_curve.h5"
    assert main(["continue", str(run), str(first(run, "BP", "odd_free")), "--parameter", "M", "-o", str(out),
                 "--quiet"]) == 0
    capsys.readouterr()
    curve = read_curve(out, "pear_free")
    q, P = curve["q"], curve["pressure"]
    assert curve["attrs"]["end"] == "fold" and 0.0143 < q.max() < 0.0146 and q[0] == 0.002
    scene = load_scene(two_coils / "two_coils.toml").with_overrides({"field.M": float(q[6]),
                                                                     "continuation.stop_stretch": 2.0})
    primary = trace_primary(scene)
    primary.stability, _ = assess_branch(primary, scene.stability.degree, True, check=True)
    free = [bifurcation.locate(primary, i, block, k) for i, block, k in bifurcation.detect(primary, primary.stability)
            if block == Block.ODD_FREE]
    assert free[0].status == Status.LOCATED and abs(free[0].X[-1] - P[6]) < 1e-10


@pytest.fixture(scope="module")
def spom1_run(tmp_path_factory):
    """SPOM1 at M = 0 (no coils), without surface branches: its run file (primary, the isola's pear branches)."""
    folder = tmp_path_factory.mktemp("spom1")
    scene = folder / "spom1.toml"
    scene.write_text(load_scene("spom1").with_overrides({"surface.branches": "none"}).to_toml())
    assert main(["run", str(scene), "-o", str(folder / "run.h5"), "--quiet"]) == 0
    return folder / "run.h5"


def test_inspect_names_where_a_pear_branch_leaves_and_rejoins_by_label(spom1_run, capsys):
    """SPOM1's isola: the pear branch leaves the primary branch at its first pitchfork and rejoins it at its second;
    inspect (text and --json) and the legend name both by their labels (what continue takes), not by the
    analysis's numbering of branch points; the notes carry no such number."""
    import balloon_cg as bc

    run = read_run(spom1_run)
    first_bp, second_bp = [s["label"] for s in run["branches"]["primary"]["special_points"] if s["kind"] == "BP"]
    assert main(["inspect", str(spom1_run)]) == 0
    text = capsys.readouterr().out
    assert f"branch pear_0   (from label {first_bp} on primary;" in text
    assert f"forward: rejoined the primary branch (at label {second_bp})" in text
    assert not re.search(r"branch point \d", text)
    assert main(["inspect", str(spom1_run), "--json"]) == 0
    pear = json.loads(capsys.readouterr().out)["branches"]["pear_0"]
    assert (pear["parent_label"], pear["rejoin_label"]) == (first_bp, second_bp)
    assert bc.load(spom1_run).branches["pear_0"].born_at == first_bp
    legend = [t.get_text() for t in bc.plot(spom1_run).legends[0].get_texts()]
    assert f"M = 0, pear from {first_bp}" in legend


def test_continue_in_M_without_coils_is_bad_input(spom1_run, tmp_path, capsys):
    """`continue RUN LABEL --parameter M` on a run without coils: exit 2 before any work, as `critical` (it was
    exit 1 from inside the curve's start), one line; nothing written."""
    out = tmp_path / "m.h5"
    for kind in ("LP", "BP"):
        assert main(["continue", str(spom1_run), str(first(spom1_run, kind, "odd_held" * (kind == "BP"))),
                     "--parameter", "M", "-o", str(out)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "continue --parameter M needs coils" in err and str(spom1_run) in err
    assert not out.exists()


def test_continue_writes_to_a_default_path(spom1_run, tmp_path, monkeypatch, capsys):
    """Without -o, continue writes RUN_label<LABEL>.h5 (a curve: RUN_label<LABEL>_<KEY>.h5) in the current folder,
    as run and critical name their outputs; an existing one is kept without --force."""
    monkeypatch.chdir(tmp_path)
    label = first(spom1_run, "LP")
    assert main(["continue", str(spom1_run), str(label), "--quiet", "--stop-stretch", "1.5"]) == 0
    assert f"written to run_label{label}.h5" in capsys.readouterr().out
    assert read_run(tmp_path / f"run_label{label}.h5")["branches"]["primary"]["attrs"]["kernel_class"]
    assert main(["continue", str(spom1_run), str(label), "--quiet"]) == 2
    assert "exists" in capsys.readouterr().err
    assert main(["continue", str(spom1_run), str(label), "--parameter", "material.mu[1]", "--quiet"]) in (0, 1)
    assert (tmp_path / f"run_label{label}_mu1.h5").exists()  # the key reduced to file-name characters, as critical


@pytest.fixture(scope="module")
def isola_restart(spom1_run):
    """`continue RUN LABEL` from the TP of SPOM1's pear branch (the isola): the file it writes."""
    [tp] = [s for s in read_run(spom1_run)["branches"]["pear_0"]["special_points"] if s["kind"] == "TP"]
    out = spom1_run.parent / "isola_again.h5"
    assert main(["continue", str(spom1_run), str(tp["label"]), "-o", str(out), "--quiet"]) == 0
    return out


def isola_points(stored: dict) -> tuple:
    """(the turning points' P of the run's pear branch and its mirror image, sorted; the primary's pitchforks' P)."""
    turns = sorted(s["pressure"] for name in ("pear_0", "pear_0_mirror") for s in stored[name]["special_points"]
                   if s["kind"] == "TP")
    return turns, [s["pressure"] for s in stored["primary"]["special_points"] if s["kind"] == "BP"]


def assert_ends_as_run_ends(branch: dict, stored: dict) -> None:
    """A restart on SPOM1's isola: both legs stopped where they rejoin the primary branch at its second pitchfork,
    and the points run marks on the pear branch and its mirror image, once each: the two turning points (the same P
    to 1e-8), the first pitchfork it passes (the primary's point), the two ends the last points before the second
    pitchfork (the pear amplitude falling, its sign kept, as at the run's pear ends), every one located; no LV or LN (run marks none on pear branches)."""
    turns, pitchforks = isola_points(stored)
    assert list(branch["attrs"]["leg_stop_codes"]) == ["rejoined", "rejoined"]
    assert [s["kind"] for s in branch["special_points"]] == ["EP", "TP", "BP", "TP", "EP"]
    assert {s["status"] for s in branch["special_points"]} == {"located"}
    again = sorted(s["pressure"] for s in branch["special_points"] if s["kind"] == "TP")
    assert np.abs(np.subtract(turns, again)).max() < 1e-8
    assert branch["special_points"][2]["pressure"] == pitchforks[0]
    amplitude = np.subtract(branch["lam2_top"], branch["lam2_bottom"])  # the pear amplitude: its sign the side
    for end, before in ((0, 1), (-1, -2)):  # the last point before the crossing, as the run's pear ends
        assert 0 < amplitude[end] / amplitude[before] < 1
    for end in branch["special_points"][::4]:
        assert abs(end["pressure"] - pitchforks[1]) < 1e-3
    assert (branch["attrs"]["parent_branch"], branch["attrs"]["parent_branch_point"]) == ("primary", 0)
    assert branch["attrs"]["rejoins_branch_point"] == stored["pear_0"]["attrs"]["rejoins_branch_point"] == 1


def test_a_restart_on_the_isola_ends_where_its_closed_loop_does(spom1_run, isola_restart):
    """SPOM1 at M = 0: the pear branch of the first pitchfork rejoins the primary branch at the second (an isola).
    `continue RUN LABEL` from its turning point (TP) goes once round the closed loop the pear branch and its mirror
    image make, and stops where `run` stopped them, marking what run marks (``assert_ends_as_run_ends``; it went
    round the loop to max_points before, exit 1, and marked LV and LN points). The file holds the loop under the
    pear branch's name, after its parent as read (the run's primary branch: its points and labels as in the run),
    so that a restart from it knows where the loop crosses its parent (the next test)."""
    stored, again = read_run(spom1_run)["branches"], read_run(isola_restart)["branches"]
    assert list(again) == ["primary", "pear_0"]
    assert_ends_as_run_ends(again["pear_0"], stored)
    assert np.array_equal(again["primary"]["unknowns"], stored["primary"]["unknowns"])
    assert [s["label"] for s in again["primary"]["special_points"]] == [
        s["label"] for s in stored["primary"]["special_points"]]


def test_a_restart_from_the_loop_continue_wrote_ends_as_run_ends(spom1_run, isola_restart, tmp_path, capsys):
    """`continue` from a TP of the loop `continue` wrote from the isola: its parent is in that file, so it stops and
    marks as `run` does, exit 0 (before, the loop was stored as `primary` without the branch it crosses: it closed
    on itself after one lap, with a fold candidate where run stores each pitchfork, the second approximate: exit 1;
    before that it went round twice to max_points, 599 points, the turning points three times, LV and LN)."""
    out = tmp_path / "lap.h5"
    tp = next(s for s in read_run(isola_restart)["branches"]["pear_0"]["special_points"] if s["kind"] == "TP")
    assert main(["continue", str(isola_restart), str(tp["label"]), "-o", str(out), "--quiet"]) == 0
    assert f"branch pear_0 continued from label {tp['label']}: " in capsys.readouterr().out
    assert_ends_as_run_ends(read_run(out)["branches"]["pear_0"], read_run(spom1_run)["branches"])


def test_a_restart_that_comes_back_to_its_start_stops_there(spom1_run, isola_restart):
    """A pear branch restarted without its parent (a loop `continue` wrote before it stored the parent: as
    `primary`, states without the equator symmetry of the scene's primary branch) cannot stop where it crosses its
    parent: it is restarted as a pear branch (``restart.is_pear``: stopped and assessed as one) and its first leg
    stops where it comes back to the point it started from (stop closed), one lap: each turning point once, at the
    run's pear branches' P to 1e-8, no LV or LN, and no second leg. (Where that loop crosses the primary branch
    it is not stored with it marks fold candidates where run marks the primary's BP.)"""
    from dataclasses import replace

    from balloon_cg.app.restart import restart

    run = read_run(isola_restart)
    tp = next(s for s in run["branches"]["pear_0"]["special_points"] if s["kind"] == "TP")
    start = find_label(run, tp["label"])
    alone = replace(start, branch=replace(start.branch, name="primary"), parent=None, parent_point=-1)
    [branch] = restart(alone, None).branches
    assert branch.name == "primary" and [leg.stop.code.value for leg in branch.legs] == ["closed"]
    assert len(branch.X) < 300
    kinds = [s.kind.value for s in branch.special]
    assert kinds.count("TP") == 2 and not {"LV", "LN"} & set(kinds)
    turns, _ = isola_points(read_run(spom1_run)["branches"])
    again = sorted(s.X[-1] for s in branch.special if s.kind.value == "TP")
    assert np.abs(np.subtract(turns, again)).max() < 1e-8
    poles = branch.pole_values()
    signature = np.column_stack([branch.X[:, -1], poles["lam2_top"], poles["lam2_bottom"]])
    step = np.abs(np.diff(signature, axis=0)).max()
    assert np.abs(signature[-1] - signature[0]).max() <= 2 * step  # it ends where it began: the loop closed
