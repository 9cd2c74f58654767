"""The m ≥ 1 natural frequencies of a capsule (balloon_cg.dynamics on analysis/stability/capsule_basis.py).

A capsule's m ≥ 1 blocks are read on its own basis (two caps and the cylinder's elements, C⁰ joined, orthonormal
under ‖δx‖² = ½ ∫ (R² + T² + Z²) S' R dθ), whose Gram matrix is the membrane's kinetic energy per 2π over the
reference capsule: the mass matrix M of K q = ν M q, Ω² = ν/2 (dynamics/pencil.py). Checked here against

- the kinetic energy (1/2π) ∫∫ |δx|² dA of the Cartesian displacement, integrated by Gauss–Legendre in the
  arclength S piece by piece (caps R = sin S, cylinder R = 1) and on a φ grid;
- the closed form of the uniformly inflated sphere's spheroidal modes of degree n (tests/test_dynamics.py:
  ``spheroidal``, derived there from the strain energy): a capsule of length 0 at the exact sphere has both Ω² of
  every degree n in each block m = 1..n;
- the located m = 1 branch points of a capsule of length 3 (the held m = 1 stability's zeros, Brent + corrector):
  one Ω² of the m1_held block vanishes there;
- the rigid translation across the axis: a zero mode without a field (Ω² = 0 at any state).
"""
import h5py
import numpy as np
import pytest
from numpy.polynomial import legendre

import balloon_cg as bc
from balloon_cg.analysis.results import Kind
from balloon_cg.analysis.stability.azimuthal import azimuthal_hessian
from balloon_cg.analysis.stability.capsule_basis import capsule_basis
from balloon_cg.app.cli import main
from balloon_cg.dynamics.frequencies import frequencies
from balloon_cg.dynamics.modes import block_modes
from balloon_cg.dynamics.pencil import mass_variation
from balloon_cg.dynamics.translation import translation_omega2
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.model import meridian
from balloon_cg.scene import parse_scene
from test_capsule_azimuthal import random_state
from test_dynamics import MATERIALS, located_zeros, pressure, spheroidal

CAPSULE = ('[material]\npreset = "{preset}"\n[geometry]\nshape = "capsule"\nlength = {length}\n[stability]\n'
           'm_max = 1\n[dynamics]\nfrequencies = true\ncount = 4\nm_max = 1\nmodes = true\n[continuation]\n'
           'stop_stretch = {stop}\n')


def capsule(length, preset="SPOM1", stop=3.0):
    return parse_scene(CAPSULE.format(preset=preset, length=length, stop=stop))


def arclength_pieces(length):
    """(S from, S to, R(S)) of the north cap, the cylinder and the south cap of the reference capsule."""
    return [(0.0, np.pi / 2, np.sin), (np.pi / 2, np.pi / 2 + length, np.ones_like),
            (np.pi / 2 + length, np.pi + length, lambda S: np.sin(np.pi + length - S))]


def kinetic_energy(basis, c, length, n=80, n_phi=24):
    """(1/2π) ∫∫ |δx|² dA of δx = R cos mφ e_ρ + T sin mφ e_φ + Z cos mφ e_z (``basis.displacement`` at θ = S/κ),
    dA = R(S) dS dφ, by Gauss–Legendre in S on each piece and the mean over a φ grid (the integrand is a
    trigonometric polynomial of degree 2m in φ: exact)."""
    kappa, (t, w) = 1 + length / np.pi, legendre.leggauss(n)
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    m = basis.m
    total = 0.0
    for low, high, radius in arclength_pieces(length):
        S = low + (high - low) * (t + 1) / 2
        R, Z, T = basis.displacement(c, S / kappa)
        rho, azimuth, z = (R[:, None] * np.cos(m * phi), T[:, None] * np.sin(m * phi), Z[:, None] * np.cos(m * phi))
        cartesian = np.array([rho * np.cos(phi) - azimuth * np.sin(phi), rho * np.sin(phi) + azimuth * np.cos(phi), z])
        total += (high - low) / 2 * w @ (radius(S) * np.mean(np.sum(cartesian**2, axis=0), axis=1))
    return total


