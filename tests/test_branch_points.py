"""Branch points located by regular extended systems (analysis/points/extended_systems.py, docs/numerics.md §4).

(a) At M = 0 every pear (n = 1) and equator-symmetric (n = 2) branch point of the primary branch against the
closed forms of sphere_modes. (b) Near a coil, the second pear pitchfork against two independent routes: the
pear branch itself (general-space equilibria of amplitude ε → 0) and the two-parameter curve of pear points
continued in M from the first pitchfork back to the scene's M (its partner point).
"""
import numpy as np
import pytest

from balloon_cg.analysis.points import branch_points as bifurcation
from balloon_cg.analysis.critical.pitchfork_curve import continue_branch_point, land_on_q
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.results import Block, Kind, Status, StopCode
from balloon_cg.analysis.stability.axisymmetric import assess_branch
from balloon_cg.model.sphere_modes import bifurcation_stretches
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import parse_scene
from balloon_cg.scene.materials import get_preset

PRESETS = ["SPOM1", "SPOM2", "FPOM1", "FPOM2", "TPOM1", "TPOM2", "neo-Hookean", "Mooney-Rivlin"]
STOP = 8.0


@pytest.mark.parametrize("preset", PRESETS)
def test_sphere_branch_points_match_the_closed_forms(preset):
    """Every closed-form n = 1 (pear, odd_held block) and n = 2 (even block) point of the sphere below the
    branch's largest stretch is a LOCATED branch point to 1e-10 in λ, and the BP index brackets it."""
    scene = parse_scene(f'[material]\npreset = "{preset}"\n[continuation]\nstop_stretch = {STOP}\n', name=preset)
    primary = analyse(scene, pear=False).primary
    lam = primary.pole_values()["lam2_top"]
    for n, block in ((1, Block.ODD_HELD), (2, Block.EVEN)):
        expected = bifurcation_stretches(get_preset(preset), n, lam_max=lam.max())
        found = {bp.index: bp for bp in primary.branch_points(block)}
        located = np.array([primary.pole_values(bp.X)["lam2_top"][0] for bp in found.values()])
        for root in expected:
            assert located.size and np.abs(located - root).min() <= 1e-10, (n, root, located)
        for index, bp in found.items():
            assert bp.kind == Kind.BP and bp.status == Status.LOCATED, bp.reason
            stretch = primary.pole_values(bp.X)["lam2_top"][0]
            assert min(lam[index], lam[index + 1]) <= stretch <= max(lam[index], lam[index + 1])


def coil_scene(preset: str, M: float):
    """One coil of radius 2 at height 0 (current 1): the membrane comes within wire_gap 0.02 of it."""
    return parse_scene(f'[material]\npreset = "{preset}"\n[field]\nM = {M}\n'
                       '[[field.coils]]\nradius = 2.0\nheight = 0.0\ncurrent = 1.0\n'
                       '[continuation]\nstop_stretch = 6.0\nwire_gap = 0.02\n', name=f"{preset}-coil")


def pear_points(scene):
    primary = trace_primary(scene)
    primary.stability, _ = assess_branch(primary, scene.stability.degree, True)
    events = [e for e in bifurcation.detect(primary, primary.stability) if e[1] == Block.ODD_HELD]
    return primary, [bifurcation.locate(primary, *event) for event in events]


def pear_branch_limit(primary, bp, start=None, epsilon: float = 1e-3) -> float:
    """P where the pear branch through ``bp`` meets the primary branch: general-space equilibria (balloon held)
    with amplitude φ·(X − X*) = ε and 2ε (φ the critical mode; from ``start`` or X* + εφ), P(ε) = P* + cε² +
    O(ε⁴) extrapolated to ε = 0."""
    tracer = bifurcation.general_tracer(primary.scene)
    system = tracer.system(bifurcation.plain_degree(primary, bp.X), primary.params)
    star = np.append(bifurcation.to_general(primary, tracer, system.eq.disc.degree, bp.X[:-1]), bp.X[-1])
    phi = bifurcation.mode_direction(bp, system.eq.disc)
    if start is not None:
        phi = phi * np.sign(phi @ (start - star))
    pressures = []
    for amplitude in (epsilon, 2 * epsilon):
        guess = star + amplitude * phi if start is None else start
        solver = primary.scene.solver
        result = newton(system.residual, system.jacobian, guess, phi, phi @ star + amplitude, solver.tol,
                        solver.max_newton)
        assert result.converged, result.message
        pressures.append(result.x[-1])
    return (4 * pressures[0] - pressures[1]) / 3


def partner_pressure(primary, first, second) -> float:
    """P of the pear point at the scene's M on the two-parameter curve continued in M from ``first`` past the
    merge back to the scene's M (the partner of ``first``), landed exactly on that M."""
    curve = continue_branch_point(primary, first, "M")
    assert curve.stop.code == StopCode.PARTNER and len(curve.merges) == 1
    X = land_on_q(curve, primary.params.M, len(curve.X) - 1)
    assert X is not None
    return float(X[curve.n])


NEAR_WIRE = [("SPOM1", 0.001, 1.92839), ("SPOM1", 0.002, 1.96178), ("TPOM1", 0.001, 1.85181)]


