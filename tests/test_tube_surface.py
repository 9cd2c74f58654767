"""The tube over (S, φ) (tube/surface/): Legendre(S) × Fourier(φ), its energy, residual and exact Jacobian.

Checked against the interval discretisation (its m = 0 restriction), against the existing m ≥ 1 blocks
(tube/azimuthal.py) and their located zeros, and against an energy written here from the strain energy alone: the
deformed point from the coefficients by numpy's Legendre series, in Cartesian components, the principal stretches
from the metric's eigenvalues, Ogden's Φ, the pressure's work over the volume between the end planes
½ x_h · (x_S × x_φ), Gauss–Legendre in S and the trapezoid in φ."""
import numpy as np
import pytest

from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.galerkin.interval import IntervalDiscretisation
from balloon_cg.numerics.eigen import GramFactor, restricted
from balloon_cg.scene import parse_scene
from balloon_cg.tube import azimuthal
from balloon_cg.tube.surface.basis import TubeSurfaceBasis
from balloon_cg.tube.surface.equilibrium import TubeSurfaceEquilibrium

ENDS = ("sliding", "plugged", "held")


def tube_scene(preset="SPOM1", length=10.0, extra=""):
    return parse_scene(f'[material]\npreset = "{preset}"\n[geometry]\nshape = "tube"\nlength = {length}\n{extra}')


def scene_and_disc(ends, degree=16, length=10.0, preset="SPOM1"):
    extra = 'ends = "sliding"\naxial_stretch = 1.3\n' if ends == "held" else f'ends = "{ends}"\n'
    scene = tube_scene(preset, length, extra)
    disc = IntervalDiscretisation(degree, length, ends=scene.geometry.ends, axial_stretch=scene.geometry.axial_stretch)
    return scene, disc


def random_state(disc, seed=3, size=0.05):
    return disc.reference() + size * np.random.default_rng(seed).standard_normal(disc.size)


@pytest.mark.parametrize("ends", ENDS)
def test_restricted_to_m0_it_is_the_interval_discretisation(ends):
    """At a random axisymmetric state (orders 0, 1, 2): E/(2π), V/(2π), the residual, ∂R/∂P and the Jacobian on the
    m = 0 unknowns are the interval discretisation's (1e-12 relative); the m ≥ 1 residual vanishes (∫ cos mφ = 0)
    and the Hessian couples no two orders (the trapezoid exact for cos mφ cos m'φ, n_phi > m + m')."""
    scene, disc = scene_and_disc(ends)
    eq, params = Equilibrium(scene, disc), Parameters(0.9)
    basis = TubeSurfaceBasis(disc, (0, 1, 2))
    surface = TubeSurfaceEquilibrium(scene, basis)
    u = random_state(disc)
    c = basis.axisymmetric(u)
    axis = basis.block(0)

    def close(a, b):
        return np.max(np.abs(np.asarray(a) - b)) <= 1e-12 * max(np.max(np.abs(b)), 1.0)

    assert close(surface.energy(c, params), eq.energy(u, params))
    assert close(surface.volume(c), eq.volume(u))
    R = surface.residual(c, params)
    assert close(R[axis], eq.residual(u, params))
    assert np.max(np.abs(R[axis.stop:])) <= 1e-12 * np.max(np.abs(R))
    assert close(surface.parameter_derivative(c, params)[axis], eq.parameter_derivative(u, params, "P"))
    H = surface.hessian(c, params)
    assert close(H[axis, axis], eq.jacobian(u, params))
    for m in (1, 2):
        assert np.max(np.abs(H[axis, basis.block(m)])) <= 1e-12 * np.max(np.abs(H))
    assert np.max(np.abs(H[basis.block(1), basis.block(2)])) <= 1e-12 * np.max(np.abs(H))


