"""A spheroid's held m = 0 reading (analysis/stability/axisymmetric.py ``held_means``, banded.py): the balloon held at
the centroid of its reference surface, ∫δη dA = 0 with dA = R S' dθ dφ = S' d(cos θ) dφ, S' = sqrt(cos²θ + c² sin²θ)
on the spheroid of aspect c (not the sphere's ∫δη d(cos θ) = 0, which the blocks held before: at aspect 0.7, M = 0
the lowest odd_held eigenvalue of the test below read 15.6417 for 15.7401).

Independent checks, written here from the meridian R = sin θ, Z = c cos θ: at M = 0 the rigid axial translation
(δη = 1, the coefficient b_0) is an exact zero mode of the full equator-odd block (H t = 0), its eigenvector there,
and the held block's spectrum is the rest of that block's (the displacement norm's G carries S', so the centroid
hold is G-orthogonal to t); in a coil's field, where the hold is a constraint, the held block's lowest eigenvalues
are those of the full block projected on the null space of the row ∫δη S' dx, by scipy here; the banded sibling
(its own elements and constraint row) gives the same to within both discretisations' error estimates.
"""
import pickle

import numpy as np
import pytest
from scipy import linalg

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.stability.axisymmetric import SecondVariation, point_degrees
from balloon_cg.analysis.stability.banded import BandedVariation
from balloon_cg.analysis.points.branch_points import general_tracer, mode_direction, plain_degree, to_general
from balloon_cg.galerkin.discretisation import Discretisation, held_surface
from balloon_cg.galerkin.equilibrium import Parameters
from balloon_cg.model import meridian
from balloon_cg.numerics.newton import newton
from balloon_cg.post.quantities import held_geometry
from balloon_cg.scene import load_scene

COUNT = 3


def spheroid_branch(aspect: float, scene: str, stop: float):
    """The primary branch of ``scene`` on the spheroid of ``aspect`` to the pole stretch ``stop`` (no pears)."""
    return trace_primary(load_scene(scene).with_overrides(
        {"geometry.shape": "spheroid", "geometry.aspect": aspect, "continuation.stop_stretch": stop,
         "surface.branches": "none"}), down=False)


def odd_coefficients(variation) -> np.ndarray:
    """The equator-odd coefficients a_odd, b_even with b_0 (a_0..a_N, b_0..b_N: MODEL.md §5)."""
    k, na = np.arange(variation.basis.degree + 1), variation.basis.degree + 1
    return np.concatenate([k[k % 2 == 1], na + k[k % 2 == 0]])


def centroid_row(variation, aspect: float) -> np.ndarray:
    """∫δη S' dx per coefficient, from its η function's node values and the nodes' weights, S' written here."""
    x = variation.basis.cos_theta
    rate = np.hypot(x, aspect * np.sqrt(1.0 - x * x))
    return (variation.weights * rate) @ variation.ops[2]


def projected_lowest(H, G, row, idx) -> np.ndarray:
    """The COUNT lowest μ of H q = μ G q on the coefficients idx with row·q = 0 (scipy's null space and eigh)."""
    Z = linalg.null_space(row[idx][None, :])
    Hz, Gz = Z.T @ H[np.ix_(idx, idx)] @ Z, Z.T @ G[np.ix_(idx, idx)] @ Z
    return linalg.eigh(Hz, Gz, eigvals_only=True, subset_by_index=(0, COUNT - 1))


def banded_and_estimate(eq, u, params):
    """The banded sibling's odd_held COUNT lowest and its estimate |μ(p = 8) − μ(p = 6)| (8 elements, half
    interval)."""
    fine, coarse = (BandedVariation(eq, 8, order, symmetric=True).lowest_blocks(u, params)["odd_held"][:COUNT]
                    for order in (8, 6))
    return fine, np.abs(fine - coarse)


