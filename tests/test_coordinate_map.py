"""The mapped Legendre basis (coordinate_map.WireMap, Discretisation(mapping=...)): map properties, exact
quadrature and transfer, accuracy near a wire against shooting, and a branch that reaches its wire gap."""
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.branches.problem import ParameterSystem

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.results import Classification, StopCode

from balloon_cg.analysis.branches.wires import wire_gap, wire_map
from balloon_cg.galerkin.coordinate_map import WireMap
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.numerics.newton import newton
from balloon_cg.post.quantities import surface
from balloon_cg.scene import load_scene
from balloon_cg.model.shooting import shoot_symmetric

import shared_pictures

SCENE = Path(__file__).resolve().parent.parent / "scenes" / "spom1_two_coils_M0.002.toml"
MAP = WireMap((0.5, -0.5), (0.06, 0.06))


def test_map_is_monotone_onto_and_odd_for_mirrored_centres():
    x = np.linspace(-1, 1, 2001)
    s = MAP.s(x)
    assert s[0] == pytest.approx(-1, abs=1e-15) and s[-1] == pytest.approx(1, abs=1e-15)
    assert np.all(np.diff(s) > 0) and np.all(MAP.ds_dx(x) > 0)
    np.testing.assert_allclose(MAP.s(-x), -s, atol=1e-15)
    np.testing.assert_allclose(MAP.x(s), x, atol=1e-13)
    h = 1e-6  # derivatives against central differences
    np.testing.assert_allclose(MAP.ds_dx(x[1:-1]), (MAP.s(x[1:-1] + h) - MAP.s(x[1:-1] - h)) / (2 * h), rtol=1e-6)
    np.testing.assert_allclose(MAP.d2s_dx2(x[1:-1]), (MAP.ds_dx(x[1:-1] + h) - MAP.ds_dx(x[1:-1] - h)) / (2 * h),
                               rtol=1e-5, atol=1e-6)
    with pytest.raises(ValueError, match="widths"):
        WireMap((0.5,), (0.0,))


def test_map_ends_are_exact():
    """h(±1) = ±1 to the last bit: the sum of one centre at 0.6 rounds one ulp short of 1 without the guard."""
    for mapping in (MAP, WireMap((0.6,), (0.06,)), WireMap((0.3,), (0.05,)), WireMap((-0.4, 0.4), (0.3, 0.3))):
        assert mapping.s(np.array([-1.0, 1.0])).tolist() == [-1.0, 1.0]


def test_mapped_quadrature_and_transfer():
    general = Discretisation(64, False, False, mapping=MAP)
    assert general.weights.sum() == pytest.approx(2.0, abs=1e-13)  # ∫ dx over [−1, 1]
    assert general.weights @ np.exp(general.cos_theta) == pytest.approx(np.e - 1 / np.e, rel=1e-12)
    disc = Discretisation(64, True, False, mapping=MAP)  # integrands even in x, on the nodes x ≥ 0
    assert disc.weights.sum() == pytest.approx(2.0, abs=1e-13)
    assert disc.weights @ np.cosh(disc.cos_theta) == pytest.approx(2.0 * np.sinh(1.0), rel=1e-12)
    plain = Discretisation(20, True, False)
    a, b = np.zeros(21), np.zeros(21)
    a[0], a[2], b[1], b[3] = 1.5, 0.1, 1.5, 0.05
    u = plain.join(a, b)
    theta = np.linspace(0, np.pi, 91)
    moved = plain.transfer(u, disc)
    for before, after in zip(plain.evaluate(u, theta), disc.evaluate(moved, theta)):
        assert np.abs(before - after).max() < 1e-10
    np.testing.assert_allclose(disc.transfer(moved, plain), u, atol=1e-10)
    # the pole rows of the mapped basis are those of Legendre (h(±1) = ±1)
    assert disc.pole_rows()["lam2_top"] @ moved == pytest.approx(plain.pole_rows()["lam2_top"] @ u, abs=1e-12)


