"""A coil off the equatorial plane (issue 27): SPOM1, one coil of radius 2 at height 0.5, M = 0.002. The primary
branch has no equator symmetry; every stability change under every control mode is a special point (LP, LV, LN or
BP: ``analysis.points.control_points``), its m = 1 crossings are located as on symmetric branches, and what is still not
searched is said in the verdict line; the pear branch the broken symmetry disconnects is found by continuation in
the coil height from 0. With the coil back at h = 0 the symmetric analysis runs as before."""
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.switching.broken_symmetry import distance_to
from balloon_cg.analysis.points.control_points import FOLD_TOL, fold_rate
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.branches.problem import branch_system, equilibrium_of
from balloon_cg.analysis.results import Block, Gauge, Kind, Origin, Status, StopCode
from balloon_cg.analysis.stability.axisymmetric import SecondVariation
from balloon_cg.analysis.verdict import Gap, failing
from balloon_cg.io.run_file import write_run
from balloon_cg.scene import Control, parse_scene

SCENE = """[material]
preset = "SPOM1"
[field]
chi = 1.0
M = 0.002
[[field.coils]]
radius = 2.0
height = {height}
current = 1.0
[continuation]
stop_stretch = 3.2
wire_gap = 0.1
"""  # stop_stretch 3.2 (the scene has 5): past the m = 1 point and both gas-control changes, at a third the cost


def coil_at(height: float):
    return parse_scene(SCENE.format(height=height), name=f"coil_at_{height:g}")


@pytest.fixture(scope="module")
def off_equator():
    """The picture without the disconnected pear branch (``pear=False``: its search is the tests below)."""
    return analyse(coil_at(0.5), pear=False)


def gas_amount(branch, X) -> float:
    """n = P V of the point X (V = 2π Ṽ)."""
    return float(X[-1] * 2 * np.pi * equilibrium_of(branch).volume(X[:-1]))


def test_every_stability_change_is_a_located_special_point(off_equator):
    """Each interval where a held stability flag changes (pressure, gas, volume control) holds a located special
    point of that control's kind: LP where P folds, LN where n = P V folds (here twice: the gas-control
    eigenvalue leaves zero and comes back, as the issue found between points 48-49 and 60-61), a BP m = 1 where the m
    = 1 block's eigenvalue crosses (47-48). At each LN: the gas block's eigenvalue, recomputed, vanishes to 1e-10, n is
    stationary along the branch (|∇n·τ| ≤ FOLD_TOL |∇n|), and n there lies beyond both bracketing points (an
    extremum: the independent reading of a fold)."""
    primary = off_equator.primary
    assert not primary.disc.symmetric and primary.gauge == Gauge.HELD
    special = {(s.kind, s.index): s for s in primary.special if s.kind != Kind.EP}
    assert all(s.status == Status.LOCATED for s in special.values())
    for flag, kind in (("stable_pressure", Kind.LP), ("stable_gas", Kind.LN), ("stable_volume", Kind.LV)):
        stable = np.array([a.flags()[flag] for a in primary.stability])
        for i in np.flatnonzero(stable[:-1] != stable[1:]):
            assert (kind, i) in special or any(s.kind == Kind.BP and s.index == i for s in special.values()), (flag, i)
    m1 = [s for s in special.values() if s.kind == Kind.BP and s.block == Block.M1_HELD]
    assert [s.index for s in m1] == [47] and m1[0].gauge == Gauge.HELD
    folds = sorted(s.index for s in special.values() if s.kind == Kind.LN)
    assert folds == [48, 60]
    system, eq = branch_system(primary), equilibrium_of(primary)
    for index in folds:
        s = special[Kind.LN, index]
        mu = SecondVariation(eq, primary.stability[index].degree).lowest(s.X[:-1], primary.params_at(s.X), False,
                                                                          "all_gas_held")
        assert np.abs(mu).min() <= 1e-10
        assert fold_rate(system, s.X, primary.X[index + 1] - primary.X[index], Control.GAS) <= FOLD_TOL
        n = gas_amount(primary, s.X)
        ends = [gas_amount(primary, primary.X[i]) for i in (index, index + 1)]
        assert n > max(ends) or n < min(ends)


