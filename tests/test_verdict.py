"""The contract: every stored result is verified or flagged, and the exit status says which (analysis.verdict,
app.cli). Edge scenes either give a complete result (exit 0) or a flagged one (exit 1, --allow-partial 0), or
no file at all when not even the start is a resolved equilibrium."""
import h5py
import numpy as np
import pytest

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.verdict import Gap
from balloon_cg.app.cli import main
from balloon_cg.io.run_file import read_run
from balloon_cg.scene import parse_scene

SPOM1 = '[material]\npreset = "SPOM1"\n'
# the axisymmetric contract; the non-axisymmetric branches' verdict is tests/test_surface.py's
ONE_COIL = ('[surface]\nbranches = "none"\n'
            "[field]\nM = {M}\n[[field.coils]]\nradius = {a}\nheight = {h}\ncurrent = 1.0\n")


def run(tmp_path, text, *flags):
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    out = tmp_path / "out.h5"
    return main(["run", str(scene), "-o", str(out), "--quiet", "--force", *flags]), out


def test_complete_run_exits_0_and_says_so(tmp_path, capsys):
    code, out = run(tmp_path, SPOM1 + "[continuation]\nstop_stretch = 2.0\n")
    assert code == 0 and capsys.readouterr().err == ""
    attrs = read_run(out)["attrs"]
    assert attrs["complete"] is True and attrs["incomplete_gaps"] == []


def test_point_budget_is_a_flagged_partial_result(tmp_path, capsys):
    """max_points reached before stop_stretch: the file is written and flagged, exit 1; --allow-partial: 0."""
    text = SPOM1 + "[continuation]\nstop_stretch = 5.0\nmax_points = 12\n"
    code, out = run(tmp_path, text, "--primary-only")
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1 and "stopped_short" in err
    attrs = read_run(out)["attrs"]
    assert attrs["complete"] is False and "stopped_short" in attrs["incomplete_gaps"]
    assert read_run(out)["branches"]["primary"]["attrs"]["leg_stop_codes"][0] == "max_points"
    code, _ = run(tmp_path, text, "--primary-only", "--allow-partial")
    assert code == 0


def test_failed_start_is_never_stored(tmp_path, capsys):
    """One coil of radius 4 at M = 1: the start stretch 1.01 cannot carry the field (the membrane wrinkles); no
    file, exit 1, one line saying so."""
    code, out = run(tmp_path, SPOM1 + ONE_COIL.format(M=1.0, a=4.0, h=0.0))
    err = capsys.readouterr().err
    assert code == 1 and not out.exists()
    assert err.count("\n") == 1 and "start" in err


def test_stored_points_are_resolved(tmp_path):
    """No stored point has an error estimate above solver.max_error (the start included)."""
    scene = parse_scene(SPOM1 + ONE_COIL.format(M=0.5, a=4.0, h=0.0) + "[continuation]\nstart_stretch = 1.5\n"
                        "stop_stretch = 2.0\n", "strong_field")
    picture = analyse(scene)
    for branch in picture.branches:
        assert branch.error_estimate.max() <= scene.solver.max_error, branch.name


def test_pear_branches_end_on_the_requested_stretch():
    """A pear branch stopped by stop_stretch ends exactly there (north, or south for the mirror image) and holds no
    special point beyond its end."""
    picture = analyse(parse_scene('[material]\npreset = "TPOM1"\n', "tpom1"))
    pears = {b.name: b for b in picture.branches if b.parent}
    assert set(pears) == {"pear_0", "pear_0_mirror"}
    north, south = pears["pear_0"].pole_values(), pears["pear_0_mirror"].pole_values()
    assert north["lam2_top"][-1] == pytest.approx(5.0, abs=1e-12)
    assert south["lam2_bottom"][-1] == pytest.approx(5.0, abs=1e-12)
    for branch in pears.values():
        assert all(s.index < len(branch.X) for s in branch.special)
        pole = "lam2_top" if branch.name == "pear_0" else "lam2_bottom"
        assert all(branch.pole_values(s.X)[pole][0] <= 5.0 + 1e-12 for s in branch.special)


