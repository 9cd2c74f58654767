"""Natural frequencies of a spheroid's surface branches (surface/stability.py, dynamics/surface.py): the whole-sphere
engine's eigenproblem H c = μ M c with M the kinetic energy over the reference spheroid (``SphericalBasis.mass``),
Ω² = μ/2.

Independent checks. The mass matrix against ½ρ∫∫|u̇|² dA written here: the reference area of the spheroid of
semi-axes (1, 1, c) in closed form, A = 2π(1 + c² artanh(e)/e), e² = 1 − c² (oblate), A = 2π(1 + c arcsin(e)/e),
e² = 1 − 1/c² (prolate), and (1/2π)∫∫|u|² dA for a random field by Gauss–Legendre in θ with the area element
dA = sin θ S'(θ) dθ dφ, S' = √(R'² + Z'²) from the meridian R = sin θ, Z = c cos θ. The frequencies against the
axisymmetric dynamics (analysis/stability, dynamics/frequencies.py: another basis, another discretisation of the
energy, its own mass kernels with S') at an axisymmetric state of the spheroid's primary branch: the whole-sphere
Hessian on the cos mφ family of order m (``stability.azimuthal_spectrum``) gives the block m's Ω², and the sectors
even under the mirror y → −y together hold the blocks even, odd_held and m<m>_held (tests/test_dynamics_surface.py:
the same claim on the sphere).
"""
import numpy as np
import pytest
from numpy.polynomial import legendre
from scipy import linalg

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.surface.branches import trace_surface
from balloon_cg.dynamics.frequencies import attach, frequencies
from balloon_cg.dynamics.surface import sector_block, surface_matching_block
from balloon_cg.dynamics.pencil import PER_EIGENVALUE, mass_variation
from balloon_cg.galerkin.coordinate_map import WireMap
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.numerics import eigen
from balloon_cg.scene import load_scene
from balloon_cg.surface import stability
from balloon_cg.surface.basis import EQUATOR, MIRROR_Y, SphericalBasis
from balloon_cg.surface.embedding import axisymmetric_coefficients, displacement_coefficients
from balloon_cg.surface.equilibrium import SurfaceEquilibrium

ASPECTS = (0.7, 1.6)
COUNT = 6
AXISYMMETRIC_DEGREE = 40  # the axisymmetric blocks' perturbation degree (at 30 their lowest six move by ≤ 2.2e-10)


def reference_area(c: float) -> float:
    """The area of the spheroid of equatorial semi-axis 1 and polar semi-axis c (module docstring)."""
    if c < 1.0:
        e = np.sqrt(1.0 - c * c)
        return 2.0 * np.pi * (1.0 + c * c * np.arctanh(e) / e)
    e = np.sqrt(1.0 - 1.0 / (c * c))
    return 2.0 * np.pi * (1.0 + c * np.arcsin(e) / e)


def area_integral(basis: SphericalBasis, c: np.ndarray, n_theta: int = 200, n_phi: int = 64) -> float:
    """(1/2π)∫∫|u|² dA of the displacement of coefficients c, dA = sin θ S' dθ dφ, by Gauss–Legendre in θ on
    [0, π] and the uniform rule in φ (module docstring)."""
    t, w = legendre.leggauss(n_theta)
    theta = np.pi * (t + 1.0) / 2.0
    weights = w * np.pi / 2.0 * np.sin(theta) * np.hypot(np.cos(theta), -basis.aspect * np.sin(theta))
    phi = 2.0 * np.pi * np.arange(n_phi) / n_phi
    u = basis.grid_values(c, np.cos(theta), phi) - basis.grid_values(np.zeros(basis.size), np.cos(theta), phi)
    return float(weights @ np.mean(np.sum(u * u, axis=0), axis=1))


