"""The m ≥ 1 blocks of a capsule (analysis/stability/capsule_basis.py, codegen/second_variation.py on the capsule's
meridian): checked against the sphere's blocks at length 0 (another kernel module and another basis: the sphere's
associated Legendre functions against two joined hemispheres) and against the second derivative of the energy of the
perturbed capsule written here from the strain energy alone (Cartesian components, the reference metric
diag(κ², R²), the pressure's work P times the enclosed volume ⅓ ∮ x · (x_θ × x_φ))."""
import numpy as np
import pytest

from balloon_cg.analysis.stability import azimuthal
from balloon_cg.analysis.stability.capsule_basis import capsule_basis
from balloon_cg.galerkin.discretisation import Discretisation, basis_table
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.model import meridian
from balloon_cg.scene import parse_scene

STENCIL = (-205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560)  # f'' ≈ Σ_j c_j (f(jh) + f(−jh))/h², error O(h⁸)
SPHERE = '[material]\npreset = "SPOM1"\n'


def capsule(length: float):
    return parse_scene(SPHERE + f'[geometry]\nshape = "capsule"\nlength = {length!r}\n')


def random_state(disc: Discretisation, geometry, stretch: float, seed: int, low: int = 6) -> np.ndarray:
    """λ2 = stretch, η = stretch · Z(θ) (the reference height, fitted on the basis) plus 0.03 × random coefficients
    of the first ``low`` + 1 functions: a smooth state, neither uniform nor mirror-symmetric, nor an equilibrium."""
    theta = np.linspace(0.0, np.pi, 801)
    table = basis_table(np.cos(theta), disc.degree, disc.joins)[0]
    a = np.zeros(disc.degree + 1)
    b = np.linalg.lstsq(table, stretch * meridian.reference_height(geometry, theta), rcond=None)[0]
    a[0] = stretch
    rng = np.random.default_rng(seed)
    a[: low + 1] += 0.03 * rng.standard_normal(low + 1)
    b[1: low + 1] += 0.03 * rng.standard_normal(low)
    return disc.join(a, b)


@pytest.mark.parametrize("m", [1, 2, 3])
def test_capsule_of_length_zero_has_the_spheres_m_ge_1_eigenvalues(m):
    """SPOM1 at a random smooth state about λ = 1.3 (degree 24, P = 1.1): the capsule of length 0 (its kernels
    another module, R = sin(κ acos(cos θ)); its perturbations two hemispheres of Jacobi polynomials joined at the
    equator) against the sphere's blocks (associated Legendre functions on the whole sphere), the six lowest held
    eigenvalues at perturbation degree 40 with the translation, the rotation and the relabelling removed: 1e-10
    of the largest (measured ≤ 2.1e-11 for m = 2; at degree 32 the sphere's sixth m = 2 eigenvalue is 1e-8 from
    its limit, the hemispheres' already there)."""
    disc = Discretisation(24, symmetric=False, pin_translation=False)
    u = random_state(disc, parse_scene(SPHERE).geometry, 1.3, seed=m)
    params = Parameters(1.1)
    sphere = azimuthal.spectra(Equilibrium(parse_scene(SPHERE), disc), u, params, m, 40, 6, (True,))[True]
    capsule_values = azimuthal.spectra(Equilibrium(capsule(0.0), disc), u, params, m, 40, 6, (True,))[True]
    assert np.max(np.abs(capsule_values - sphere)) <= 1e-10 * np.max(np.abs(sphere)), capsule_values - sphere