@pytest.mark.parametrize("aspect", [0.7, 1.6])
def test_held_block_of_a_field_free_spheroid_is_its_odd_block_without_the_translation(aspect):
    """M = 0, SPOM1, the middle point of the primary branch to pole stretch 1.6, perturbation degree 40: the axial
    translation b_0 (δη = 1, δλ2 = 0 at every node) has |H t| ≤ 1e-10 |H| (measured 0: the kernels' η enters
    through η' only) and is the eigenvector of the full odd block's eigenvalue nearest zero (|μ| ≤ 1e-9, measured
    2.5e-13; G-cosine with t ≥ 1 − 1e-10, measured 1 to rounding); the odd block's next COUNT eigenvalues are
    odd_held's (dense) to 1e-9 relative (measured ≤ 5.3e-13), and the banded sibling's within its own estimate plus
    1e-9 relative (measured ≤ 3.3e-12 apart). With the sphere's hold (the code before) odd_held's were up to 0.63 %
    off (15.6417 for 15.7401 at aspect 0.7)."""
    branch = spheroid_branch(aspect, "spom1", 1.6)
    eq, X = equilibrium_of(branch), branch.X[len(branch.X) // 2]
    u, params = X[:-1], branch.params_at(X)
    assert branch.scene.stability.norm == "displacement" and params.M == 0.0
    variation = SecondVariation(eq, 40)
    H, _ = variation.matrices(u, params)
    G, idx, t = variation.gram, odd_coefficients(variation), variation.basis.degree + 1
    assert np.array_equal(variation.ops[2][:, t], np.ones(variation.basis.x.size))
    assert not variation.ops[0][:, t].any()
    Hodd, Godd = H[np.ix_(idx, idx)], G[np.ix_(idx, idx)]
    translation = (idx == t).astype(float)
    assert np.linalg.norm(Hodd @ translation) <= 1e-10 * np.linalg.norm(Hodd)
    values, vectors = linalg.eigh(Hodd, Godd)
    zero = int(np.argmin(np.abs(values)))
    assert abs(values[zero]) <= 1e-9
    v = vectors[:, zero]
    cosine = abs(v @ Godd @ translation) / np.sqrt((v @ Godd @ v) * (translation @ Godd @ translation))
    assert cosine >= 1.0 - 1e-10
    rest = np.delete(values, zero)[:COUNT]
    held = variation.assess(u, params, True).blocks["odd_held"][:COUNT]
    np.testing.assert_allclose(held, rest, rtol=1e-9, atol=0)
    banded, estimate = banded_and_estimate(eq, u, params)
    assert np.all(np.abs(banded - rest) <= estimate + 1e-9 * np.abs(rest)), (banded - rest, estimate)


@pytest.fixture(scope="module")
def in_a_field():
    """SPOM1 on the spheroid of aspect 1.3 in one coil of radius 4 at the equator, M = 0.002: the primary branch to
    pole stretch 1.8, its m = 0 and m = 1 points located (``analyse``, no pear branches)."""
    scene = load_scene("spom1_single_coil").with_overrides(
        {"geometry.shape": "spheroid", "geometry.aspect": 1.3, "continuation.stop_stretch": 1.8,
         "surface.branches": "none"})
    return analyse(scene, pear=False).primary


def test_located_pear_point_of_a_spheroid_in_a_field_is_a_zero_of_the_held_block(in_a_field):
    """The Werner–Spence system (analysis/points/extended_systems.py) locates the odd_held branch point on the blocks'
    held functions: the dense odd_held block at the located point has an eigenvalue within 1e-9 of zero at degrees
    40 and 60 (measured 4.8e-13, 1.9e-12; P* = 1.8290822088)."""
    branch = in_a_field
    (bp,) = [s for s in branch.branch_points() if s.block.value == "odd_held"]
    eq = equilibrium_of(branch)
    for degree in (40, 60):
        values = SecondVariation(eq, degree).lowest(bp.X[:-1], branch.params_at(bp.X), True, "odd_held")
        assert np.abs(values).min() <= 1e-9, (degree, values)


def test_held_block_of_a_spheroid_in_a_field_is_the_centroid_projection(in_a_field):
    """``in_a_field`` (the hold is a constraint: the translation is no zero mode), its last point at its
    point degree (40, P = 1.2319; odd_held's lowest −0.6706: past a pear point): odd_held's COUNT lowest (dense)
    against the full odd block's projected on ∫δη S' dx = 0 to 1e-9 relative (measured 1.1e-12), and the banded
    sibling's within its own estimate plus 1e-9 relative (measured ≤ 8.2e-13 apart); the sphere's hold ∫δη dx = 0
    gives others (the test's power: 2.8e-3 relative, −0.6691 for −0.6706, which the code before read), and
    odd_free (the translation included) is the unconstrained block's (measured 3.1e-10)."""
    aspect, branch = 1.3, in_a_field
    eq, X = equilibrium_of(branch), branch.X[-1]
    u, params = X[:-1], branch.params_at(X)
    assert params.M > 0.0
    variation = SecondVariation(eq, int(point_degrees(branch, branch.scene.stability.degree)[-1]))
    H, _ = variation.matrices(u, params)
    G, idx = variation.gram, odd_coefficients(variation)
    blocks = variation.assess(u, params, True).blocks
    projected = projected_lowest(H, G, centroid_row(variation, aspect), idx)
    np.testing.assert_allclose(blocks["odd_held"][:COUNT], projected, rtol=1e-9, atol=0)
    sphere_hold = (variation.weights @ variation.ops[2])
    other = projected_lowest(H, G, sphere_hold, idx)
    assert np.abs(other / projected - 1.0).max() > 1e-6
    free = linalg.eigh(H[np.ix_(idx, idx)], G[np.ix_(idx, idx)], eigvals_only=True, subset_by_index=(0, COUNT - 1))
    np.testing.assert_allclose(blocks["odd_free"][:COUNT], free, rtol=1e-9, atol=0)
    banded, estimate = banded_and_estimate(eq, u, params)
    assert np.all(np.abs(banded - projected) <= estimate + 1e-9 * np.abs(projected)), (banded - projected, estimate)


@pytest.mark.parametrize("aspect", [0.7, 1.3])
def test_held_general_basis_of_a_spheroid_holds_its_area_centroid(aspect):
    """The equilibrium's held general basis (``Tracer.system``: a pear branch's, the balloon held in a coil's field)
    holds the centroid of the reference spheroid: every η function has ∫η S' dx = 0 with S' = sqrt(x² + c²(1 − x²))
    written here, to 1e-13 (the quadrature's own error on ∫P_k S' dx; the code before dropped b_0, ∫η dx = 0:
    ∫P_2 S' dx ≠ 0); the sphere's held basis is the one without b_0, bit for bit."""
    scene = load_scene("spom1_single_coil").with_overrides({"geometry.shape": "spheroid", "geometry.aspect": aspect})
    disc = general_tracer(scene).system(40, Parameters(P=1.0, M=0.002)).eq.disc
    assert disc.pin_translation and not disc.symmetric
    rate = np.hypot(disc.cos_theta, aspect * disc.sin_theta)
    eta = disc.ops[2][:, disc.a_index.size:]
    means = (disc.weights * rate) @ eta
    assert np.abs(means).max() <= 1e-13 * np.abs((disc.weights * rate) @ np.abs(eta)).max(), np.abs(means).max()
    sphere = general_tracer(load_scene("spom1_single_coil")).system(40, Parameters(P=1.0, M=0.002)).eq.disc
    plain = Discretisation(40, False, True, sphere.quadrature)
    assert np.array_equal(sphere.ops, plain.ops) and not sphere.eta_mean.any()


def pear_corrections(branch, bp, deltas):
    """(P, state) of the general held system's corrections on φ·(X − X*) = δ from X* + δφ (``pear.pear_leg``'s first
    step; φ the located critical mode in the general basis), per δ."""
    scene = branch.scene
    tracer = general_tracer(scene, bp.block)
    degree = plain_degree(branch, bp.X)
    system = tracer.system(degree, branch.params)
    X_star = np.append(to_general(branch, tracer, degree, bp.X[:-1]), bp.X[-1])
    phi = mode_direction(bp, system.eq.disc)
    points = []
    for delta in deltas:
        guess = X_star + delta * phi
        result = newton(system.residual, system.jacobian, guess, phi, phi @ guess, scene.solver.tol,
                        scene.solver.max_newton)
        assert result.converged, delta
        points.append(result.x)
    return X_star, np.array(points)


def test_traced_held_pear_branch_of_a_spheroid_passes_through_its_branch_point(in_a_field):
    """``in_a_field``'s odd_held pear point: the held pear branch's corrections at φ·(X − X*) = ±δ (δ = 0.02, 0.01,
    0.005; P even in δ: P(δ) = P(−δ) to 1e-12) extrapolated to δ = 0 (the mean of ±δ is X* + O(δ²), Richardson
    in δ²) give P* and the state (its coefficient vector's norm) at the located point within max(1e-9 rel, the
    estimate: the two Richardson pairs' difference) (measured: P 9.6e-12 off, the state 2.4e-10 relative, estimate
    3.5e-9). The code before held the equilibrium by b_0 (the sphere's centroid), the
    stability blocks by the area centroid: its branch went through P = 1.8290758529, 6.4e-6 below the P* located."""
    branch = in_a_field
    (bp,) = [s for s in branch.branch_points() if s.block.value == "odd_held"]
    X_star, X = pear_corrections(branch, bp, (0.02, 0.01, 0.005, -0.02, -0.01, -0.005))
    assert np.abs(X[:3, -1] - X[3:, -1]).max() <= 1e-12 * abs(X_star[-1])
    mean = 0.5 * (X[:3] + X[3:])
    fine, coarse = (4.0 * mean[2] - mean[1]) / 3.0, (4.0 * mean[1] - mean[0]) / 3.0
    u_off, u_bound = np.linalg.norm(fine[:-1] - X_star[:-1]), np.linalg.norm(fine[:-1] - coarse[:-1])
    assert u_off <= max(1e-9 * np.linalg.norm(X_star[:-1]), u_bound), (u_off, u_bound)
    assert abs(fine[-1] - X_star[-1]) <= max(1e-9 * X_star[-1], abs(fine[-1] - coarse[-1])), fine[-1] - X_star[-1]


def test_held_surface_survives_pickling_and_storage():
    """A held general basis's surface (``held_surface``: a spheroid's aspect, a capsule's length only) comes back
    from a pickle (``Discretisation.__reduce__``) and from the stored attrs held_shape, held_size
    (post/quantities.py ``held_geometry``) equal, so that a stored held pear branch evaluates on its own hold."""
    for table in ({"geometry.shape": "spheroid", "geometry.aspect": 1.3},
                  {"geometry.shape": "capsule", "geometry.length": 2.0, "geometry.element_length": 1.0}):
        geometry = load_scene("spom1_single_coil").with_overrides(table).geometry
        held = held_surface(geometry, False, True)
        disc = Discretisation(24, False, True, joins=meridian.joins(geometry), held=held)
        assert pickle.loads(pickle.dumps(disc)) == disc and disc.eta_mean.any()
        size = held.aspect if held.shape.value == "spheroid" else held.length
        assert held_geometry({"held_shape": held.shape.value, "held_size": size}) == held
        assert held_surface(geometry, True, True) is None and held_surface(geometry, False, False) is None
    assert held_surface(load_scene("spom1_single_coil").geometry, False, True) is None
