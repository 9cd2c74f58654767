"""A capsule's graded basis: a degree per element group, each chosen from its own tail (galerkin/elements.py
``graded_sequence``, analysis/branches/graded.py, scene key ``geometry.element_degrees = "graded"``).

Checked: the graded basis spans the piecewise polynomials of its degrees per element (written here) and holds the
shared (greedy) basis of the same degrees, so states move between them exactly and back; a basis with more degree
in one group holds one with less and the transfer between them permutes coefficients (exact), the reverse is not
nested; each group's tail reads its own series; a point solved on the graded basis its tails choose is the state
of the shared basis of a higher degree (a second basis) within both tail estimates; the traced pressure maximum on
graded elements is the shared basis's; one-line errors.
"""
import numpy as np
import pytest

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import StopCode
from balloon_cg.analysis.branches.graded import covering_basis, graded_point
from balloon_cg.analysis.branches.resolution import Resolution
from balloon_cg.analysis.branches.tracer import unit
from balloon_cg.galerkin.discretisation import Discretisation, graded
from balloon_cg.galerkin.elements import CYLINDER, element_table, group_degrees, groups
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.analysis.branches.problem import ParameterSystem
from balloon_cg.analysis.branches.primary import start_parameters, trace_primary
from balloon_cg.model import meridian, tube
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import SceneError, parse_scene

from test_capsule import capsule_scene, inflated, shared_pressure_maximum

GRADED = '[geometry]\nshape = "capsule"\nlength = {length}\nelement_length = 5.0\nelement_degrees = "graded"\n'


def _cylinder_coordinates(x, joins):
    """(element e, its own t) of cylinder nodes x, written here: ξ = (π/2 − θ)/(π/2 − θj), ξ_e = (2e − n)/n."""
    n, c = len(joins) - 1, joins[-1]
    xi = (np.pi / 2 - np.arccos(x)) / (np.pi / 2 - np.arccos(c))
    bounds = (2 * np.arange(n + 1) - n) / n
    element = np.clip(np.searchsorted(bounds, xi, side="right") - 1, 0, n - 1)
    return element, (2 * xi - bounds[element] - bounds[element + 1]) / (bounds[element + 1] - bounds[element])


def test_graded_basis_spans_its_degrees_per_element_and_holds_the_shared_basis():
    """Capsule of length 20, 5 cylinder elements (groups: the middle element, two mirror pairs, the caps). The
    graded basis of degrees (30, 6, 4, 8): φ_k of parity (−1)^k, continuous at every join; a continuous function of
    degree 30 in θ on the middle element, 6 and 4 on the pairs (different on each element of a pair), 8 in x on the
    caps (written here) fitted exactly (least squares at 1500 points, 1e-10), which the graded basis (29, 6, 4, 8)
    cannot (> 1e-6); (12, 6, 4, 8) moves into (30, 6, 4, 8) exactly (1e-13 on a θ grid), the reverse is not nested;
    the shared basis of degree N moves into the graded basis of its own group degrees exactly and, where those hold
    the same functions, back; a function in the middle element's bubbles alone has no tail in the other groups."""
    joins = meridian.joins(capsule_scene(20.0, element=5.0).geometry)
    assert len(joins) == 6 and len(groups(joins)) == 4
    shape = Discretisation(40, False, False, joins=joins)
    wide = graded(shape, (30, 6, 4, 8))
    assert wide.degree + 1 == 2 + 4 + 29 + 2 * (5 + 3) + 2 * 8 and wide.element_degrees == (30, 6, 4, 8)
    x = np.cos(np.linspace(0.0, np.pi, 1500))
    p, _ = element_table(x, wide.degree, joins, wide.element_degrees)
    flipped, _ = element_table(-x, wide.degree, joins, wide.element_degrees)
    assert np.abs(flipped - p * (-1.0) ** np.arange(wide.degree + 1)).max() < 1e-12
    for side in joins:
        across, slopes = element_table(np.array([side - 1e-12, side + 1e-12]), wide.degree, joins, wide.element_degrees)
        assert np.all(np.abs(across[0] - across[1]) < 1e-12 + 2e-12 * np.abs(slopes).max(axis=0))
    c = joins[-1]
    cylinder = np.abs(x) <= c
    element, t = _cylinder_coordinates(np.where(cylinder, x, 0.0), joins)
    knots = np.cos(np.arange(6))  # the function's values at the cylinder's six boundaries
    own = {0: 4, 1: 6, 2: 30, 3: 6, 4: 4}  # the degree in θ on each cylinder element, south to north
    bubble = np.array([(1 - ti**2) * (0.4 + 0.1 * e) * np.polynomial.legendre.legval(ti, np.eye(own[e] - 1)[-1])
                       for e, ti in zip(element, t)])
    f = knots[element] * (1 - t) / 2 + knots[element + 1] * (1 + t) / 2 + bubble
    f = np.where(x > c, knots[-1] + 2 * (x - c) - 7 * (x - c) ** 8,
                 np.where(x < -c, knots[0] + (x + c) ** 2 - (x + c) ** 8, f))
    for degrees, exact in (((30, 6, 4, 8), True), ((29, 6, 4, 8), False)):
        disc = graded(shape, degrees)
        table, _ = element_table(x, disc.degree, joins, disc.element_degrees)
        residual = np.abs(table @ np.linalg.lstsq(table, f, rcond=None)[0] - f).max()
        assert residual < 1e-10 if exact else residual > 1e-6
    theta = np.linspace(0.0, np.pi, 401)
    narrow = graded(shape, (12, 6, 4, 8))
    assert narrow.nests_in(wide) and not wide.nests_in(narrow)
    u = np.random.default_rng(3).normal(size=narrow.size)
    moved = narrow.transfer(u, wide)
    assert max(np.abs(a - b).max() for a, b in zip(narrow.evaluate(u, theta), wide.evaluate(moved, theta))) < 1e-13
    for degree in (40, 81, 160):
        shared = Discretisation(degree, True, True, joins=joins)
        same = graded(shared, group_degrees(degree, joins))
        u = np.random.default_rng(degree).normal(size=shared.size)
        there = shared.transfer(u, same)
        assert shared.nests_in(same)
        assert max(np.abs(a - b).max() for a, b in zip(shared.evaluate(u, theta), same.evaluate(there, theta))) < 1e-12
        if same.degree == shared.degree:  # the same functions in another order: back exactly
            assert same.nests_in(shared) and np.abs(same.transfer(there, shared) - u).max() == 0.0
    middle_only = np.zeros(wide.degree + 1)  # 1 and the middle element's bubbles falling as 2^−j
    bubbles = [k for k, (family, _, element, _) in enumerate(wide.function_keys) if (family, element) == (CYLINDER, 2)]
    middle_only[0], middle_only[bubbles] = 1.0, 0.5 ** np.arange(len(bubbles))
    tails = wide.element_tails(np.concatenate([middle_only, np.zeros(wide.degree + 1)]))
    assert len(bubbles) == 29 and tails[0] > 1e-10 and max(tails[1:]) == 0.0