@pytest.mark.parametrize("aspect", ASPECTS)
def test_mass_matrix_is_the_kinetic_energy_over_the_reference_spheroid(aspect):
    """1ᵀM1: a unit translation along each axis has cᵀMc = A/2π, the closed-form area, to 1e-13 relative (measured
    1.8e-15: the Gauss rule in cos θ integrates S' alone to rounding at the default 22 nodes of degree 12); cᵀMc
    of random coefficients (unmapped and wire-mapped bases) is (1/2π)∫∫|u|² dA by the θ-quadrature here to 1e-12
    relative on 80 θ-nodes (measured ≤ 6.1e-13; at the default 22, 8e-12 unmapped and 9e-8 on the map of width
    0.05: S'·P̃P̃' is analytic but no polynomial, integrated as the Hessian's node functions are); M is symmetric
    positive definite and block-diagonal in the blocks (component, m, t); the sphere's norm c·c/2π is not it (by
    23 to 34 %); at aspect 1, M is gram·I exactly."""
    rng = np.random.default_rng(38)
    basis = SphericalBasis(12, aspect=aspect)
    M = basis.mass()
    for k in range(3):
        field = np.zeros((3, basis.n_theta * basis.n_phi))
        field[k] = 1.0
        t = displacement_coefficients(basis, field)
        assert t @ M @ t == pytest.approx(reference_area(aspect) / (2 * np.pi), rel=1e-13)
    assert np.array_equal(M, M.T) and np.linalg.eigvalsh(M).min() > 0.0
    outside = np.ones_like(M, dtype=bool)
    for b in basis.blocks:
        outside[b.slice, b.slice] = False
    assert not M[outside].any()
    wire = WireMap((0.3,), (0.05,))
    for fine in (SphericalBasis(12, n_theta=80, aspect=aspect),
                 SphericalBasis(12, n_theta=80, mapping=wire, aspect=aspect)):
        c = rng.standard_normal(fine.size) / np.sqrt(fine.size)
        direct = area_integral(fine, c, 400 if fine.mapping is not None else 200)
        assert c @ fine.mass() @ c == pytest.approx(direct, rel=1e-12)
        assert abs(c @ c * fine.gram() / direct - 1.0) > 1e-2
    sphere = SphericalBasis(12, mapping=wire)
    assert np.array_equal(sphere.mass(), sphere.gram() * np.eye(sphere.size))