def test_unsymmetric_scene_states_that_branch_points_were_not_searched(tmp_path):
    scene = parse_scene(SPOM1 + ONE_COIL.format(M=0.002, a=2.0, h=0.5) + "[continuation]\nstop_stretch = 1.5\n",
                        "unsymmetric")
    picture = analyse(scene)
    gaps = [item.gap for item in picture.incomplete]
    assert Gap.NOT_SEARCHED in gaps and not Gap.NOT_SEARCHED.fails
    code, out = run(tmp_path, scene.text)
    assert code == 0  # a stated limitation, not an incomplete result
    with h5py.File(out) as f:
        assert bool(f.attrs["complete"]) and list(f.attrs["incomplete_gaps"]) == ["not_searched"]
        assert np.asarray(f.attrs["incomplete_messages"]).size == 1


EDGE_SCENES = {
    "far_coil": SPOM1 + ONE_COIL.format(M=0.002, a=40.0, h=0.0) + "[continuation]\nstop_stretch = 3.0\n",
    "tiny_field": SPOM1 + ONE_COIL.format(M=1e-9, a=4.0, h=0.0) + "[continuation]\nstop_stretch = 3.0\n",
    "stiff": "[material]\nmu = [0.5]\nalpha = [8.0]\n[continuation]\nstop_stretch = 3.0\n",
    "negative_exponent": "[material]\nmu = [-1.0]\nalpha = [-4.0]\n[continuation]\nstop_stretch = 3.0\n",
    "mooney_rivlin_at_the_wire": '[material]\npreset = "Mooney-Rivlin"\n' + ONE_COIL.format(M=0.01, a=3.0, h=0.5)
                                 + "[continuation]\nstop_stretch = 4.0\nwire_gap = 0.01\n[solver]\nmax_degree = 90\n",
    "strong_field_start": SPOM1 + ONE_COIL.format(M=1.0, a=4.0, h=0.0),
    "near_critical_M": SPOM1 + ONE_COIL.format(M=4.185, a=4.0, h=0.0)
                       + "[continuation]\nstart_stretch = 2.0\nmin_stretch = 1.5\nstop_stretch = 2.3\n",
}


@pytest.mark.parametrize("name", sorted(EDGE_SCENES))
def test_edge_scene_is_complete_or_flagged(name, tmp_path, capsys):
    """Exit 0 with every stored point resolved and every special point located, or exit 1 naming what is
    incomplete (a flagged file, or none when the start itself fails)."""
    code, out = run(tmp_path, EDGE_SCENES[name])
    err = capsys.readouterr().err
    assert code in (0, 1) and "Traceback" not in err
    if code == 1:
        assert err.count("\n") == 1 and ("incomplete" in err or "error" in err)
    if not out.exists():
        assert code == 1
        return
    stored = read_run(out)
    max_error = parse_scene(EDGE_SCENES[name]).solver.max_error
    for branch in stored["branches"].values():
        assert branch["error_estimate"].max() <= max_error
        assert np.isfinite(branch["unknowns"]).all()
        if code == 0:
            assert all(s["status"] == "located" for s in branch["special_points"])
    assert stored["attrs"]["complete"] is (code == 0)


def test_near_undeformed_leg_with_a_field_reaches_min_stretch():
    """The shipped M = 0.003 two-coil scene: its lower leg ends on min_stretch like M = 0.002. It used to stop on
    resolution at degree 320: the point past min_stretch = 1.001 lies in compression (λ < 1), which no degree
    resolves, and the resolution check came before the range check."""
    from pathlib import Path

    from balloon_cg.analysis.branches.primary import trace_primary
    from balloon_cg.analysis.results import StopCode
    from balloon_cg.scene import load_scene

    scene = load_scene(Path(__file__).resolve().parents[1] / "scenes" / "spom1_two_coils_M0.003.toml").with_overrides(
        {"surface.branches": "none"})
    branch = trace_primary(scene)
    assert [leg.stop.code for leg in branch.legs] == [StopCode.WIRE_GAP, StopCode.MIN_STRETCH]
    assert branch.pole_values()["lam2_top"][0] == pytest.approx(scene.continuation.min_stretch, abs=1e-12)
    assert branch.degree.max() < scene.solver.max_degree and branch.disc.mapping is not None
    assert branch.error_estimate.max() <= scene.solver.max_error


