"""Meetings of a fold and a pitchfork (analysis/critical/fold_meeting.py) against folds and pitchforks located on plain branches.

SPOM1 between the two coils, the pear pitchfork followed in M from M = 0.002: at M* the symmetric branch through
the pitchfork has its gas-control fold (LN). Checked independently of the meeting's test function: on a primary
branch traced under gas control at M*, the LN located by the continuation's fold locator (Brent on dn/ds along
the branch) and the pear pitchfork located by the Werner–Spence system are both at the meeting's P; at M*(1 ∓ δ)
they lie on opposite sides of each other along the branch (the fold and the pitchfork cross at M*).
"""
import json

import numpy as np
import pytest

from balloon_cg.analysis.points.branch_points import detect, locate
from balloon_cg.analysis.critical.pitchfork_curve import continue_branch_point, land_on_q
from balloon_cg.analysis.critical.fold_curve import FoldSystem, continue_fold, fold_tangent
from balloon_cg.analysis.critical.fold_meeting import FoldTest, oriented_tangents
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.results import Block, Kind, Status
from balloon_cg.analysis.stability.axisymmetric import assess_branch
from balloon_cg.app.cli import main
from balloon_cg.scene import Control, load_scene

SCENE = "spom1_two_coils_M0.002"


def pear_point(branch):
    """The first held pear pitchfork of ``branch``, located."""
    assessments, _ = assess_branch(branch, branch.scene.stability.degree)
    return locate(branch, *next(e for e in detect(branch, assessments) if e[1] == Block.ODD_HELD))


def gas_branch(M: float):
    """The primary branch at M under gas control, its located LN fold and pear pitchfork as (P, λ2(0)) each."""
    scene = load_scene(SCENE).with_overrides({"field.M": M, "loading.control": "gas"}, name="gas")
    branch = trace_primary(scene)
    folds = [s for s in branch.special if s.kind == Kind.LN]
    assert len(folds) == 1 and folds[0].status == Status.LOCATED
    bp = pear_point(branch)
    assert bp.status == Status.LOCATED
    north = branch.disc.pole_rows()["lam2_top"]
    return [(float(s.X[-1]), float(north @ s.X[:-1])) for s in (folds[0], bp)]


@pytest.fixture(scope="module")
def meeting():
    branch = trace_primary(load_scene(SCENE))
    curve = continue_branch_point(branch, pear_point(branch), "M", 1.0, max_points=16)
    return curve, curve.meetings


def test_the_ln_meets_the_pitchfork(meeting):
    """One meeting on the first 16 curve points, LN-BP, located; the LN and the pitchfork of a primary branch at
    M* are at its P to 1e-9 (measured: 8e-14 and 5e-15)."""
    curve, meetings = meeting
    assert [(m.kind, m.status, m.block) for m in meetings] == [(Kind.LN_BP, Status.LOCATED, Block.ODD_HELD)]
    M, P = meetings[0].X[-1], meetings[0].X[curve.n]
    assert curve.q[meetings[0].index] < M < curve.q[meetings[0].index + 1]
    (P_fold, lam_fold), (P_bp, lam_bp) = gas_branch(M)
    assert abs(P_fold - P) < 1e-9 and abs(P_bp - P) < 1e-9
    assert abs(lam_fold - lam_bp) < 1e-6  # λ at a fold of n is only as sharp as √(tolerance)


def test_a_curve_point_names_q_not_p(meeting):
    """A curve point's X ends in q (here M): its repr says M = q, not P = q."""
    curve, meetings = meeting
    assert f"M = {meetings[0].X[-1]:.10g}" in repr(meetings[0]) and "P =" not in repr(meetings[0])
    assert all(s.parameter == "M" for s in curve.merges + curve.meetings)


def test_the_ln_curve_passes_through_the_meeting(meeting):
    """The LN fold curve in M (fold_curve, from the LN of the gas-control branch at M = 0.002), landed on M*, is at
    the meeting's P to 1e-9 (measured: 1.4e-13)."""
    curve, meetings = meeting
    M, P = meetings[0].X[-1], meetings[0].X[curve.n]
    branch = trace_primary(load_scene(SCENE).with_overrides({"loading.control": "gas"}, name="gas"))
    fold = next(s for s in branch.special if s.kind == Kind.LN)
    ln_curve = continue_fold(branch, fold, "M", 1.0, stop=lambda point: None, max_points=60)
    near = int(np.searchsorted(ln_curve.q, M))
    assert 0 < near < len(ln_curve.q) and ln_curve.q[near - 1] < M
    X = land_on_q(ln_curve, M, near)
    assert X is not None and abs(X[ln_curve.n] - P) < 1e-9


@pytest.mark.slow
def test_fold_and_pitchfork_change_order_at_the_meeting(meeting):
    """Along the branch (in λ2(0)) the LN lies beyond the pitchfork on one side of M* and before it on the other."""
    curve, meetings = meeting
    M = meetings[0].X[-1]
    sides = [np.sign(lam_fold - lam_bp)
             for (_, lam_fold), (_, lam_bp) in (gas_branch(M * (1 + d)) for d in (-1e-3, 1e-3))]
    assert sides[0] * sides[1] < 0