def check_near_wire_pitchfork(preset, M, expected):
    primary, bps = pear_points(coil_scene(preset, M))
    assert len(bps) == 2 and all(bp.status == Status.LOCATED for bp in bps), [bp.reason for bp in bps]
    first, second = bps
    assert second.X[-1] == pytest.approx(expected, abs=1e-5)
    index = second.index
    assert (primary.X[index, -1] - second.X[-1]) * (primary.X[index + 1, -1] - second.X[-1]) <= 0
    assert abs(pear_branch_limit(primary, second) - second.X[-1]) <= 1e-8
    assert abs(partner_pressure(primary, first, second) - second.X[-1]) <= 1e-8


def test_second_pitchfork_near_a_coil_matches_the_pear_branch_and_the_two_parameter_curve():
    """SPOM1, M = 0.001: the pitchfork where the pear branch rejoins (P ≈ 1.92839, formerly mislocated at
    1.935366 from an under-resolved stability basis)."""
    check_near_wire_pitchfork(*NEAR_WIRE[0])


@pytest.mark.slow
@pytest.mark.parametrize("case", NEAR_WIRE[1:])
def test_second_pitchfork_near_a_coil_other_cases(case):
    check_near_wire_pitchfork(*case)


@pytest.mark.slow
def test_traced_pear_branch_rejoins_at_the_located_pitchfork():
    """The pear branch traced from the first pitchfork (switching.trace_pear) rejoins where the second is
    located: from its last point, the amplitude limit of the pear equilibria is P* to 1e-8."""
    from balloon_cg.analysis.switching.pear import trace_pear

    primary, (first, second) = pear_points(coil_scene("SPOM1", 0.001))
    pear = trace_pear(primary, first, 1.0, "pear")
    assert pear.stopped(StopCode.REJOINED)
    tracer = bifurcation.general_tracer(primary.scene)
    disc = tracer.system(bifurcation.plain_degree(primary, second.X), primary.params).eq.disc
    last = pear.disc.transfer(pear.X[-1], disc)
    assert abs(pear_branch_limit(primary, second, start=last) - second.X[-1]) <= 1e-8


@pytest.fixture(scope="module")
def tpom1():
    scene = parse_scene('[material]\npreset = "TPOM1"\n[continuation]\nstop_stretch = 3.0\n', name="TPOM1")
    return analyse(scene, pear=False).primary


@pytest.mark.parametrize("block", [Block.ODD_HELD, Block.EVEN])
def test_extended_jacobians_match_differences_of_the_residual(tpom1, block):
    """Werner–Spence and Moore: the Jacobian (third-derivative terms by differences of the generated Hessian)
    against central differences of the exact residual, at the located point; β = 0 there."""
    from balloon_cg.analysis.points.extended_systems import MooreSystem, WernerSpence
    from balloon_cg.analysis.branches.problem import equilibrium_of

    bp = tpom1.branch_points(block)[0]
    eq, params = equilibrium_of(tpom1), tpom1.params
    if block == Block.ODD_HELD:
        system = WernerSpence(eq, params, np.zeros(0))
        phi = bp.mode[system.odd]
        system.ell = phi / (phi @ phi)
        X = np.concatenate([bp.X, phi])
    else:
        system = MooreSystem(eq, params, np.zeros(0))
        psi = bp.mode @ system.embed
        system.ell = psi / (psi @ psi)
        X = np.concatenate([bp.X, psi, [0.0]])
    assert np.abs(system.residual(X)).max() < 1e-8
    J = system.jacobian(X)
    rng = np.random.default_rng(1)
    for _ in range(3):
        d = rng.normal(size=X.size)
        h = 1e-6 / np.abs(d).max()
        numeric = (system.residual(X + h * d) - system.residual(X - h * d)) / (2 * h)
        assert np.abs(J @ d - numeric).max() <= 1e-6 * max(1.0, np.abs(numeric).max())


def test_failed_extended_newton_is_approximate_not_located(tpom1):
    """With one Newton iteration the extended system cannot converge: the point is APPROXIMATE, with the
    bracket's uncertainty and the reason, never LOCATED."""
    from dataclasses import replace

    bp = tpom1.branch_points(Block.EVEN)[0]
    starved = replace(tpom1, scene=tpom1.scene.with_overrides({"solver.max_newton": 1}))
    failed = bifurcation.locate(starved, bp.index, Block.EVEN, 0)
    assert failed.status == Status.APPROXIMATE and "Newton on the extended system failed" in failed.reason
    assert 0 < failed.uncertainty and abs(failed.X[-1] - bp.X[-1]) <= 2 * failed.uncertainty


def test_crossing_must_change_sign_and_converge_at_the_bracketing_points(tpom1):
    """The bracket check behind LOCATED: nothing to report at the located point's interval; an interval without
    a sign change of the crossing eigenvalue is reported."""
    bp = tpom1.branch_points(Block.ODD_HELD)[0]
    assert bifurcation.crossing_problems(tpom1, bp.index, Block.ODD_HELD, 0) == []
    problems = bifurcation.crossing_problems(tpom1, bp.index + 2, Block.ODD_HELD, 0)
    assert any("does not change sign" in p for p in problems)