def test_graded_point_is_the_state_of_a_finer_shared_basis():
    """SPOM1 capsule of length 20 cut into 5 elements at P = 1.45 (on its way to its pressure maximum, degree 40):
    solved again at that P on the graded basis its element groups' own tails choose (max_error 1e-11) it is the state
    of the shared basis of degree 200 (a second basis, every group's degree at least the graded one's) within both
    tail estimates: V and λ2 at the middle and at the poles; every group resolved, on fewer unknowns."""
    scene = capsule_scene(20.0, element=5.0)
    eq, u = inflated(scene, 40, 1.45)
    params = start_parameters(scene, "P")
    X = np.append(u, 1.45)

    def system_on(disc):
        return ParameterSystem(Equilibrium(scene, disc), params, "P")

    policy = Resolution(1e-11, 320)
    point = graded_point(system_on, eq.disc, X, unit(X.size, -1), policy, 1e-13, 30)
    assert point.resolved and len(point.rounds) >= 2 and point.X[-1] == 1.45
    fine = Equilibrium(scene, Discretisation(200, True, True, joins=eq.disc.joins))
    assert all(a <= b for a, b in zip(point.rounds[-1][0], group_degrees(200, eq.disc.joins)))
    reference = system_on(fine.disc)
    solved = newton(reference.residual, reference.jacobian, point.disc.transfer(point.X, fine.disc),
                    unit(fine.disc.size + 1, -1), 1.45, 1e-13, 30)
    assert solved.converged and fine.disc.tail(solved.x[:-1]) < 1e-11
    graded_eq = Equilibrium(scene, point.disc)
    bound = max(point.disc.tail(point.X[:-1]), fine.disc.tail(solved.x[:-1])) + 1e-13
    theta = np.array([0.0, np.pi / 2, np.pi])
    assert abs(graded_eq.volume(point.X[:-1]) - fine.volume(solved.x[:-1])) < bound * fine.volume(solved.x[:-1])
    assert np.abs(graded_eq.state_at(point.X[:-1], theta)[0] - fine.state_at(solved.x[:-1], theta)[0]).max() < bound
    assert point.disc.size < fine.disc.size