def test_meeting_stored_shown_and_drawn(meeting, tmp_path, capsys):
    """``critical`` writes the meeting to the curve file; ``inspect`` prints it, ``inspect --json`` lists it (q and
    P of the meeting found in memory); the phase diagram draws it."""
    curve, meetings = meeting
    out = tmp_path / "M.h5"
    # exit 1: no critical M (P reaches 0 before the curve turns back)
    assert main(["critical", SCENE, "--parameter", "M", "-o", str(out), "--quiet"]) == 1
    assert f"the LN fold meets the pitchfork at M = {meetings[0].X[-1]:.10g}" in capsys.readouterr().err
    assert main(["inspect", str(out), "--json"]) == 0
    stored = json.loads(capsys.readouterr().out)["curves"]["pear"]["meetings"]
    assert [(m["kind"], m["status"]) for m in stored] == [("LN-BP", "located")]
    assert stored[0]["q"] == pytest.approx(meetings[0].X[-1], rel=1e-12)
    assert stored[0]["pressure"] == pytest.approx(meetings[0].X[curve.n], rel=1e-12)
    assert main(["inspect", str(out)]) == 0
    assert "LN-BP meeting        M = " in capsys.readouterr().out
    assert main(["plot", str(out), "--what", "phase", "-o", str(tmp_path / "phase.png")]) == 0


def test_sphere_pitchforks_against_the_closed_form():
    """At M = 0 (the sphere, P = 2Φ1/λ², n = P V ∝ Pλ³) every pear point has d ln P/d ln λ = −1 and d ln n/d ln λ = 2
    (docs/numerics.md): the fold tests of the symmetric tangent along the SPOM1 pitchfork curve in α1 (λ the pole
    stretch, V from ``Equilibrium.volume``) to 1e-8 (measured: 5e-12, 1e-11; α1 1.3 to 1.66); no meeting."""
    branch = trace_primary(load_scene("spom1"))
    curve = continue_branch_point(branch, pear_point(branch), "alpha1", 1.0, max_points=12)
    assert curve.meetings == []
    system = curve.system()
    north = curve.disc.pole_rows()["lam2_top"]
    tangents = oriented_tangents(system, curve.X)
    for X, tau in zip(curve.X, tangents):
        u, P = X[:curve.n], X[curve.n]
        lam, dlam = north @ u, north @ tau[:curve.n]
        assert FoldTest(system, Control.PRESSURE)(X, tau) * lam / (P * dlam) == pytest.approx(-1.0, abs=1e-8)
        rate = FoldTest(system, Control.GAS)(X, tau) * lam / (P * 2 * np.pi * system.eq.volume(u) * dlam)
        assert rate == pytest.approx(2.0, abs=1e-8)


@pytest.mark.slow
def test_paper_coil_meetings_on_the_isola_curve():
    """The paper's single coil (a = 1.961): the pitchfork curve in M merges at the critical M and comes back along
    the partner pitchfork, meeting the LN and then the LV (measured: M = 0.0039361829, 0.0033308375). At each, a
    primary branch traced at that M under that control has the fold and a held pitchfork at the meeting's P to
    1e-8 (measured: LN 1.2e-12, BP 2.0e-12; LV 1.4e-10, BP 3.4e-11)."""
    scene = load_scene("spom1_paper_coil")
    branch = trace_primary(scene)
    curve = continue_branch_point(branch, pear_point(branch), "M", 1.0)
    assert curve.end.value == "isola_merge"
    assert [(m.kind, m.status) for m in curve.meetings] == [(Kind.LN_BP, Status.LOCATED), (Kind.LV_BP, Status.LOCATED)]
    for meeting, control in zip(curve.meetings, ("gas", "volume")):
        M, P = meeting.X[-1], meeting.X[curve.n]
        assert M < curve.critical[0]
        plain = trace_primary(scene.with_overrides({"field.M": M, "loading.control": control}, name=control))
        folds = [s.X[-1] for s in plain.special if s.kind == Kind(meeting.kind.value[:2])]
        assessments, _ = assess_branch(plain, scene.stability.degree)
        pitchforks = [locate(plain, *e).X[-1] for e in detect(plain, assessments) if e[1] == Block.ODD_HELD]
        assert min(abs(np.array(folds) - P)) < 1e-8 and min(abs(np.array(pitchforks) - P)) < 1e-8


def test_newton_on_the_augmented_system_agrees(meeting):
    """A second method: Newton on the pitchfork system (R, H_odd φ, ℓ·φ − 1) augmented with the fold system of gas
    control (F_x w, ∇n·w, ℓ_w·w − 1), square in (u, P, φ, q, w), from the curve point before the meeting: it
    converges (regular: the meeting is an isolated codim-2 point) to the located meeting, 1e-11 in M and P
    (measured: 1.7e-15, 1.0e-14; 4 iterations)."""
    curve, meetings = meeting
    pitchfork = curve.system()
    n, m = pitchfork.n, pitchfork.m
    u, P, phi, q = pitchfork.split(curve.X[meetings[0].index])
    w = fold_tangent(pitchfork.eq, np.append(u, P), Control.GAS, pitchfork.set_q(q))
    fold = FoldSystem(pitchfork.eq, pitchfork.set_q(q), curve.second, Control.GAS, w)
    Z = np.concatenate([u, [P], phi, [q], w])
    for _ in range(10):
        X, w = Z[:n + m + 2], Z[n + m + 2:]
        Y = np.concatenate([X[:n + 1], w, X[-1:]])  # the fold system's (u, P, w, q)
        J = np.zeros((Z.size, Z.size))
        J[:n + m + 1, :n + m + 2] = pitchfork.jacobian(X)
        rows = fold.jacobian(Y)[n:]
        J[n + m + 1:, :n + 1], J[n + m + 1:, n + m + 1], J[n + m + 1:, n + m + 2:] = \
            rows[:, :n + 1], rows[:, -1], rows[:, n + 1:-1]
        step = np.linalg.solve(J, -np.concatenate([pitchfork.residual(X), fold.residual(Y)[n:]]))
        Z += step
        if np.abs(step).max() < 1e-13:
            break
    assert np.abs(step).max() < 1e-13
    assert abs(Z[n + m + 1] - meetings[0].X[-1]) < 1e-11 and abs(Z[n] - meetings[0].X[n]) < 1e-11