@pytest.fixture(scope="module", params=ASPECTS)
def axisymmetric_state(request):
    """SPOM1 on a spheroid of ``aspect`` at M = 0: its primary branch to the pole stretch 1.6 and the point in
    its middle (P = 1.8327 at aspect 1.6)."""
    scene = load_scene("spom1").with_overrides({"geometry.shape": "spheroid", "geometry.aspect": request.param,
                                                "continuation.stop_stretch": 1.6, "surface.branches": "none"})
    primary = analyse(scene, pear=False).primary
    X = primary.X[len(primary.X) // 2]
    variation = mass_variation(Equilibrium(scene, primary.disc), AXISYMMETRIC_DEGREE)
    blocks = frequencies(variation, X[:-1], primary.params_at(X), primary.disc.symmetric, 5, 2 * COUNT)
    return primary, X, blocks


def surface_at(primary, X, degree: int, symmetry: tuple, order: int = -1):
    """(SurfaceEquilibrium, coefficients) of the axisymmetric state X on the whole-sphere basis of ``degree``."""
    basis = SphericalBasis(degree, symmetry, order=order, aspect=primary.scene.geometry.aspect)
    return SurfaceEquilibrium(primary.scene, basis), axisymmetric_coefficients(basis, primary.disc, X[:-1])


def test_each_azimuthal_order_has_the_axisymmetric_block_s_frequencies(axisymmetric_state):
    """Per order m = 1, 2, 3 the whole-sphere Hessian on the cos mφ family (held: the translation and the rigid
    rotation removed, M-orthogonally) has the Ω² of the axisymmetric block m<m>_held, the lowest COUNT, to 1e-10.
    Resolution: at degrees 32 and 40 (order 4) the Ω² differ by ≤ 1e-11 (measured ≤ 1.3e-12; at degree 24 the sixth
    Ω² of m = 3 is 8e-10 off at aspect 1.6), the axisymmetric blocks' at perturbation degrees 30 and 40 by
    ≤ 2.2e-10 (so at 40 by less); measured ≤ 2.6e-12 apart. While a spheroid's m = 1 blocks removed a relabelling
    about a horizontal axis (no zero mode there: azimuthal.excluded_modes), m1_held lacked the surface's 1.9987
    (aspect 1.6) and read 2.4651 for 2.4669.
    A second method for the pencil: for m = 2 (no zero modes) scipy's generalised eigh of (EᵀHE, EᵀME) gives the
    same Ω² to 1e-10, and with the sphere's norm (EᵀE/2π) other ones (by more than 1 %)."""
    primary, X, blocks = axisymmetric_state
    params = primary.params_at(X)
    spectra = {}
    for degree in (32, 40):
        eq, c = surface_at(primary, X, degree, (MIRROR_Y,), order=4)
        spectra[degree] = {m: PER_EIGENVALUE * stability.azimuthal_spectrum(eq, c, params, m, True, COUNT)
                           for m in (1, 2, 3)}
    for m in (1, 2, 3):
        resolution = np.abs(spectra[32][m] - spectra[40][m]).max()
        assert resolution <= 1e-11, (m, resolution)
        np.testing.assert_allclose(spectra[40][m], blocks[f"m{m}_held"][:COUNT], rtol=0, atol=1e-10)
    E = stability.azimuthal_family(eq.basis, 2)
    H, M = E.T @ eq.hessian(c, params) @ E, E.T @ eq.basis.mass() @ E
    pencil = PER_EIGENVALUE * linalg.eigh(H, M, eigvals_only=True, subset_by_index=(0, COUNT - 1))
    np.testing.assert_allclose(pencil, spectra[40][2], rtol=0, atol=1e-10)
    sphere_norm = PER_EIGENVALUE * linalg.eigh(H, eq.basis.gram() * np.eye(E.shape[1]), eigvals_only=True,
                                               subset_by_index=(0, COUNT - 1))
    assert np.abs(sphere_norm / pencil - 1.0).max() > 1e-2


def odd_block(primary, X) -> np.ndarray:
    """The 2 COUNT lowest Ω² of the axisymmetric m = 0 equator-odd block (a_odd, b_even: the pear modes) with the
    axial translation b_0 removed M-orthogonally, (M e_b0)ᵀq = 0 (the translation is a zero mode at M = 0: the
    modes are M-orthogonal to it), from the axisymmetric second variation's own matrices. The block odd_held drops
    b_0 instead, ∫δη d(cos θ) = 0: the sphere's hold, the same spectrum on the sphere (P_0 ⊥ P_k there), another
    on a spheroid (whose M carries S': 7.1320 for 7.1754 at aspect 0.7)."""
    variation = mass_variation(Equilibrium(primary.scene, primary.disc), AXISYMMETRIC_DEGREE)
    H, _ = variation.matrices(X[:-1], primary.params_at(X))
    G, t = variation.gram, variation.translation
    index = np.concatenate([variation.index["a_odd"], variation.index["b_even"]])
    return PER_EIGENVALUE * eigen.lowest(H, eigen.GramFactor(G[np.ix_(index, index)]), 2 * COUNT,
                                         G[t, index][None, :], index)


def test_mirror_even_sectors_hold_the_axisymmetric_blocks(axisymmetric_state):
    """The frequency path itself (``stability.sector_spectra``, held under pressure control, as the assessment
    and dynamics/surface.py read a surface branch): on the full basis of degree 24 with the mirror y → −y and the
    equator z → −z, the two mirror-even sectors' COUNT lowest Ω² each are Ω² of the axisymmetric blocks even, the
    equator-odd m = 0 block (``odd_block``) and m1..m5_held, and the COUNT lowest of both together, with
    multiplicity, are the blocks' COUNT lowest, to 1e-9 (the resolution of degree 24: the test above; measured
    ≤ 1.3e-11; the modes of m ≥ 6 lie above them: checked)."""
    primary, X, blocks = axisymmetric_state
    eq, c = surface_at(primary, X, 24, (MIRROR_Y, EQUATOR))
    held = stability.Reading(True)
    sectors = stability.sector_spectra(eq, c, primary.params_at(X), COUNT, (held,))[held]
    whole = PER_EIGENVALUE * np.concatenate([values for key, values in sectors.items() if key[0] == 1])
    parts = [blocks["even"], odd_block(primary, X)] + [blocks[f"m{m}_held"] for m in range(1, 6)]
    axisymmetric = np.sort(np.concatenate(parts))
    assert blocks["m5_held"][0] > axisymmetric[COUNT - 1]  # order m ≥ 5 starts above: m ≥ 6 too
    assert np.abs(whole[:, None] - axisymmetric[None, :]).min(axis=1).max() <= 1e-9
    np.testing.assert_allclose(np.sort(whole)[:COUNT], axisymmetric[:COUNT], rtol=0, atol=1e-9)


@pytest.fixture(scope="module")
def m1_branch():
    """SPOM1 on the spheroid of aspect 1.6 at M = 0 with [dynamics] frequencies (count 4, m_max 3): the primary
    branch to the pole stretch 1.6 (its held m = 1 branch point at P = 1.9447), the branch born there traced 4
    points on the whole spheroid, its frequencies attached as a run attaches them (dynamics.frequencies.attach)."""
    scene = load_scene("spom1").with_overrides(
        {"geometry.shape": "spheroid", "geometry.aspect": 1.6, "continuation.stop_stretch": 1.6,
         "surface.branches": "none", "dynamics.frequencies": True, "dynamics.count": 4, "dynamics.m_max": 3})
    primary = analyse(scene, pear=False).primary
    k, bp = next((k, s) for k, s in enumerate(primary.branch_points()) if s.m == 1 and s.block.held)
    branch = trace_surface(primary, k, bp, 1.0, "m1", 4)
    attach([primary, branch], 4, 3)
    return primary, bp, branch


def test_a_spheroid_surface_branch_s_frequencies_at_its_birth_point(m1_branch):
    """At point 0 of the branch (the branch point's state solved on the whole spheroid at its P*) the stored Ω²
    (the assessment's sectors, Ω² = μ/2) of the two mirror-even held sectors are Ω² of the primary's blocks even,
    m1..m3_held at the branch point and of the equator-odd m = 0 block (``odd_block``), and their four lowest with
    multiplicity are the blocks' four lowest, to 1e-9 (the two states are the same to the solver's tolerance 1e-11
    and an Ω² moves with the state by an O(1) factor, tests/test_dynamics_surface.py; measured 1.5e-12); at the
    branch point's own state (special point 0) one Ω² of its sector is zero to the solver tolerance (measured
    -8.0e-12, the lowest -1.28: the branch is born unstable)."""
    primary, bp, branch = m1_branch
    n = next(n for n, s in enumerate(primary.special) if s is bp)
    count = branch.frequencies.count
    parts = [primary.frequencies.special[name][n] for name in ("even", "m1_held", "m2_held", "m3_held")]
    axisymmetric = np.sort(np.concatenate(parts + [odd_block(primary, bp.X)]))
    mirror = branch.basis.symmetry.index(MIRROR_Y)
    keys = [key for key in branch.sectors["held"] if key[mirror] == 1]
    whole = np.concatenate([branch.frequencies.omega2[sector_block("held", key)][0] for key in keys])
    assert abs(branch.values[0] - bp.X[-1]) < 1e-12 and np.isfinite(whole).all()
    assert np.abs(whole[:, None] - axisymmetric[None, :]).min(axis=1).max() <= 1e-9
    np.testing.assert_allclose(np.sort(whole)[:count], axisymmetric[:count], rtol=0, atol=1e-9)
    origin = branch.special[0]
    block = surface_matching_block(origin, branch)
    assert np.min(np.abs(branch.frequencies.special[block][0])) <= branch.scene.solver.tol