def test_graded_capsule_folds_where_the_shared_basis_does(tmp_path_factory):
    """SPOM1 capsule of length 10, 3 cylinder elements, traced from degree 40 with geometry.element_degrees =
    "graded": its pressure maximum is the shared basis's (1.5063197245255, docs/shapes.md) to 1e-10, stored on the
    graded basis covering every leg's (``covering_basis``)."""
    scene = parse_scene('[material]\npreset = "SPOM1"\n' + GRADED.format(length=10.0)
                        + "[stability]\nm_max = 0\n[continuation]\nstop_stretch = 1.3\n")
    branch = analyse(scene, pear=False).branches[0]
    fold = next(p for p in branch.special if p.kind.value == "LP")
    assert abs(fold.X[-1] - shared_pressure_maximum(tmp_path_factory, 10.0, 40)) < 1e-10
    assert branch.disc.element_degrees and branch.disc.tail(fold.X[:-1]) <= 1e-9


def test_covering_basis_holds_every_basis_it_covers():
    """The covering basis of a shared basis and two graded ones holds each (nests_in) and takes their highest
    degree per group."""
    joins = meridian.joins(capsule_scene(20.0, element=5.0).geometry)
    shared = Discretisation(60, True, True, joins=joins)
    used = [shared, graded(shared, (30, 6, 4, 8)), graded(shared, (10, 12, 4, 3))]
    cover = covering_basis(used)
    top = np.max([group_degrees(d.degree, joins, d.element_degrees) for d in used], axis=0)
    assert cover.element_degrees == tuple(top) and all(d.nests_in(cover) for d in used)


@pytest.mark.parametrize("text, key", [
    ('[geometry]\nshape = "capsule"\nlength = 10\nelement_degrees = "own"\n', 'geometry.element_degrees = "own"'),
    ('[geometry]\nshape = "tube"\nlength = 10\nends = "sliding"\nelement_degrees = "graded"\n',
     'geometry.element_degrees = "graded": only for geometry.shape = "capsule"'),
])
def test_graded_key_errors_name_key_value_and_range(text, key):
    with pytest.raises(SceneError, match="^scene: " + key.replace("(", r"\(")) as error:
        parse_scene('[material]\npreset = "SPOM1"\n' + text)
    assert "\n" not in str(error.value)
    kept = parse_scene('[material]\npreset = "SPOM1"\n' + GRADED.format(length=12.0))
    assert kept.geometry.to_table()["element_degrees"] == "graded"


@pytest.mark.slow
def test_a_graded_long_capsule_propagates_its_bulge_at_maxwells_pressure_at_the_default_max_error():
    """SPOM1 capsule of length 40, 5 cylinder elements, graded, at the default [solver] (max_error 1e-9,
    max_degree 320), traced in P with step_max 1 to pole stretch 3: every stored point within max_error
    (``error_estimate``), from its start (pole stretch 1.001) past its fold, where it starts bulging within 1e-3 of
    the long tube's pressure maximum P* and of a sliding tube's onset at L = 40 (model/tube) and at the shared
    basis's fold (1.4907571927638, docs/shapes.md) to 1e-10, to V/V0 ≥ 700; where both fronts are far from the caps
    and from each other (200 ≤ V/V0 ≤ 600) P is within 1e-4 of Maxwell's pressure (model/tube.maxwell_pressure),
    from V/V0 = 400 within 1e-7. The shared basis stops at max_degree just past the fold (V/V0 2.7).
    Measured (benchmarks/results/capsule_graded.txt): 2.8e-5, 1.9e-8; 1490 points, ~720 s on the loaded machine."""
    text = ('[material]\npreset = "SPOM1"\n' + GRADED.format(length=40.0).replace("element_length = 5.0",
                                                                              "element_length = 10.0")
            + "[stability]\nm_max = 0\n[continuation]\nstop_stretch = 3.0\nstep_max = 1.0\nmax_points = 3000\n")
    scene = parse_scene(text)
    branch = trace_primary(scene)
    assert branch.stopped(StopCode.STOP_STRETCH) and branch.stopped(StopCode.MIN_STRETCH)
    assert branch.error_estimate.max() <= 1e-9 and branch.disc.element_degrees
    fold = next(p.X[-1] for p in branch.special if p.kind.value == "LP")
    assert abs(fold - tube.pressure_maximum(scene.material).pressure) < 1e-3
    assert abs(fold - tube.bulge_onset(scene.material, 40.0).pressure) < 1e-3
    assert abs(fold - 1.4907571927638) < 1e-10
    eq = Equilibrium(scene, branch.disc)
    volume = np.array([2 * np.pi * eq.volume(x[:-1]) for x in branch.X]) / (40 * np.pi + 4 * np.pi / 3)
    maxwell = tube.maxwell_pressure(scene.material)[0]
    plateau = (volume >= 200) & (volume <= 600)
    assert volume.max() >= 700 and plateau.sum() > 50
    assert np.abs(branch.X[plateau, -1] - maxwell).max() <= 1e-4
    assert np.abs(branch.X[plateau & (volume >= 400), -1] - maxwell).max() <= 1e-7
