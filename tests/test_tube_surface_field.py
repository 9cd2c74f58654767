"""The tube over (S, φ) (tube/surface/) in the field of a coaxial coil and under a voltage, and its m = 2 branch.

The energy is written here from its definition, independently of the kernels: the membrane's of
tests/test_tube_surface.py (``written_energy``: the Cartesian point from numpy's Legendre series, the principal
stretches from the metric), −½ χ M H²(√(x² + y²), z) with H² of the coils by the Biot–Savart integral of MODEL.md §3
(tests/test_tube_field.py) and the dielectric term −Φ̄² (λ1 λ2)². At an axisymmetric state the order-0 part is the
interval discretisation's in the same field (its own kernels, the field in (ρ, η)). The m = 2 zero is the primary
branch's first in the field of SPOM1's coil scene at M = 0.03, degree 30 (no m ≥ 2 zero of the field-free tubes has
a stretched membrane, docs/tubes.md): a zero of the discretised problem, the switch checked there; its P moves by
1e-2 between degrees 20, 30 and 40 (the parent's middle bulge is not resolved there: docs/tubes.md)."""
import numpy as np
import pytest

from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.galerkin.interval import IntervalDiscretisation
from balloon_cg.numerics.eigen import NO_CONSTRAINT, GramFactor, restricted
from balloon_cg.tube import azimuthal
from balloon_cg.tube.primary import scene_parameters
from balloon_cg.tube.surface.basis import TubeSurfaceBasis
from balloon_cg.tube.surface.equilibrium import MeridianSurfaceEquilibrium

from test_tube_field import biot_savart_squared
from test_tube_surface import random_state, tube_scene, written_energy, written_point

COIL = "[field]\nM = 0.05\n[[field.coils]]\nradius = 2.5\nheight = 0.0\ncurrent = 1.0\n"
CASES = {"coil": COIL, "voltage": "[electric]\nvoltage = 0.2\n", "both": COIL + "[electric]\nvoltage = 0.2\n"}


def charged_scene(case, ends="sliding", degree=10):
    scene = tube_scene("SPOM1", 10.0, f'ends = "{ends}"\n' + CASES[case])
    disc = IntervalDiscretisation(degree, 10.0, ends=scene.geometry.ends)
    return scene, disc