def test_curvature_of_a_mapped_profile_matches_the_plain_one():
    plain = Discretisation(20, True, False)
    a, b = np.zeros(21), np.zeros(21)
    a[0], a[2], b[1], b[3] = 1.5, 0.1, 1.5, 0.05
    X = np.append(plain.join(a, b), 1.0)
    disc = Discretisation(64, True, False, mapping=MAP)
    theta = np.linspace(0, np.pi, 61)
    expected, got = surface(plain, X, theta), surface(disc, plain.transfer(X, disc), theta)
    for key in ("lam1", "rho", "k_meridian", "k_parallel", "gaussian_curvature"):
        np.testing.assert_allclose(got[key], expected[key], atol=1e-8, err_msg=key)


def test_map_width_follows_the_gap_along_the_membrane_within_its_bounds():
    """ε = gap · clip(0.8 |dx/ds|, 0.1, 0.4) below gap 2 (wires.map_width): positive at a pole (|dx/ds| = 0)."""
    from balloon_cg.analysis.branches.wires import Approach, map_width

    assert map_width(Approach(1.0, 0.3, 0.0)) == pytest.approx(0.03)
    assert map_width(Approach(0.0, 0.5, 0.3)) == pytest.approx(0.12)
    assert map_width(Approach(0.0, 0.05, 1.15)) == pytest.approx(0.02)
    assert map_width(Approach(0.0, 2.0, 0.5)) is None


def test_stretched_membrane_gets_a_narrower_map_and_a_lower_degree():
    """The a = 4 coil (spom1_single_coil): where the membrane is stretched (|dx/ds| ≈ 0.26 at the wire) the map
    width 0.8·gap·|dx/ds| ≈ 0.21·gap in x resolves the branch to its wire gap at degree 60 (0.4·gap: 135;
    benchmarks/results/wire_map_widths.txt)."""
    scene = load_scene(SCENE.parent / "spom1_single_coil.toml")
    branch = trace_primary(scene, down=False)
    assert branch.stopped(StopCode.WIRE_GAP) and branch.disc.mapping is not None
    assert branch.disc.degree <= 60


@pytest.fixture(scope="module")
def near_wire():
    """The two-coil primary branch landed at pole stretch 1.8 (gap ≈ 0.17) and its shooting pressure."""
    scene = load_scene(SCENE).with_overrides({"continuation.stop_stretch": 1.8})
    branch = trace_primary(scene, down=False)
    X = branch.X[-1]
    eta0 = float(branch.disc.pole_rows()["eta_top"] @ X[:-1])
    shot = shoot_symmetric(scene, 1.8, X[-1], eta0, tol=1e-13)
    assert shot.converged
    return scene, branch, X, shot.P


def _solve_at(scene, branch, X, disc, stretch):
    system = ParameterSystem(Equilibrium(scene, disc), branch.params, "P")
    row = np.append(disc.pole_rows()["lam2_top"], 0.0)
    result = newton(system.residual, system.jacobian, branch.disc.transfer(X, disc), row, stretch, 1e-13, 30)
    assert result.converged
    return result.x


def test_mapped_basis_resolves_the_wire_with_a_third_of_the_degree(near_wire):
    """Degree 64: relative P error < 3e-9 against shooting with the wire map, > 1e-5 in plain Legendre."""
    scene, branch, X, P_ref = near_wire
    mapping = wire_map(branch.disc, X[:-1], scene.field.coils, True)
    assert mapping is not None and len(mapping.centres) == 2
    errors = {}
    for name, m in (("plain", None), ("mapped", mapping)):
        disc = Discretisation(64, True, False, mapping=m)
        errors[name] = abs(_solve_at(scene, branch, X, disc, 1.8)[-1] / P_ref - 1)
    assert errors["mapped"] < 3e-9 and errors["plain"] > 1e-5