def perturbed_energy(scene, b, state, c, m, P, eps, n_phi=64):
    """E/(2π) of the capsule x = (ρ0 + εR cos mφ) e_ρ + εT sin mφ e_φ + (η0 + εZ cos mφ) e_z at the basis' nodes
    (θ-weights: its d(cos θ) weights over sin θ): Φ(λ1, λ2) over the reference area κ R dθ dφ, λ1², λ2² the
    eigenvalues of the metric over the reference's diag(κ², R²), minus P ⅓ x · (x_θ × x_φ). ``state`` =
    (ρ0, ρ0', η0, η0') at the nodes, R, κ written here."""
    material, length = scene.material, scene.geometry.length
    kappa = 1 + length / np.pi
    theta = b.theta
    cap = np.minimum(kappa * np.minimum(theta, np.pi - theta), np.pi / 2)
    radius = np.sin(cap)[:, None]
    dtheta = (b.weights / np.sin(theta))
    rho, drho, eta, deta = (q[:, None] for q in state)
    Rv, dR, Zv, dZ, Tv, dT = (eps * q[:, None] for q in b.values(c))
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    cM, sM = np.cos(m * phi), np.sin(m * phi)
    f, g, z = rho + Rv * cM, Tv * sM, eta + Zv * cM
    x_t = np.array([drho + dR * cM, dT * sM, deta + dZ * cM])
    x_p = np.array([-m * Rv * sM - g, m * Tv * cM + f, -m * Zv * sM])
    a11, a12, a22 = (x_t * x_t).sum(0) / kappa**2, (x_t * x_p).sum(0) / (kappa * radius), (x_p * x_p).sum(0) / radius**2
    root = np.sqrt((a11 - a22) ** 2 / 4 + a12**2)
    l1, l2 = np.sqrt((a11 + a22) / 2 + root), np.sqrt((a11 + a22) / 2 - root)
    phi_energy = sum(mu / al * (l1**al + l2**al + (l1 * l2) ** -al - 3) for mu, al in zip(material.mu, material.alpha))
    normal = np.cross(x_t, x_p, axis=0)
    volume = (f * normal[0] + g * normal[1] + z * normal[2]) / 3
    density = phi_energy * kappa * radius - P * volume
    return dtheta @ density.sum(1) / n_phi


@pytest.mark.parametrize("length, m", [(3.0, 1), (3.0, 2), (8.0, 1)])
def test_capsule_block_is_the_second_variation_of_its_energy(length, m):
    """A random smooth state (degree 16 on the capsule's element basis) and a random perturbation c: cᵀHc of the
    assembled block against d²E/dε² of the energy written here (an 8th-order stencil in ε), 1e-8 relative (measured
    9e-11, 1.9e-10, 1.6e-10); and the Gram matrix is ½ ∫ (R² + T² + Z²) κ R dθ (the same quadrature: 1e-12)."""
    scene = capsule(length)
    eq = Equilibrium(scene, Discretisation(16, symmetric=False, pin_translation=False,
                                           joins=meridian.joins(scene.geometry)))
    disc = eq.disc
    u = random_state(disc, scene.geometry, 1.4, seed=7)
    P = 0.9
    b = azimuthal.perturbation_basis(eq, m, 16)
    assert b is capsule_basis(m, 16, scene.geometry)
    H, G = azimuthal.azimuthal_hessian(eq, u, Parameters(P), m, 16)
    c = np.random.default_rng(11).standard_normal(b.size)
    c /= np.abs(b.values(c)).max()  # max |R|, |R'|, … = 1 (the orthonormal functions' slopes are large)
    lam2, dlam2, eta, deta = disc.evaluate(u, b.theta)
    kappa = 1 + length / np.pi
    cap = np.minimum(kappa * np.minimum(b.theta, np.pi - b.theta), np.pi / 2)
    R = np.sin(cap)
    dR = np.where(cap < np.pi / 2, kappa * np.cos(cap) * np.sign(np.pi / 2 - b.theta), 0.0)
    state = (lam2 * R, dlam2 * R + lam2 * dR, eta, deta)
    h = 2e-2  # with max |y| = 1: the stencil's rounding 1e-9 at h = 5e-3, its truncation below 2e-10 at 2e-2
    second = sum(w * (perturbed_energy(scene, b, state, c, m, P, j * h) + perturbed_energy(scene, b, state, c, m, P,
                                                                                           -j * h))
                 / (2 if j == 0 else 1) for j, w in enumerate(STENCIL)) / h**2
    assert abs(c @ H @ c - second) <= 1e-8 * abs(second), (c @ H @ c, second)
    R_, _, Z_, _, T_, _ = b.values(c)
    gram = 0.5 * (b.weights / np.sin(b.theta)) @ ((R_**2 + T_**2 + Z_**2) * kappa * R)
    assert abs(c @ G @ c - gram) <= 1e-12 * gram