def test_the_verdict_line_says_what_is_not_searched(off_equator, tmp_path, capsys):
    """The result is complete (the exit status is 0) but not everything is searched: the disconnected pear branch
    and the free balloon's branch are named in the verdict line of the summary (``run`` prints it, as ``inspect``)."""
    from balloon_cg.app.cli import main

    found = off_equator.incomplete
    assert [item.gap for item in found] == [Gap.NOT_SEARCHED] and not failing(found)
    path = write_run(tmp_path / "off.h5", off_equator.primary.scene, off_equator.branches, snaps=off_equator.snaps,
                     found=found)
    assert main(["inspect", str(path)]) == 0
    verdict = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("result"))
    assert verdict.split()[1] == "complete," and "not_searched" in verdict
    assert "pear branch of the broken pitchfork" in verdict and "free balloon's branch" in verdict


def test_the_coil_back_on_the_equator_gives_the_symmetric_analysis():
    """At h = 0 the field is equator-symmetric: the primary branch is traced in the symmetric layout, its pear
    pitchforks of both readings are located by the extended systems, nothing is left unsearched."""
    picture = analyse(coil_at(0.0), pear=False)
    assert picture.primary.disc.symmetric and picture.not_searched == ""
    blocks = {bp.block for bp in picture.branch_points}
    assert {Block.ODD_HELD, Block.ODD_FREE} <= blocks
    assert all(bp.status == Status.LOCATED for bp in picture.branch_points)
    assert not [s for s in picture.primary.special if s.kind in (Kind.LV, Kind.LN)]


def test_the_disconnected_pear_branch_is_found_by_continuation_in_the_coil_height(tmp_path, capsys):
    """The pear branch the coil's height breaks off the primary branch: found from the pear branch of the coil at
    h = 0 (continued in h at its pear amplitude), traced both ways in P, stored with how it was found. Every point a
    resolved Newton solution of the held problem at h = 0.5; it bulges the other way (the south pole stretch up to
    stop_stretch), folds in P, and stays away from the primary branch (no point within 0.05 of it in (P, λ2(0),
    λ2(π))); the verdict line no longer lists it as not searched."""
    from balloon_cg.app.cli import main

    picture = analyse(coil_at(0.5))
    branches = {b.name: b for b in picture.branches}
    assert set(branches) == {"primary", "broken_pear"}
    broken, primary = branches["broken_pear"], branches["primary"]
    assert broken.origin == Origin.CONTINUED_IN_HEIGHT and broken.gauge == Gauge.HELD and len(broken.X) > 20
    tol = broken.scene.solver
    assert broken.residual.max() <= tol.tol and broken.error_estimate.max() <= tol.max_error
    assert broken.stopped(StopCode.BOTTOM_STOP_STRETCH) and any(s.kind == Kind.LP for s in broken.special)
    assert min(distance_to(primary, X, broken.disc) for X in broken.X) > 0.05
    assert "broken pitchfork" not in picture.not_searched and not failing(picture.incomplete)
    path = write_run(tmp_path / "off.h5", primary.scene, picture.branches, snaps=picture.snaps,
                     found=picture.incomplete)
    assert main(["inspect", str(path), "--json"]) == 0
    import json

    stored = json.loads(capsys.readouterr().out)["branches"]["broken_pear"]
    assert stored["origin"] == "continued_in_height" and stored["gauge"] == "held"


def test_the_disconnected_pear_branch_gets_its_user_points():
    """A volume event (``[[events]]`` volume = 20) on the coil at h = 0.5: the disconnected pear branch passes V = 20
    twice (its volume has a minimum 19.886 between them) and holds a located UZ point in each interval, V = 20 there
    to 1e-10 relative (the volume of the stored state recomputed) and R = 0 to the solver tolerance (it had none:
    only the primary branch's were located)."""
    from balloon_cg.analysis.switching.broken_symmetry import broken_pear
    from balloon_cg.analysis.branches.primary import trace_primary

    scene = parse_scene(SCENE.format(height=0.5).replace("stop_stretch = 3.2", "stop_stretch = 5.0")
                        + '[[events]]\nquantity = "volume"\nvalue = 20\n', name="coil_at_0.5")
    broken = broken_pear(scene, trace_primary(scene))
    eq, system = equilibrium_of(broken), branch_system(broken)
    volume = np.array([2 * np.pi * eq.volume(X[:-1]) for X in broken.X])
    crossings = np.flatnonzero((volume[:-1] - 20) * (volume[1:] - 20) < 0)
    assert len(crossings) == 2
    points = [s for s in broken.special if s.kind == Kind.UZ]
    assert [s.index for s in points] == list(crossings) and all(s.note == "volume = 20" for s in points)
    for s in points:
        assert s.status == Status.LOCATED and abs(2 * np.pi * eq.volume(s.X[:-1]) / 20 - 1) < 1e-10
        assert np.abs(system.residual(s.X)).max() <= scene.solver.tol


