"""Natural frequencies on a spheroid (balloon_cg.dynamics, codegen/inertia.py, model/meridian.py: mass_density).

The kinetic energy is ½ ρ T0 ∫ |u̇|² dA over the reference spheroid R = sin θ, Z = aspect · cos θ, whose area
element is dA = R S' dθ dφ, S' = sqrt(R'² + Z'²) = sqrt(cos²θ + aspect² sin²θ). The mass matrix is checked here
against that integral by quadrature in θ (not in cos θ, as the runtime assembles it), and the frequencies against
the sphere's (aspect 1) and against the located stability changes of a spheroid (aspect ≠ 1).
"""
import numpy as np
import pytest
from numpy.polynomial import legendre

from balloon_cg.analysis import azimuthal as az
import balloon_cg as bc
from balloon_cg.analysis.results import Status
from balloon_cg.dynamics.frequencies import matching_block
from balloon_cg.dynamics.pencil import mass_variation
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.scene import Shape, load_scene
from balloon_cg.scene.tables import Geometry

ASPECT = 1.4
DYNAMICS = {"dynamics.frequencies": True, "dynamics.count": 4, "dynamics.m_max": 2, "stability.m_max": 2}


def spheroid(aspect, **overrides):
    return load_scene("spom1").with_overrides({"geometry.shape": "spheroid", "geometry.aspect": aspect,
                                               **overrides})


def area_rule(aspect, n=200):
    """θ nodes and the weights of (1/2π) ∫∫ f dA = ∫_0^π f sin θ S'(θ) dθ (Gauss–Legendre in θ), S' from the
    meridian's derivatives R' = cos θ, Z' = −aspect sin θ."""
    t, w = legendre.leggauss(n)
    theta = np.pi * (t + 1) / 2
    return theta, w * np.pi / 2 * np.sin(theta) * np.hypot(np.cos(theta), -aspect * np.sin(theta))


def test_spheroid_mass_matrices_are_the_kinetic_energy_over_the_reference_spheroid():
    """cᵀ M c = (1/2π) ∫∫ |δx|² dA over the spheroid of aspect 1.4 for random coefficients c: m = 0 from
    δx = sin θ δλ2 e_ρ + δη e_z (ρ = λ2 R, R = sin θ), m = 1, 2, 3 from the Cartesian displacement
    (AzimuthalBasis.cartesian) on a θ × φ grid; and the sphere's mass matrix is not it (by more than 1 %)."""
    rng = np.random.default_rng(39)
    scene = spheroid(ASPECT)
    variation = mass_variation(Equilibrium(scene, Discretisation(10, symmetric=False, pin_translation=False)), 12)
    theta, weights = area_rule(ASPECT)
    x = np.cos(theta)
    for _ in range(3):
        c = rng.standard_normal(variation.basis.size)
        a, b = variation.basis.split(c)
        direct = weights @ ((np.sin(theta) * legendre.legval(x, a)) ** 2 + legendre.legval(x, b) ** 2)
        assert c @ variation.gram @ c == pytest.approx(direct, rel=1e-12)
    sphere = mass_variation(Equilibrium(load_scene("spom1"), Discretisation(10, symmetric=False,
                                                                             pin_translation=False)), 12)
    assert abs(c @ sphere.gram @ c / direct - 1) > 1e-2
    phi = 2 * np.pi * np.arange(24) / 24
    for m in (1, 2, 3):
        basis = az.AzimuthalBasis(m, 12, 40, geometry=Geometry(Shape.SPHEROID, ASPECT))
        c = rng.standard_normal(basis.size)
        dx = basis.cartesian(c, np.repeat(theta, phi.size), np.tile(phi, theta.size)).reshape(3, theta.size, phi.size)
        direct = weights @ np.mean(np.sum(dx**2, axis=0), axis=1)
        assert c @ basis.gram @ c == pytest.approx(direct, rel=1e-12)


@pytest.fixture(scope="module")
def spheroid_picture():
    """SPOM1 spheroid of aspect 1.4 at M = 0 to a pole stretch 3.5, frequencies of m = 0, 1, 2."""
    return bc.analyse(spheroid(ASPECT, **DYNAMICS, **{"continuation.stop_stretch": 3.5}), pear=False).picture


def test_spheroid_of_aspect_one_has_the_sphere_frequencies():
    """SPOM1 at M = 0 to a pole stretch 3: every block's Ω² (m = 0, 1, 2) at every point and special point, and
    the rigid translations', of the spheroid of aspect 1 are the sphere's to 1e-10 (another kernel module, another
    mass kernel: the spheroid's S' at aspect 1)."""
    sphere = load_scene("spom1").with_overrides({**DYNAMICS, "continuation.stop_stretch": 3.0})
    one, other = (bc.analyse(scene, pear=False).picture.branches[0].frequencies
                  for scene in (sphere, sphere.with_overrides({"geometry.shape": "spheroid",
                                                               "geometry.aspect": 1.0})))
    assert set(one.omega2) == set(other.omega2) and {"even", "odd_held", "m1_held", "m2_held"} <= set(one.omega2)
    for name in one.omega2:
        assert np.allclose(one.omega2[name], other.omega2[name], rtol=0, atol=1e-10, equal_nan=True), name
        assert np.allclose(one.special[name], other.special[name], rtol=0, atol=1e-10, equal_nan=True), name
    for direction in one.translation:
        assert np.abs(one.translation[direction] - other.translation[direction]).max() <= 1e-10


def test_spheroid_located_points_have_a_vanishing_frequency_in_their_block(spheroid_picture):
    """Aspect 1.4: at every located fold and branch point one stored Ω² of its block (``matching_block``) is zero
    to the solver's tolerance, and the points around it have that block's lowest Ω² of opposite signs."""
    checked = 0
    for branch in spheroid_picture.branches:
        for n, s in enumerate(branch.special):
            block = matching_block(s, branch)
            if block is None or s.status != Status.LOCATED:
                continue
            assert np.nanmin(np.abs(branch.frequencies.special[block][n])) <= branch.scene.solver.tol, (branch.name, s)
            around = branch.frequencies.omega2[block][s.index:s.index + 2, 0]
            assert around[0] * around[1] < 0, (branch.name, s, around)
            checked += 1
    assert checked >= 2, [s.kind for b in spheroid_picture.branches for s in b.special]


def test_spheroid_free_balloon_translations_are_zero_frequencies(spheroid_picture):
    """Without a field the rigid translations of the spheroid are zero modes at every point (to 1e-10)."""
    branch = spheroid_picture.branches[0]
    for direction, omega2 in branch.frequencies.translation.items():
        assert np.abs(omega2).max() <= 1e-10, direction