def test_wrinkling_while_the_field_is_switched_on_is_located(tmp_path, capsys):
    """Single coil of radius 4 at h = 0, start stretch 1.01: the start wrinkles (an elastic principal stress reaches
    0) at M ≈ 0.6047 while the field is switched on; M = 1 stops there with that M named, and M = 0.6 (just below)
    starts taut."""
    from balloon_cg.analysis.branches.primary import start
    from balloon_cg.analysis.branches.tracer import ContinuationError, Tracer

    code, out = run(tmp_path, SPOM1 + ONE_COIL.format(M=1.0, a=4.0, h=0.0))
    err = capsys.readouterr().err
    assert code == 1 and not out.exists() and "wrinkles" in err
    limit = float(err.split(" at M = ")[1].split()[0])
    assert 0.59 < limit < 0.62
    below = parse_scene(SPOM1 + ONE_COIL.format(M=round(limit * 0.999, 6), a=4.0, h=0.0))
    start(Tracer(below))  # taut: no error
    above = parse_scene(SPOM1 + ONE_COIL.format(M=round(limit * 1.001, 6), a=4.0, h=0.0))
    with pytest.raises(ContinuationError, match="wrinkles"):
        start(Tracer(above))


def test_every_crossing_eigenvalue_is_an_event():
    """Two eigenvalues of one block crossing in the same interval are two branch points, not one."""
    from types import SimpleNamespace

    from balloon_cg.analysis.points.branch_points import detect
    from balloon_cg.analysis.results import Block

    def assessment(odd, even):
        return SimpleNamespace(blocks={Block.ODD_HELD: np.array(odd), Block.EVEN: np.array(even)})

    branch = SimpleNamespace(fold_intervals=frozenset())  # no fold (Branch.fold_intervals)
    events = detect(branch, [assessment([0.5, 1.0, 2.0], [1.0, 2.0, 3.0]),
                             assessment([-0.5, -0.1, 2.0], [1.0, 2.0, 3.0])])
    assert events == [(0, Block.ODD_HELD, 0), (0, Block.ODD_HELD, 1)]


def test_unclassified_branch_point_and_unstarted_branch_are_incomplete():
    from types import SimpleNamespace

    from balloon_cg.analysis.results import Block, Kind, SpecialPoint
    from balloon_cg.analysis.verdict import failing, incomplete

    bp = SpecialPoint(Kind.BP, 3, np.zeros(3), block=Block.ODD_HELD)
    branch = SimpleNamespace(name="primary", legs=(), special=[bp], unsettled=[])
    found = incomplete([branch], not_started=(("pear_0", "the first correction did not converge"),))
    assert {item.gap for item in failing(found)} == {Gap.UNCLASSIFIED, Gap.NOT_STARTED}


def test_a_surface_branch_point_above_max_error_on_the_final_basis_is_flagged():
    """Points of a non-axisymmetric branch are traced on the basis of their segment and stored on the last; one
    whose tail there exceeds solver.max_error makes the result incomplete (Gap.UNRESOLVED), naming the points."""
    from balloon_cg.analysis.results import SurfaceBranch
    from balloon_cg.analysis.verdict import failing, incomplete
    from balloon_cg.galerkin.equilibrium import Parameters

    scene = parse_scene(SPOM1)
    limit = scene.solver.max_error
    branch = SurfaceBranch("m1_bp0", scene, None, "ogden_spom1", "", Parameters(1.0), np.zeros((3, 1)),
                           np.ones(3), np.ones(3), np.zeros(3), np.array([0.1, 0.5, 0.5]) * limit, {}, 1,
                           ("primary", 0))
    assert failing(incomplete([branch])) == []
    branch.error_estimate[:2] = 2.0 * limit
    (found,) = failing(incomplete([branch]))
    assert found.gap == Gap.UNRESOLVED and "points [0, 1]" in found.message