@pytest.mark.parametrize("m", [1, 2, 3])
def test_capsule_m_ge_1_mass_matrix_is_the_kinetic_energy_over_the_reference_capsule(m):
    """Length 2, degree 12: cᵀ M c = (1/2π) ∫∫ |δx|² dA (``kinetic_energy``) for random coefficients c, to 1e-12;
    the displacement drawn on any θ grid is the basis's values at its own nodes."""
    rng = np.random.default_rng(40 + m)
    length = 2.0
    basis = capsule_basis(m, 12, capsule(length).geometry)
    for _ in range(3):
        c = rng.standard_normal(basis.size)
        assert c @ basis.gram @ c == pytest.approx(kinetic_energy(basis, c, length), rel=1e-12)
    assert np.abs(basis.displacement(c, basis.theta) - basis.values(c)[[0, 2, 4]]).max() <= 1e-12


@pytest.mark.parametrize("name", list(MATERIALS))
@pytest.mark.parametrize("lam", [1.3, 2.5])
def test_capsule_of_length_zero_at_the_sphere_has_the_spheroidal_closed_form_in_every_m_block(name, lam):
    """The exact sphere λ2 = λ, η = λ cos θ (P its pressure) on a capsule of length 0, degree 14: both spheroidal
    Ω² of every degree n = 2..5 appear in every block m1_held..m<n>_held to 1e-9 (the sphere's degeneracy in m)."""
    degree = 14
    scene = capsule(0.0, preset=name)
    disc = Discretisation(degree, symmetric=False, pin_translation=False, joins=meridian.joins(scene.geometry))
    a, b = np.zeros(degree + 1), np.zeros(degree + 1)
    a[0], b[1] = lam, lam
    P = float(pressure(name, lam)[0])
    blocks = frequencies(mass_variation(Equilibrium(scene, disc), degree), disc.join(a, b), Parameters(P), True,
                         m_max=5, count=16)
    for n in range(2, 6):
        for value in spheroidal(name, lam, P, n):
            found = [blocks[f"m{m}_held"][np.argmin(abs(blocks[f"m{m}_held"] - value))] for m in range(1, n + 1)]
            assert np.allclose(found, value, rtol=1e-9, atol=1e-9), (n, value, found)


@pytest.mark.parametrize("length", [0.0, 2.0])
def test_capsule_lateral_translation_is_a_zero_mode_without_a_field(length):
    """M = 0: the translation across the axis costs no energy at any state (here a random smooth one, not an
    equilibrium): its Ω² is zero to 1e-10 (the axial one's too); the translation is in the m = 1 basis exactly."""
    scene = capsule(length)
    disc = Discretisation(24, symmetric=False, pin_translation=False, joins=meridian.joins(scene.geometry))
    u = random_state(disc, scene.geometry, 1.3, seed=7)
    rigid = translation_omega2(mass_variation(Equilibrium(scene, disc), 30), u, Parameters(1.1))
    assert abs(rigid["lateral"]) <= 1e-10 and abs(rigid["axial"]) <= 1e-10, rigid


def test_capsule_of_length_zero_has_the_sphere_lateral_translation_in_a_coil_field():
    """A coaxial coil of radius 3 at the equator, M = 0.05, at a random smooth state (degree 24, P = 1.1): the
    lateral translation's Ω² of the capsule of length 0 (its m = 1 basis of two hemispheres, its Gram matrix the
    mass) is the sphere's (the m = 1 mass and Hessian kernels at the nodes of its basis) to 1e-10, and not zero."""
    coil = '[field]\nM = 0.05\n[[field.coils]]\nradius = 3.0\nheight = 0.0\ncurrent = 1.0\n'
    found = []
    for geometry in ("", '[geometry]\nshape = "capsule"\nlength = 0.0\n'):
        scene = parse_scene('[material]\npreset = "SPOM1"\n' + geometry + coil)
        disc = Discretisation(24, symmetric=False, pin_translation=False)
        u = random_state(disc, scene.geometry, 1.3, seed=8)
        found.append(translation_omega2(mass_variation(Equilibrium(scene, disc), 30), u, Parameters(1.1, M=0.05))["lateral"])
    assert abs(found[0]) > 1e-4 and abs(found[1] - found[0]) <= 1e-10, found