@pytest.mark.parametrize("ends", ENDS)
def test_order_m_blocks_are_the_azimuthal_blocks(ends):
    """At a random axisymmetric state the Hessian's order-m block (m = 1, 2, 3) is tube/azimuthal.hessian (1e-12
    relative) and its eigenvalues on the Gram matrix, the zero modes removed as there, are the block's (1e-10)."""
    scene, disc = scene_and_disc(ends)
    eq, params = Equilibrium(scene, disc), Parameters(0.9)
    basis = TubeSurfaceBasis(disc, (0, 1, 2, 3))
    surface = TubeSurfaceEquilibrium(scene, basis)
    u = random_state(disc, seed=5)
    H = surface.hessian(basis.axisymmetric(u), params)
    factor = GramFactor(azimuthal.operators(disc)[1])
    for m in (1, 2, 3):
        block = H[basis.block(m), basis.block(m)]
        expected = azimuthal.hessian(eq, u, params, m)
        assert np.max(np.abs(block - expected)) <= 1e-12 * np.max(np.abs(expected)), m
        ours = np.linalg.eigvalsh(restricted(block, factor, azimuthal.zero_modes(eq, params, m)))
        theirs = np.linalg.eigvalsh(azimuthal.block(eq, u, params, m))
        assert np.max(np.abs(ours - theirs)) <= 1e-10 * max(1.0, np.max(np.abs(theirs))), m


def located_zeros(case):
    """(scene, branch, its located m = 1 zeros (tube/azimuthal_crossings.py)) of a held neo-Hookean tube's uniform
    branch (λz = 1.5, degree 16: its sideways buckle) or of SPOM1's bulge branch (L = 10, degree 20, to V/V0 = 5: the
    lateral buckle of the bulge, a non-uniform state)."""
    from balloon_cg.galerkin.interval import Mirror
    from balloon_cg.tube.azimuthal_crossings import crossings
    from balloon_cg.tube.bulge import bulge_branch
    from balloon_cg.tube.primary import primary_branch

    if case == "held":
        scene = tube_scene("neo-Hookean", 10.0, "axial_stretch = 1.5\n").with_overrides(
            {"solver.degree": 16, "continuation.stop_stretch": 2.3})
        branch = primary_branch(scene)
    else:
        scene = tube_scene("SPOM1", 10.0).with_overrides({"solver.degree": 20, "continuation.stop_stretch": 5.0})
        primary = primary_branch(scene)
        branch = bulge_branch(scene, primary, primary.branch_points(Mirror.ODD)[0], stop_volume=5.0)
    eq = Equilibrium(scene, branch.disc)
    modes = azimuthal.branch_modes(eq, np.column_stack([branch.states, branch.pressure]), branch.params, 1)
    return scene, branch, [c for c in crossings(scene, branch, modes) if c.pressure > 0.5]


@pytest.mark.parametrize("case", ["held", "bulge"])
def test_lowest_m1_eigenvalue_vanishes_at_the_located_branch_point(case):
    """At each located m = 1 zero the lowest eigenvalue of the surface Hessian's m = 1 block (orders 0, 1, 2; the
    translation removed on the Gram matrix as tube/azimuthal.py does) is zero (1e-9 of the block's scale: the
    location's own tolerance), and it has opposite signs at the branch's points on either side."""
    scene, branch, found = located_zeros(case)
    assert found, "no located m = 1 zero"
    disc = branch.disc
    eq = Equilibrium(scene, disc)
    basis = TubeSurfaceBasis(disc, (0, 1, 2))
    surface = TubeSurfaceEquilibrium(scene, basis)
    factor = GramFactor(azimuthal.operators(disc)[1])

    def lowest(u, P):
        params = branch.params.with_value("P", P)
        block = surface.hessian(basis.axisymmetric(u), params)[basis.block(1), basis.block(1)]
        A = restricted(block, factor, azimuthal.zero_modes(eq, params, 1))
        return np.linalg.eigvalsh(A)[0], np.max(np.abs(A))

    for zero in found:
        value, scale = lowest(zero.u, zero.pressure)
        assert abs(value) <= 1e-9 * scale, (zero.pressure, value, scale)
        before = lowest(branch.states[zero.index], branch.pressure[zero.index])[0]
        after = lowest(branch.states[zero.index + 1], branch.pressure[zero.index + 1])[0]
        assert before * after < 0, (before, after)