def test_the_disconnected_pear_branch_on_two_workers_is_the_serial_one(monkeypatch):
    """The halves of the symmetric relative's pear branch and the legs of the disconnected branch's trace go to two
    forked workers (``broken_pear``; every spread forks here): the branch is the serial one bit for bit, and its
    seed is the first point of pear amplitude ≥ SEED_AMPLITUDE of that half traced whole (``trace_pear``)."""
    from balloon_cg.analysis.branches.primary import trace_primary
    from balloon_cg.analysis.switching import broken_symmetry
    from balloon_cg.analysis.switching.pear import trace_pear
    from balloon_cg.numerics import workers

    scene = coil_at(0.5)
    primary = trace_primary(scene)
    monkeypatch.setattr(workers, "MIN_COST", 0.0)
    spread, calls = workers.spread, []
    monkeypatch.setattr(workers, "spread", lambda work, items, *args, **kwargs: calls.append(
        workers.sharing(len(items), 1.0)) or spread(work, items, *args, **kwargs))
    found = {}
    for count in ("1", "2"):
        monkeypatch.setenv("BALLOON_CG_WORKERS", count)
        found[count] = broken_symmetry.broken_pear(scene, primary)
    assert calls == [1, 1, 2, 2]  # the relative's assessment, the halves: here, then on two workers
    assert np.array_equal(found["1"].X, found["2"].X) and found["1"].degree.tolist() == found["2"].degree.tolist()
    assert [(s.kind, s.index) for s in found["1"].special] == [(s.kind, s.index) for s in found["2"].special]
    relative, bp = broken_symmetry.pitchfork(scene)
    X, _ = broken_symmetry.seed(scene, relative, bp, 1.0)
    whole = trace_pear(relative, bp, 1.0, "pear")
    poles = whole.pole_values()
    first = np.flatnonzero(np.abs(poles["lam2_top"] - poles["lam2_bottom"]) >= broken_symmetry.SEED_AMPLITUDE)[0]
    assert whole.disc.mapping is None and X.size == whole.X.shape[1]  # stored on the seed's own basis
    assert np.array_equal(X, whole.X[first])


def test_critical_follows_a_fold_of_the_off_equator_coil_and_its_help_says_so(tmp_path, capsys):
    """`critical --of LP` needs no equator symmetry (a fold is no pitchfork): on the coil at h = 0.5 the fold of P in
    M runs until P reaches 0 (exit 1, no cusp), while the pitchfork (--of BP) is refused naming the coil (exit 2);
    the help says the symmetry is needed with --of BP only (it said it of every scene)."""
    from balloon_cg.app.cli import main

    scene = tmp_path / "off.toml"
    scene.write_text(SCENE.format(height=0.5).replace("stop_stretch = 3.2", "stop_stretch = 1.5"))
    assert main(["critical", str(scene), "--of", "LP", "--parameter", "M", "-o", str(tmp_path / "lp.h5"),
                 "--quiet"]) == 1
    assert "P reached 0" in capsys.readouterr().err
    assert main(["critical", str(scene), "--parameter", "M", "-o", str(tmp_path / "bp.h5"), "--quiet"]) == 2
    assert "coil 0 (radius 2, height 0.5) has no mirror image" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["critical", "--help"])
    text = " ".join(capsys.readouterr().out.split()).replace("- ", "-")  # argparse wraps after a hyphen
    assert "--of BP: not equator-symmetric" in text and "with --of BP equator-symmetric" in text
    assert "the fold curve ends in a cusp" in text


@pytest.mark.parametrize("path", sorted(p for p in (Path(__file__).parent.parent / "scenes").glob("*.toml")
                                         if not p.stem.startswith("tube_")), ids=lambda p: p.stem)  # a tube: no picture
def test_no_shipped_scene_leaves_branch_points_unsearched_with_every_branch_asked_for(path):
    """Issue 41: every shipped scene under ``[surface] branches = "all"`` (up to λ2(0) = 1.3, below every branch
    point: what is searched follows from the scene's field and events, not from how far it is traced) has no
    not_searched entry and a complete verdict. The off-equator scene's is the slow test of test_free_balloon."""
    from balloon_cg.scene import load_scene

    scene = load_scene(path).with_overrides({"surface.branches": "all", "continuation.stop_stretch": 1.3},
                                            name=path.stem)
    picture = analyse(scene)
    assert picture.not_searched == "" and not failing(picture.incomplete)
    assert Gap.NOT_SEARCHED not in {item.gap for item in picture.incomplete}