@pytest.fixture(scope="module")
def capsule_picture():
    """SPOM1 capsule of length 3 to a hoop stretch 3: m = 0 and m = 1 stability and frequencies, with modes."""
    return bc.analyse(capsule(3.0), pear=False).picture


def test_capsule_m1_branch_points_have_a_vanishing_m1_frequency(capsule_picture):
    """Length 3: the two located m = 1 branch points (past the pressure maximum, P ≈ 1.461 and 0.847) have a zero Ω²
    in m1_held to 1e-9, the points around each differing by one negative Ω² there (test_dynamics.located_zeros;
    1e-9 as for the m = 0 points of test_dynamics_shapes: the located points' arclength is resolved to ~1e-10)."""
    kinds = located_zeros(capsule_picture, zero=1e-9)
    branch = capsule_picture.branches[0]
    m1 = [s for s in branch.special if s.kind == Kind.BP and s.block.value == "m1_held"]
    assert len(m1) == 2 and kinds.count(Kind.BP) >= 3, kinds


def test_capsule_m1_modes_have_unit_modal_mass_and_their_frequencies(capsule_picture):
    """The stored m1_held mode shapes of every special point: ½ ∫ (R² + Z² + T²) R dS = 1 by Gauss–Legendre in S
    piece by piece (the modes redrawn on those nodes by block_modes), to 1e-10, and the same Ω² as stored to
    4 ε‖H‖/2 (two backward-stable eigensolves of one pencil, on the constraints' null space and on the reduced
    standard matrix; at the assessed degree 135 ‖H‖₂ ≈ 1.3e6–6.5e6, so ≈ 6e-10: measured ≤ 2.2e-10)."""
    branch = capsule_picture.branches[0]
    length, (t, w) = 3.0, legendre.leggauss(80)
    kappa = 1 + length / np.pi
    pieces = arclength_pieces(length)
    S = np.concatenate([low + (high - low) * (t + 1) / 2 for low, high, _ in pieces])
    weights = np.concatenate([(high - low) / 2 * w * radius(low + (high - low) * (t + 1) / 2)
                              for low, high, radius in pieces])
    degrees = branch.frequencies.degree
    variation_degree = {}
    for n, s in enumerate(branch.special):
        N = int(degrees[s.index:s.index + 2].max())
        variation = variation_degree.setdefault(N, mass_variation(Equilibrium(branch.scene, branch.disc), N))
        omega2, shapes = block_modes(variation, s.X[:-1], branch.params_at(s.X), branch.disc.symmetric, "m1_held",
                                     4, S / kappa)
        rounding = 2 * np.finfo(float).eps * np.linalg.norm(azimuthal_hessian(
            variation.eq, s.X[:-1], branch.params_at(s.X), 1, N)[0], 2)
        assert np.abs(omega2 - branch.frequencies.special["m1_held"][n]).max() <= rounding
        assert 0.5 * np.sum(shapes**2, axis=1) @ weights == pytest.approx(np.ones(len(shapes)), rel=1e-10)
    assert branch.frequencies.modes["m1_held"].shape[:3] == (len(branch.special), 4, 3)


def test_capsule_run_stores_its_m1_frequencies_and_lateral_translation(tmp_path):
    """``run --primary-only`` of a capsule (length 3, to a hoop stretch 1.6: before its m = 1 points) with m_max = 1:
    the file holds m1_held's Ω² and mode shapes, and the lateral translation's Ω², zero without a field (1e-10)."""
    scene_file = tmp_path / "capsule.toml"
    scene_file.write_text(CAPSULE.format(preset="SPOM1", length=3.0, stop=1.6))
    path = tmp_path / "capsule.h5"
    assert main(["run", str(scene_file), "-o", str(path), "--quiet", "--primary-only"]) == 0
    with h5py.File(path) as f:
        group = f["branches/primary/frequencies"]
        assert group.attrs["m_max"] == 1 and np.isfinite(group["omega2_m1_held"][()]).all()
        assert "modes_m1_held" in group
        assert np.abs(group["translation_lateral"][()]).max() <= 1e-10