def test_branch_reaches_the_wire_gap_and_its_end_matches_shooting():
    """The default two-coil scene now ends on its wire_gap (0.1), not on resolution, and the last point's pressure
    agrees with shooting at its pole stretch."""
    scene = load_scene(SCENE)
    branch = trace_primary(scene, down=False)
    assert branch.stopped(StopCode.WIRE_GAP) and branch.disc.mapping is not None
    # each point passed max_error on its own basis; the stored estimate adds the (measured) loss of its transfer
    # to the final mapped basis
    assert np.all(branch.error_estimate <= scene.solver.max_error + 1e-11)
    X = branch.X[-1]  # the last stored point, one continuation step before the one within wire_gap
    assert wire_gap(branch.disc, X[:-1], scene.field.coils)[0] < 0.12
    stretch = float(branch.disc.pole_rows()["lam2_top"] @ X[:-1])
    eta0 = float(branch.disc.pole_rows()["eta_top"] @ X[:-1])
    shot = shoot_symmetric(scene, stretch, X[-1], eta0, tol=1e-13)
    assert shot.converged and abs(shot.P / X[-1] - 1) < 1e-8


def _pear_point(branch):
    from balloon_cg.analysis.points import branch_points as bifurcation
    from balloon_cg.analysis.stability.axisymmetric import SecondVariation

    variation = SecondVariation(equilibrium_of(branch), branch.disc.degree)
    odd = bifurcation.block_indices(variation, "odd_held", False)
    lowest = np.array([variation._lowest(variation.matrices(X[:-1], branch.params.with_value("P", X[-1]))[0],
                                         odd)[0] for X in branch.X])
    i = int(np.flatnonzero(np.sign(lowest[:-1]) != np.sign(lowest[1:]))[0])
    return bifurcation.classify(branch, bifurcation.locate(branch, i, "odd_held", 0))


@pytest.mark.parametrize("preset", [None, "TPOM1"])
def test_the_paper_coil_branch_at_its_largest_field_reaches_the_wire(preset):
    """The paper's single coil at M = 0.003 (Figs. 3–5): the primary branch reaches the wire gap within the
    solver's resolution (main's map rule: degree 202 of 320). A map rule that widened the maps far from the wire
    ended these branches at the resolution limit instead (found by `make paper`, not by a test)."""
    from balloon_cg.post.paper import SINGLE_COIL, SINGLE_COIL_REACH, Case

    overrides = ((("material.preset", preset),) if preset else ()) + (("field.M", 0.003),) + SINGLE_COIL_REACH
    branch = trace_primary(Case(SINGLE_COIL, overrides).load())
    assert branch.stopped(StopCode.WIRE_GAP), branch.stop_reason
    assert branch.disc.degree < branch.scene.solver.max_degree


def test_pear_point_does_not_depend_on_the_basis_map():
    """The pear pitchfork located on the two-coil branch as stored (wire-mapped basis) and on the same branch
    projected to Legendre in x (degree 96) agree: the stability basis stays in x, where the held constraint
    b_0 = 0 means ∫η dx = 0 (in a mapped basis it would mean ∫η ds = 0, a different constraint)."""
    from dataclasses import replace

    scene = load_scene(SCENE)
    mapped = trace_primary(scene, down=False)
    assert mapped.disc.mapping is not None
    disc = Discretisation(96, True, False)
    plain = replace(mapped, disc=disc, X=mapped.disc.transfer(mapped.X, disc))
    bp_mapped, bp_plain = _pear_point(mapped), _pear_point(plain)
    assert bp_mapped.X[-1] == pytest.approx(bp_plain.X[-1], rel=1e-9)
    assert bp_mapped.classification == bp_plain.classification == Classification.PITCHFORK_SUPER


