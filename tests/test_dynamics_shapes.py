"""Natural frequencies on a spheroid and a capsule (balloon_cg.dynamics, codegen/inertia.py, model/meridian.py:
mass_density).

The kinetic energy is ½ ρ T0 ∫ |u̇|² dA over the reference surface, dA = R dS dφ (S its arclength). On the spheroid
R = sin θ, Z = aspect · cos θ, dS = S' dθ, S' = sqrt(R'² + Z'²) = sqrt(cos²θ + aspect² sin²θ); on the capsule of
length L (hemispherical caps of radius 1 on a cylinder of radius 1) R = sin S on the north cap S ∈ [0, π/2], 1 on
the cylinder, sin(π + L − S) on the south cap, the Legendre variable x = cos(S/κ), κ = 1 + L/π. The mass matrix is
checked here against that integral by quadrature in θ or in S piece by piece (not in cos θ, as the runtime
assembles it), and the frequencies against the sphere's (aspect 1, length 0) and against the located stability
changes (aspect ≠ 1, length > 0).
"""
import h5py
import numpy as np
import pytest
from numpy.polynomial import legendre

import balloon_cg as bc
from balloon_cg.analysis.stability import azimuthal as az
from balloon_cg.analysis.results import Kind
from balloon_cg.app.cli import main
from balloon_cg.dynamics.pencil import mass_variation
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.model import meridian
from balloon_cg.scene import Shape, load_scene, parse_scene
from balloon_cg.scene.tables import Geometry
from test_dynamics import located_zeros

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
    δx = sin θ δλ2 e_ρ + δη e_z (ρ = λ2 R, R = sin θ; δλ2 = Σ a_k P_k, and δη = b_0 + Σ_k≥1 b_k (P_k − m_k), the held
    functions with m_k = ∫P_k dA/A, the reference's centroid: tests/test_spheroid_held.py), m = 1, 2, 3 from the
    Cartesian displacement (AzimuthalBasis.cartesian) on a θ × φ grid; and the sphere's mass matrix is not it (by
    more than 1 %)."""
    rng = np.random.default_rng(39)
    scene = spheroid(ASPECT)
    variation = mass_variation(Equilibrium(scene, Discretisation(10, symmetric=False, pin_translation=False)), 12)
    theta, weights = area_rule(ASPECT)
    x = np.cos(theta)
    means = weights @ legendre.legvander(x, 12)[:, 1:] / weights.sum()
    for _ in range(3):
        c = rng.standard_normal(variation.basis.size)
        a, b = variation.basis.split(c)
        eta = legendre.legval(x, b) - means @ b[1:]
        direct = weights @ ((np.sin(theta) * legendre.legval(x, a)) ** 2 + eta ** 2)
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
    """Aspect 1.4: at every located fold and branch point (the LP, the pear and m = 1 BPs) one stored Ω² of its
    block is zero to the solver's tolerance, the points around it differing by one in its negative Ω²
    (test_dynamics.located_zeros)."""
    kinds = located_zeros(spheroid_picture)
    assert Kind.LP in kinds and kinds.count(Kind.BP) >= 2, kinds


def test_spheroid_free_balloon_translations_are_zero_frequencies(spheroid_picture):
    """Without a field the rigid translations of the spheroid are zero modes at every point (to 1e-10)."""
    branch = spheroid_picture.branches[0]
    for direction, omega2 in branch.frequencies.translation.items():
        assert np.abs(omega2).max() <= 1e-10, direction


CAPSULE = ('[material]\npreset = "SPOM1"\n[geometry]\nshape = "capsule"\nlength = {length}\n[stability]\nm_max = 0\n'
           '[dynamics]\nfrequencies = true\ncount = 4\nm_max = 0\n[continuation]\nstop_stretch = {stop}\n')


def capsule_scene(length, stop=3.0):
    return parse_scene(CAPSULE.format(length=length, stop=stop))


def test_capsule_mass_matrix_is_the_kinetic_energy_over_the_reference_capsule():
    """Length 2: cᵀ M c = (1/2π) ∫∫ |δx|² dA = ∫ (R² δλ2² + δη²) R dS for random coefficients c, by Gauss–Legendre
    in S on each cap and on the cylinder (δλ2, δη the basis's series at θ = S/κ: the capsule's piecewise basis,
    galerkin/elements.py; δη on the held functions φ_k − m_k, k ≥ 1, m_k = ∫φ_k dA/A by the same rule, A/2π = 2 + L),
    to 1e-12."""
    rng = np.random.default_rng(38)
    length = 2.0
    scene = capsule_scene(length)
    joins = meridian.joins(scene.geometry)
    variation = mass_variation(Equilibrium(scene, Discretisation(10, symmetric=False, pin_translation=False,
                                                                 joins=joins)), 12)
    kappa, t, w = 1 + length / np.pi, *legendre.leggauss(80)
    pieces = [(0.0, np.pi / 2, np.sin), (np.pi / 2, np.pi / 2 + length, np.ones_like),
              (np.pi / 2 + length, np.pi + length, lambda S: np.sin(np.pi + length - S))]
    nodes = [(lo + (hi - lo) * (t + 1) / 2, (hi - lo) / 2 * w, radius) for lo, hi, radius in pieces]
    na = variation.basis.a_index.size
    # the held η functions φ_k − m_k, m_k = ∫φ_k dA/A (the reference's centroid: tests/test_capsule_held.py)
    unit_eta = [variation.basis.evaluate(np.eye(variation.basis.size)[na + 1:], S / kappa)[2] for S, _, _ in nodes]
    means = sum(e @ (W * radius(S)) for e, (S, W, radius) in zip(unit_eta, nodes)) / (2.0 + length)
    for _ in range(3):
        c = rng.standard_normal(variation.basis.size)
        direct = 0.0
        for S, W, radius in nodes:
            lam2, _, eta, _ = variation.basis.evaluate(c, S / kappa)
            eta = eta - means @ c[na + 1:]
            direct += W @ ((radius(S)**2 * lam2**2 + eta**2) * radius(S))
        assert c @ variation.gram @ c == pytest.approx(direct, rel=1e-12)


def test_capsule_of_length_zero_has_the_sphere_frequencies():
    """SPOM1 to a pole stretch 3, m = 0: every block's Ω² at every point and special point and both rigid
    translations' are the sphere's to 1e-10 (another kernel module: R = sin(κ acos(cos θ)), S' = κ = 1; the lateral
    one on the capsule's m = 1 basis of two hemispheres against the sphere's m = 1 mass kernel)."""
    sphere = load_scene("spom1").with_overrides({"stability.m_max": 0, "dynamics.frequencies": True,
                                                 "dynamics.count": 4, "dynamics.m_max": 0,
                                                 "continuation.stop_stretch": 3.0})
    one, other = (bc.analyse(scene, pear=False).picture.branches[0].frequencies
                  for scene in (sphere, capsule_scene(0.0)))
    assert set(one.omega2) == set(other.omega2) and {"even", "even_volume", "odd_held"} <= set(one.omega2)
    for name in one.omega2:
        assert np.allclose(one.omega2[name], other.omega2[name], rtol=0, atol=1e-10, equal_nan=True), name
        assert np.allclose(one.special[name], other.special[name], rtol=0, atol=1e-10, equal_nan=True), name
    for direction in one.translation:
        assert np.abs(one.translation[direction] - other.translation[direction]).max() <= 1e-10


def test_capsule_located_points_have_a_vanishing_frequency_in_their_block():
    """Length 3 to a hoop stretch 3: at the located LP and equator-breaking BP one stored Ω² of its block is zero
    to 1e-9, the points around it differing by one in its negative Ω² (located_zeros). Not to solver.tol as on the
    sphere: the branch is refined to degree 135 (max_error), where the points are located to ~1e-10 in the
    arclength and the LP's Ω² changes by 2.9 per unit arclength (measured 4.0e-11 at the LP, 2.7e-12 at the BP;
    the bracketing points' are 4e-4 to 1e-1)."""
    kinds = located_zeros(bc.analyse(capsule_scene(3.0), pear=False).picture, zero=1e-9)
    assert Kind.LP in kinds and Kind.BP in kinds, kinds


def test_capsule_run_stores_its_frequencies_and_inspect_reads_them(tmp_path, capsys):
    """``run --primary-only`` of a capsule (length 3) with [dynamics] frequencies and m_max = 0: the file holds every
    m = 0 block's Ω² of the analysis and both rigid translations' (zero without a field); ``inspect`` and ``bc.load``
    read it."""
    scene_file = tmp_path / "capsule.toml"
    scene_file.write_text(CAPSULE.format(length=3.0, stop=2.0))
    path = tmp_path / "capsule.h5"
    assert main(["run", str(scene_file), "-o", str(path), "--quiet", "--primary-only"]) == 0
    expected = bc.analyse(capsule_scene(3.0, 2.0), pear=False).picture.branches[0].frequencies
    stored = bc.load(path).branches["primary"].data["frequencies"]
    assert np.array_equal(stored["even"], expected.omega2["even"], equal_nan=True)
    with h5py.File(path) as f:
        assert np.abs(f["branches/primary/frequencies/translation_lateral"][()]).max() <= 1e-10
        assert np.abs(f["branches/primary/frequencies/translation_axial"][()]).max() <= 1e-12
    assert main(["inspect", str(path)]) == 0
    assert "lowest Ω²" in capsys.readouterr().out