@pytest.mark.parametrize("m", [1, 2])
def test_capsule_blocks_split_into_their_reflection_classes(m):
    """L = 3, an equator-symmetric random smooth state (λ2 even, η odd in x; degree 16): the two reflection classes'
    blocks (the equator-symmetric discretisation's reading) have together the whole block's six lowest eigenvalues
    (the same state on the discretisation without symmetry), 1e-10 of the largest; the classes hold the translation
    (class 0) and the rotation (class 1) as the sphere's do; the basis is orthonormal (G = I to 1e-12)."""
    scene = capsule(3.0)
    bounds = meridian.joins(scene.geometry)
    whole = Discretisation(16, symmetric=False, pin_translation=False, joins=bounds)
    split = Discretisation(16, symmetric=True, pin_translation=True, joins=bounds)
    full = random_state(whole, scene.geometry, 1.4, seed=3)
    a, b = whole.split(full)
    a[1::2], b[0::2] = 0.0, 0.0
    params = Parameters(0.9)
    values = [azimuthal.spectra(Equilibrium(scene, disc), disc.join(a, b), params, m, 16, 6, (True,))[True]
              for disc in (whole, split)]
    assert np.max(np.abs(values[0] - values[1])) <= 1e-10 * np.max(np.abs(values[0])), values
    basis = capsule_basis(m, 16, scene.geometry)
    assert sorted(np.concatenate(basis.classes).tolist()) == list(range(basis.size))
    assert np.max(np.abs(basis.gram - np.eye(basis.size))) <= 1e-12  # orthonormal: no entries between classes


def test_capsule_branch_locates_stores_and_shows_its_m1_points(tmp_path):
    """SPOM1 capsule of length 3, m_max = 1, to a pole stretch of 1.3 (the sphere's pipeline: ``analyse``): beyond
    its pressure maximum the held m = 1 block has two located zeros (branch points m1_held: measured P = 1.4612867475
    and 0.8467644642, the same from degrees 40 and 64 to 2e-11); at each the lowest held m = 1 eigenvalue on a
    perturbation basis 24 degrees finer than the branch's is still 0 (1e-7 of the next one: the zero is the
    continuous problem's, not the basis'); the run file stores them and ``inspect`` shows them as BP m=1."""
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.app.summaries import summarise_file
    from balloon_cg.io.run_file import write_run

    scene = parse_scene(SPHERE + '[geometry]\nshape = "capsule"\nlength = 3.0\n[stability]\nm_max = 1\n'
                        '[continuation]\nstop_stretch = 1.3\n')
    branch = analyse(scene, pear=False).branches[0]
    points = [p for p in branch.special if p.kind.value == "BP" and p.block.value == "m1_held"]
    fold = next(p for p in branch.special if p.kind.value == "LP")
    assert len(points) == 2 and all(p.X[-1] < fold.X[-1] and p.status.value == "located" for p in points)
    eq = Equilibrium(scene, branch.disc)
    for p in points:
        values = azimuthal.spectra(eq, p.X[:-1], Parameters(p.X[-1]), 1, branch.disc.degree + 24, 3, (True,))[True]
        assert abs(values[0]) <= 1e-7 * values[1], values
    path = write_run(tmp_path / "capsule.h5", scene, [branch])
    summary, text = summarise_file(path)
    assert text.count("BP m=1") == 2


def test_capsule_in_a_coil_field_reads_held_and_free():
    """L = 3 with a coaxial coil about its middle (radius 3, M = 0.01), an equator-symmetric random smooth state
    (degree 16, P = 0.9): the free m = 1 reading keeps the translation and has a negative eigenvalue (the coil pulls
    the capsule sideways: measured −0.0047), the held one removes it (lowest 0.516); the held reading through the
    free one's factorisation (``lowest_readings``) is the one restricted directly (``restricted_blocks``), 1e-10;
    at M = 0 the two readings are one."""
    scene = parse_scene(SPHERE + '[geometry]\nshape = "capsule"\nlength = 3.0\n[field]\nM = 0.01\n[[field.coils]]\n'
                        'radius = 3.0\nheight = 0.0\ncurrent = 1.0\n')
    bounds = meridian.joins(scene.geometry)
    whole = Discretisation(16, symmetric=False, pin_translation=False, joins=bounds)
    disc = Discretisation(16, symmetric=True, pin_translation=True, joins=bounds)
    a, b = whole.split(random_state(whole, scene.geometry, 1.4, seed=3))
    a[1::2], b[0::2] = 0.0, 0.0
    eq, u = Equilibrium(scene, disc), disc.join(a, b)
    for M in (0.01, 0.0):
        params = Parameters(0.9, M)
        fast = azimuthal.lowest_readings(eq, u, params, 1, 16, 4, (True, False))
        direct = {held: azimuthal.merged_lowest(parts, 4)
                  for held, parts in azimuthal.restricted_blocks(eq, u, params, 1, 16, (True, False)).items()}
        for held in (True, False):
            assert np.max(np.abs(fast[held] - direct[held])) <= 1e-10 * np.max(np.abs(direct[held]))
        if M:
            assert direct[False][0] < 0 < direct[True][0]
        else:
            assert np.array_equal(direct[True], direct[False]) and direct[True][0] > 0