def test_mapped_branch_round_trips_through_hdf5(tmp_path):
    """A branch stored on a mapped basis is rebuilt from the file (map_centres, map_widths) and evaluates to the
    same profile and curvature as in memory."""
    from balloon_cg.post.quantities import branch_discretisation
    from balloon_cg.io.run_file import read_run, write_run

    scene = load_scene(SCENE)
    branch = trace_primary(scene, down=False)
    assert branch.disc.mapping is not None
    write_run(tmp_path / "run.h5", scene, [branch])
    stored = read_run(tmp_path / "run.h5")["branches"]["primary"]
    disc = branch_discretisation(stored)
    assert disc == branch.disc
    theta = np.linspace(0, np.pi, 91)
    expected, got = surface(branch.disc, branch.X[-3:], theta), surface(disc, stored["unknowns"][-3:], theta)
    for key in ("rho", "eta", "k_meridian", "gaussian_curvature"):
        np.testing.assert_array_equal(got[key], expected[key])


@pytest.fixture(scope="module")
def two_coil_picture(tmp_path_factory):
    return shared_pictures.two_coil_picture(tmp_path_factory)  # the axisymmetric branches


def test_held_mapped_basis_keeps_the_hold_and_the_pear_branch_reaches_the_wire(two_coil_picture):
    """On a general (held) basis the map keeps b_0 = 0 meaning ∫η dx = 0 (η = Σ b_k (P_k(s) − m_k)); the pear branch
    of the two-coil scene then reaches its wire gap 0.1 on a mapped basis (before: degree 320 and a resolution
    stop), every stored point within max_error, and its last point matches a plain Legendre solve at degree 320."""
    held = Discretisation(80, False, True, mapping=WireMap((0.6,), (0.06,)))
    rng = np.random.default_rng(0)
    u = rng.normal(size=held.size) / (1 + np.arange(held.size)) ** 2
    assert abs(held.weights @ held.node_state(u)[2]) < 1e-14
    theta = np.array([0.0, np.pi])
    eta = held.evaluate(u, theta)[2]
    assert held.pole_rows()["eta_top"] @ u == pytest.approx(eta[0], abs=1e-14)
    assert held.pole_rows()["eta_bottom"] @ u == pytest.approx(eta[1], abs=1e-14)

    scene = load_scene(SCENE)
    picture = two_coil_picture
    pear = next(b for b in picture.branches if b.name == "pear_0")
    assert pear.stopped(StopCode.WIRE_GAP) and pear.disc.mapping is not None and not pear.disc.symmetric
    assert np.all(pear.error_estimate <= scene.solver.max_error)
    # independent check: the last point re-solved in plain Legendre (degree 320, the same held constraint; shooting
    # solves the free balloon, not the held one) at the same pressure. Not at the same north pole stretch: the
    # branch ends next to its turning point in λ2(0), where P at fixed λ2(0) is ill-conditioned (there plain 320
    # and 400 and mapped 202, 320 and 400 differ by up to 3e-8 in P, by < 1e-9 in λ2(0) at fixed P).
    X = pear.X[-1]
    plain = Discretisation(320, False, True)
    system = ParameterSystem(Equilibrium(scene, plain), pear.params, "P")
    row = np.append(np.zeros(plain.size), 1.0)
    result = newton(system.residual, system.jacobian, pear.disc.transfer(X, plain), row, X[-1], 1e-12, 30)
    north = np.append(plain.pole_rows()["lam2_top"], 0.0)
    stretch = float(pear.disc.pole_rows()["lam2_top"] @ X[:-1])
    assert result.converged and abs(north @ result.x / stretch - 1) < 2 * scene.solver.max_error