def written_total(scene, disc, orders, n_phi, c, params):
    """E/(2π): ``written_energy`` (Φ and −P ½ (x, y, 0)·(x_S × x_φ)) plus −½ χ M H² and −Φ̄² (λ1λ2)² at the same
    nodes (Gauss–Legendre in S, the trapezoid in φ)."""
    s, w = np.polynomial.legendre.leggauss(disc.x.size)
    x, x_s, x_p = written_point(disc, orders, c, s, 2 * np.pi * np.arange(n_phi) / n_phi)
    areal_sq = (np.cross(x_s, x_p, axis=0) ** 2).sum(0)  # (λ1 λ2)²
    density = -params.voltage**2 * areal_sq
    coils = [(coil.radius, coil.height, coil.current) for coil in scene.field.coils]
    if coils:
        rho = np.hypot(x[0], x[1])
        density = density - 0.5 * params.chi * params.M * biot_savart_squared(rho.ravel(), x[2].ravel(),
                                                                               coils).reshape(rho.shape)
    extra = (disc.length / 2 * w) @ density.sum(axis=1) / n_phi
    return written_energy(scene.material, disc, orders, n_phi, c, params.P) + extra


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("ends", ("sliding", "plugged"))
def test_energy_in_a_field_and_under_a_voltage_is_the_one_written_here(case, ends):
    """At a random non-axisymmetric state (orders 0, 1, 2): E/(2π) is the energy written here (1e-12 relative), the
    residual its central differences (1e-7 of its largest entry), the Jacobian the residual's (1e-7) and symmetric."""
    scene, disc = charged_scene(case, ends)
    basis = TubeSurfaceBasis(disc, (0, 1, 2))
    surface = MeridianSurfaceEquilibrium(scene, basis)
    rng = np.random.default_rng(13)
    c = basis.axisymmetric(random_state(disc, seed=9)) + 0.02 * rng.standard_normal(basis.size) * (
        np.arange(basis.size) >= disc.size)
    params, h = scene_parameters(scene, 0.9), 1e-6

    def energy(c):
        return written_total(scene, disc, basis.orders, basis.n_phi, c, params)

    E = energy(c)
    assert abs(surface.energy(c, params) - E) <= 1e-12 * abs(E), (surface.energy(c, params), E)
    steps = np.eye(basis.size)[basis.free] * h
    R = surface.residual(c, params)
    differences = np.array([(energy(c + e) - energy(c - e)) / (2 * h) for e in steps])
    assert np.max(np.abs(R[basis.free] - differences)) <= 1e-7 * np.max(np.abs(R))
    H = surface.hessian(c, params)
    assert np.max(np.abs(H - H.T)) <= 1e-12 * np.max(np.abs(H))
    columns = np.array([(surface.residual(c + e, params) - surface.residual(c - e, params)) / (2 * h) for e in steps])
    assert np.max(np.abs(H[:, basis.free] - columns.T)) <= 1e-7 * np.max(np.abs(H))


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("ends", ("sliding", "plugged"))
def test_axisymmetric_in_a_field_it_is_the_interval_discretisation(case, ends):
    """At a random axisymmetric state in the same field and voltage: E/(2π), the residual and the Jacobian on the
    order-0 unknowns are the interval discretisation's (its kernels, H² in (ρ, η); 1e-12 relative); the orders do
    not couple and the order-m block (m = 1, 2) is tube/azimuthal.hessian's (1e-12)."""
    scene, disc = charged_scene(case, ends, degree=16)
    params = scene_parameters(scene, 0.9)
    eq = Equilibrium(scene, disc)
    basis = TubeSurfaceBasis(disc, (0, 1, 2))
    surface = MeridianSurfaceEquilibrium(scene, basis)
    u = random_state(disc, seed=4)
    c = basis.axisymmetric(u)
    axis = basis.block(0)

    def close(a, b):
        return np.max(np.abs(np.asarray(a) - b)) <= 1e-12 * max(np.max(np.abs(b)), 1.0)

    assert close(surface.energy(c, params), eq.energy(u, params))
    R = surface.residual(c, params)
    assert close(R[axis], eq.residual(u, params))
    assert np.max(np.abs(R[axis.stop:])) <= 1e-12 * np.max(np.abs(R))
    H = surface.hessian(c, params)
    assert close(H[axis, axis], eq.jacobian(u, params))
    for m in (1, 2):
        assert np.max(np.abs(H[axis, basis.block(m)])) <= 1e-12 * np.max(np.abs(H))
        assert close(H[basis.block(m), basis.block(m)], azimuthal.hessian(eq, u, params, m)), m
    assert np.max(np.abs(H[basis.block(1), basis.block(2)])) <= 1e-12 * np.max(np.abs(H))


@pytest.fixture(scope="module")
def m2_zero():
    """(scene, the primary branch, its first located m = 2 zero above P = 0.5) of SPOM1's coil scene at M = 0.03
    (degree 30; the zeros near P = 0 are the slack reference state's)."""
    from pathlib import Path

    from balloon_cg.scene import load_scene
    from balloon_cg.tube.azimuthal_crossings import crossings
    from balloon_cg.tube.primary import primary_branch

    scene = load_scene(Path(__file__).resolve().parents[1] / "scenes" / "tube_spom1_L10_coil.toml").with_overrides(
        {"field.M": 0.03, "solver.degree": 30, "stability.m_max": 2, "continuation.stop_stretch": 5.0,
         "continuation.max_points": 300})
    branch = primary_branch(scene)
    eq = Equilibrium(scene, branch.disc)
    modes = azimuthal.branch_modes(eq, np.column_stack([branch.states, branch.pressure]), branch.params, 2)
    found = [c for c in crossings(scene, branch, modes) if c.m == 2 and c.pressure > 0.5]
    assert found, "no located m = 2 zero"
    return scene, branch, found[0]