def test_mirror_on_the_mirrored_map_matches_the_traced_mirror(two_coil_picture):
    """Two coils, M = 0.002: the stored mirror (the pear branch reflected, on the mirrored two-centre wire map)
    against the mirror traced by its own continuation, which chooses its maps itself: the same map to 1e-9, the
    same points (P, both pole stretches, solved degrees), the same stop; and the m ≥ 1 branch points found on the
    stored mirror (``azimuthal_points``, on its own points) lie where the pear branch's do."""
    from balloon_cg.analysis.results import Origin
    from balloon_cg.analysis.switching.pear import trace_pear

    picture = two_coil_picture
    branches = {b.name: b for b in picture.branches}
    pear, mirror = branches["pear_0"], branches["pear_0_mirror"]
    assert mirror.origin == Origin.REFLECTED and pear.disc.mapping is not None
    traced = trace_pear(picture.primary, picture.branch_points[0], -1.0, "traced")
    assert traced.disc.degree == mirror.disc.degree and len(traced.disc.mapping.centres) == 2
    for ours, theirs in ((mirror.disc.mapping.centres, traced.disc.mapping.centres),
                         (mirror.disc.mapping.widths, traced.disc.mapping.widths)):
        np.testing.assert_allclose(ours, theirs, rtol=1e-9, atol=1e-12)
    assert mirror.disc.mapping.centres != pear.disc.mapping.centres
    assert len(traced.X) == len(mirror.X) and np.array_equal(traced.degree, mirror.degree)
    np.testing.assert_allclose(mirror.X[:, -1], traced.X[:, -1], rtol=1e-9)
    for pole in ("lam2_top", "lam2_bottom"):
        np.testing.assert_allclose(mirror.pole_values()[pole], traced.pole_values()[pole], rtol=1e-9)
    assert [leg.stop.code for leg in mirror.legs] == [leg.stop.code for leg in traced.legs] == [StopCode.WIRE_GAP]
    assert [(s.kind, s.index) for s in mirror.special if s.m == 0] == [(s.kind, s.index) for s in traced.special]
    azimuthal = [[(s.index, s.block, s.X[-1]) for s in b.special if s.m > 0] for b in (pear, mirror)]
    assert azimuthal[0] and [p[:2] for p in azimuthal[0]] == [p[:2] for p in azimuthal[1]]
    np.testing.assert_allclose([p[2] for p in azimuthal[1]], [p[2] for p in azimuthal[0]], rtol=1e-9)


def test_projection_is_accurate_at_high_degree():
    """transfer() projects by least squares: a quadratic moved onto a narrow map at degree 320 is exact to 1e-12
    (the Gauss-weight formula lost ~1e-9 there: numpy's end weights carry ~3e-14, amplified by (k + ½)P_k(±1))."""
    plain = Discretisation(40, False, True)
    a, b = np.zeros(41), np.zeros(41)
    a[0], a[2], b[1], b[2] = 1.5, 0.1, 1.5, 0.05
    u = plain.join(a, b)
    theta = np.linspace(0, np.pi, 721)
    for degree in (135, 320):
        disc = Discretisation(degree, False, True, mapping=WireMap((0.1,), (0.03,)))
        moved = plain.transfer(u, disc)
        for before, after in zip(plain.evaluate(u, theta)[::2], disc.evaluate(moved, theta)[::2]):
            assert np.abs(before - after).max() < 1e-12


def test_bifurcation_work_on_a_mapped_branch_uses_a_degree_that_holds_it(near_wire):
    """Branch points of a mapped branch are classified and continued in x at a degree whose projection and tail
    are within max_error, which near a wire is above the mapped degree."""
    from balloon_cg.analysis.points.branch_points import plain_degree

    scene, branch, X, _ = near_wire
    assert branch.disc.mapping is not None
    degree = plain_degree(branch, X)
    assert degree > branch.disc.degree
    plain = Discretisation(degree, True, False)
    moved = branch.disc.transfer(X, plain)
    assert plain.tail(moved[:-1]) <= scene.solver.max_error


def test_equal_discretisations_share_read_only_tables():
    """Discretisations with the same five fields share their tables (built once), which nobody can change; a
    different field gives other tables."""
    mapping = WireMap((0.3,), (0.05,))
    first, second = Discretisation(24, False, True, 0, mapping), Discretisation(24, False, True, 0, mapping)
    assert first.ops is second.ops and first.weights is second.weights and first.eta_mean is second.eta_mean
    assert not first.ops.flags.writeable and not first.x.flags.writeable
    with pytest.raises(ValueError):
        first.weights[0] = 1.0
    other = Discretisation(24, False, True, 0, WireMap((0.3,), (0.06,)))
    assert other.ops is not first.ops and not np.array_equal(other.x, first.x)