def test_an_m2_zero_is_switched_to_an_equilibrium_of_the_written_energy(m2_zero):
    """At the located m = 2 zero the lowest eigenvalue of the surface Hessian's order-2 block (orders 0, 2, 4: the
    branch's dihedral sector, tube/surface/switching.py) on the Gram matrix is 0 (1e-9 of the block's scale), of
    opposite signs at the branch's points on either side; the switched point at ε = 0.05 (and ±0.025, 0.0125)
    converges (residual ≤ 1e-12 of P ∂Ṽ/∂c), its amplitude is ε, no gauge in the field; it is stationary for the
    energy written here (field included: central differences along 8 random directions ≤ 1e-9 of P ∂Ṽ/∂c, the
    predictor's ≥ 1e-6); a pitchfork: P(−ε) = P(ε) (the rotation by π/2 maps c_2 to −c_2; 1e-12) and (P − P_0)/ε²
    converging as ε² (ratio of successive changes 4 ± 0.3). The default n_phi (20: a multiple of 2m) keeps the
    rotation exact on the nodes."""
    from balloon_cg.tube.surface.switching import switched_point

    scene, branch, zero = m2_zero
    disc = branch.disc
    basis = TubeSurfaceBasis(disc, (0, 2, 4))
    surface = MeridianSurfaceEquilibrium(scene, basis)
    factor = GramFactor(azimuthal.operators(disc)[1])

    def lowest(u, P):
        block = surface.hessian(basis.axisymmetric(u), branch.params.with_value("P", P))[basis.block(2), basis.block(2)]
        A = restricted(block, factor, NO_CONSTRAINT)
        return np.linalg.eigvalsh(A)[0], np.max(np.abs(A))

    value, scale = lowest(zero.u, zero.pressure)
    assert abs(value) <= 1e-9 * scale, (value, scale)
    before = lowest(branch.states[zero.index], branch.pressure[zero.index])[0]
    after = lowest(branch.states[zero.index + 1], branch.pressure[zero.index + 1])[0]
    assert before * after < 0, (before, after)

    points = {eps: switched_point(scene, disc, zero, eps, branch.params) for eps in (0.05, 0.025, -0.025, 0.0125)}
    start = basis.with_mode(basis.axisymmetric(zero.u), 2, 0.05 * zero.mode)
    pressure_scale = zero.pressure * np.max(np.abs(surface.parameter_derivative(start, branch.params)))
    gram = azimuthal.operators(disc)[1]
    for eps, point in points.items():
        assert point.converged and point.basis.orders == (0, 2, 4), (eps, point.message)
        assert point.residual <= 1e-12 * pressure_scale, (eps, point.residual)
        assert abs(zero.mode @ gram @ point.c[basis.block(2)] - eps) <= 1e-12 and point.reaction == 0.0
    h = 1e-6
    directions = np.zeros((8, basis.size))
    directions[:, basis.free] = np.random.default_rng(2).standard_normal((8, basis.free.size))
    steps = h * directions / np.linalg.norm(directions, axis=1)[:, None]

    def gradient(c, P):
        params = branch.params.with_value("P", P)
        return np.array([(written_total(scene, disc, basis.orders, basis.n_phi, c + e, params)
                          - written_total(scene, disc, basis.orders, basis.n_phi, c - e, params)) / (2 * h)
                         for e in steps])

    stationary = np.max(np.abs(gradient(points[0.05].c, points[0.05].pressure)))
    predicted = np.max(np.abs(gradient(start, zero.pressure)))
    assert stationary <= 1e-9 * pressure_scale and predicted >= 1e-6 * pressure_scale, (stationary, predicted)
    assert abs(points[-0.025].pressure - points[0.025].pressure) <= 1e-12 * zero.pressure
    quotient = {eps: (points[eps].pressure - zero.pressure) / eps**2 for eps in (0.05, 0.025, 0.0125)}
    ratio = (quotient[0.05] - quotient[0.025]) / (quotient[0.025] - quotient[0.0125])
    assert abs(ratio - 4) <= 0.3, (quotient, ratio)

