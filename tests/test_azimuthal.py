"""Non-axisymmetric (m ≥ 1) second variation (balloon_cg.analysis.stability.azimuthal, codegen/second_variation.py).

Independent checks: the exact sphere's spectrum (spherical symmetry: m = 1 = axisymmetric n ≥ 1 + toroidal modes
with the closed form below), rigid-body null vectors, the removable singularity of the shear coefficient against
mpmath, a brute-force 2D energy (numerical eigenvalues of G⁻¹g, Biot–Savart field, both volume forms) differenced
twice in ε, and convergence in the perturbation degree on a deformed magnetic state.
"""
from pathlib import Path

import mpmath
import numpy as np
import pytest
from numpy.polynomial import legendre
from scipy import linalg

from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.stability import azimuthal as az
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.galerkin import legendre as associated
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.model.field import field_squared
from balloon_cg.scene import load_scene, parse_scene
from balloon_cg.model.sphere import sphere_pressure

ROOT = Path(__file__).resolve().parent.parent
SPOM1 = (3.00508, 0.0145, -0.0177), (1.3, 4.0, -2.0)


def sphere_state(scene, stretch, degree=14):
    """Equilibrium object on the full (m = 0) basis with b_0 kept, and the exact sphere of radius ``stretch``."""
    disc = Discretisation(degree, symmetric=False, pin_translation=False)
    eq = Equilibrium(scene, disc)
    a, b = np.zeros(degree + 1), np.zeros(degree + 1)
    a[0], b[1] = stretch, stretch
    return eq, disc.join(a, b), Parameters(sphere_pressure(scene.material, stretch))


def axisymmetric_spectrum(eq, u, params):
    """Eigenvalues of the m = 0 Hessian in the same norm ‖δx‖² = ∫ (sin²θ δλ2² + δη²) d(cos θ) (per 2π)."""
    disc = eq.disc
    ops, w, s = disc.ops, disc.weights, disc.sin_theta
    gram = (ops[0].T * (w * s * s)) @ ops[0] + (ops[2].T * w) @ ops[2]
    J = eq.jacobian(u, params)
    inflation = disc.join(np.eye(disc.degree + 1)[0], np.eye(disc.degree + 1)[1])  # δλ2 = 1, δη = cos θ: n = 0
    return linalg.eigh(J, gram, eigvals_only=True), (inflation @ J @ inflation) / (inflation @ gram @ inflation)


def sphere_derivatives(stretch):
    """Φ1, Φ11, Φ12 of the SPOM1 Ogden energy at λ1 = λ2 = stretch."""
    mu, alpha = map(np.array, SPOM1)
    lam = stretch
    phi1 = np.sum(mu * (lam ** (alpha - 1) - lam ** (-2 * alpha - 1)))
    phi11 = np.sum(mu * ((alpha - 1) * lam ** (alpha - 2) + (alpha + 1) * lam ** (-2 * alpha - 2)))
    phi12 = np.sum(mu * alpha * lam ** (-2 * alpha - 2))
    return phi1, phi11, phi12


def remove_matches(values, targets, tol):
    """values minus (multiset) targets, each target matched within tol·max(1, |target|); returns the rest and the
    targets that found no match."""
    rest = list(values)
    missing = []
    for t in targets:
        j = int(np.argmin(np.abs(np.array(rest) - t))) if rest else -1
        if j >= 0 and abs(rest[j] - t) <= tol * max(1.0, abs(t)):
            rest.pop(j)
        else:
            missing.append(t)
    return np.array(rest), missing


@pytest.fixture(scope="module")
def spom1():
    return load_scene(ROOT / "scenes" / "spom1.toml")


def test_associated_legendre_functions_are_orthonormal_with_exact_theta_derivatives():
    x, w = legendre.leggauss(60)
    theta, h = np.arccos(x), 1e-6
    for order in range(4):
        p, dp = associated.assoc_legendre(x, 25, order)
        assert np.abs(p.T @ (w[:, None] * p) - np.diag(np.arange(26) >= order)).max() < 1e-12
        up, _ = associated.assoc_legendre(np.cos(theta + h), 25, order)
        down, _ = associated.assoc_legendre(np.cos(theta - h), 25, order)
        assert np.abs((up - down) / (2 * h) - dp).max() < 1e-7 * np.abs(dp).max()


@pytest.mark.parametrize("m", [1, 2, 3])
def test_every_basis_function_is_a_smooth_displacement_at_the_poles(m):
    """δx (Cartesian) of each basis function has one limit at each pole, whatever φ (no 1/sin θ anywhere), and is
    Lipschitz there; for m = 1 the poles move (translation), for m ≥ 2 they do not."""
    b = az.AzimuthalBasis(m, 9, 30)
    phi = np.linspace(0, 2 * np.pi, 8)[:-1]
    for j in range(b.size):
        c = np.eye(b.size)[j]
        for pole in (0.0, np.pi):
            at_pole = b.cartesian(c, np.full(phi.size, pole), phi)
            assert np.abs(at_pole - at_pole[:, :1]).max() < 1e-12
            if m >= 2:
                assert np.abs(at_pole).max() < 1e-12
            for t in (1e-4, 1e-6):
                near = b.cartesian(c, np.full(phi.size, abs(pole - t)), phi)
                assert np.abs(near - at_pole).max() < 50 * t * max(1.0, np.abs(at_pole).max())


@pytest.mark.parametrize("stretch", [1.5, 2.5])
def test_sphere_m1_spectrum_is_the_axisymmetric_one_plus_toroidal_modes(spom1, stretch):
    """Spherical symmetry: the cos φ family holds the spheroidal modes of every degree n ≥ 1 (same eigenvalues as
    the axisymmetric Hessian without its n = 0 inflation mode) and the toroidal ones (tangential, divergence-free),
    absent from the axisymmetric model: μ_n = (n(n+1) − 2)·½(Φ11 − Φ12 + Φ1/λ), n ≥ 1 (n = 1: the rotation).
    The last factor is the limit of (λ1Φ1 − λ2Φ2)/(λ1² − λ2²), the prestressed membrane's shear modulus."""
    eq, u, params = sphere_state(spom1, stretch)
    assert np.abs(eq.residual(u, params)).max() < 1e-12
    axisym, inflation = axisymmetric_spectrum(eq, u, params)
    spheroidal, missing = remove_matches(axisym, [inflation], 1e-10)
    assert not missing
    phi1, phi11, phi12 = sphere_derivatives(stretch)
    shear = 0.5 * (phi11 - phi12 + phi1 / stretch)
    toroidal = [(n * (n + 1) - 2) * shear for n in range(1, 12)]
    H, G = az.azimuthal_hessian(eq, u, params, 1, 14)
    m1 = az.lowest_eigenvalues(H, G, 14)
    expected = np.sort(np.concatenate([spheroidal, toroidal]))[:14]
    assert np.abs(m1 - expected).max() < 1e-9 * np.abs(expected).max()
    # the n = 1 spheroidal pair: the translation (0) and 3(Φ11 + Φ12 − Φ1/λ) (the pear mode, MODEL.md §5)
    pear = 3 * (phi11 + phi12 - phi1 / stretch)
    assert len(remove_matches(m1, [0.0, 0.0, pear], 1e-9)[1]) == 0
    # m = 2 holds the same modes except n = 1
    H2, G2 = az.azimuthal_hessian(eq, u, params, 2, 14)
    m2 = az.lowest_eigenvalues(H2, G2, 14)
    rest, missing = remove_matches(spheroidal, [0.0, pear], 1e-9)
    assert not missing
    expected2 = np.sort(np.concatenate([rest, toroidal[1:]]))[:14]
    assert np.abs(m2 - expected2).max() < 1e-9 * np.abs(expected2).max()


@pytest.mark.parametrize("stretch", [1.5, 2.5])
def test_rigid_translation_and_rotation_are_null_vectors_at_M0(spom1, stretch):
    eq, u, params = sphere_state(spom1, stretch)
    H, G = az.azimuthal_hessian(eq, u, params, 1, 12)
    scale = np.abs(H).max()
    modes = az.special_modes(eq, u, 12)
    for name in ("translation", "rotation"):
        assert modes[name] @ G @ modes[name] > 1.0  # nontrivial
        assert np.abs(H @ modes[name]).max() < 1e-10 * scale
    # on the sphere the relabelling mode is the rotation
    assert np.abs(modes["relabelling"] - modes["rotation"]).max() < 1e-12
    values = az.lowest_eigenvalues(H, G, 6)
    zero = np.abs(values) < 1e-10 * scale
    assert zero.sum() == 2 and np.abs(values[~zero]).min() > 1e-3
    # excluding them removes exactly the two zeros (at λ = 2.5 the n = 1 pear mode is negative, below them)
    assert np.allclose(az.spectrum(eq, u, params, 1, 12, 4), values[~zero], rtol=1e-10)


def test_translation_is_a_null_vector_of_any_state_without_field():
    """E(x0 + ε e_x) = E(x0) for every state when M = 0 (not only at equilibrium): a deformed, unbalanced shape."""
    scene = load_scene(ROOT / "scenes" / "spom1_two_coils_M0.002.toml")
    disc = Discretisation(8, symmetric=False, pin_translation=False)
    eq = Equilibrium(scene, disc)
    a, b = np.zeros(9), np.zeros(9)
    a[[0, 1, 2]], b[[0, 1, 3]] = (1.7, 0.1, 0.25), (0.05, 1.5, 0.1)
    u = disc.join(a, b)
    H, _ = az.azimuthal_hessian(eq, u, Parameters(1.9, 0.0, 1.0), 1, 12)
    translation = az.special_modes(eq, u, 12)["translation"]
    assert np.abs(H @ translation).max() < 1e-11 * np.abs(H).max()


def exact_shear(mu, alpha, l1, l2):
    """K = (φ̂_1 − φ̂_2)/(λ1² − λ2²) for Ogden, 50 digits; its limit at λ1 = λ2 from the derivative."""
    with mpmath.workdps(50):
        l1, l2 = mpmath.mpf(l1), mpmath.mpf(l2)
        e1, e2 = l1**2, l2**2
        total = mpmath.mpf(0)
        for m, a in zip(mu, alpha):
            m, a = mpmath.mpf(m), mpmath.mpf(a)
            p = a / 2 - 1
            divided = (e1**p - e2**p) / (e1 - e2) if e1 != e2 else p * e2 ** (p - 1)
            total += m / 2 * (divided + (e1 * e2) ** (-a / 2 - 1))
        return float(total)


@pytest.mark.parametrize(
    "module, mu, alpha",
    [("ogden_spom1", *SPOM1), ("ogden_tpom2", (2.0202,), (1.98,)),
     ("ogden_mooney_rivlin", (2 / 1.1, -0.2 / 1.1), (2.0, -2.0)),
     ("ogden_general_field", (1.1, 0.4, -0.05), (1.7, 3.3, -2.5))],
)
def test_shear_coefficient_is_finite_smooth_and_exact_through_lambda1_eq_lambda2(module, mu, alpha):
    from balloon_cg import generated
    from balloon_cg.model.kernels import KernelSet
    from balloon_cg.scene.materials import Material

    kernels = KernelSet(Material("test", mu, alpha), generated.CLASSES[module][1], kernel_class=module)
    K = lambda l1, l2: kernels.call("shear_coefficient", {"lam1": l1, "lam2": l2})[0]  # noqa: E731
    worst = 0.0
    for l2 in (1.0, 1.7, 3.0, 6.0):
        limit = exact_shear(mu, alpha, l2, l2)
        assert K(l2, l2) == pytest.approx(limit, rel=1e-14)
        for sign in (1, -1):
            assert abs(K(l2 * (1 + sign * 1e-9), l2) - limit) < 1e-8 * abs(limit)
        for h in np.concatenate([-np.logspace(-15, -0.5, 80), np.logspace(-15, -0.5, 80)]):
            l1 = l2 * (1 + h)
            worst = max(worst, abs(K(l1, l2) / exact_shear(mu, alpha, l1, l2) - 1))
    assert worst < 1e-13


def test_termwise_shear_formula_is_the_divided_difference_of_the_energy():
    """The per-term formula used above (and emitted) equals (φ̂_1 − φ̂_2)/(λ1² − λ2²) from the class's Φ (SymPy)."""
    from codegen import functional as fn, second_variation as sv
    from codegen.classes import scene_classes

    cls = next(c for c in scene_classes() if c.name == "ogden_spom1")
    _, limit, closed = sv.shear_coefficient(cls)
    values = dict(zip(cls.elastic.moduli(), SPOM1[0]))
    for l1, l2 in ((1.9, 1.4), (1.3, 2.6), (3.0, 3.2)):
        expected = exact_shear(*SPOM1, l1, l2)
        assert float(closed.subs({**values, sv.l1: l1, fn.lam2: l2})) == pytest.approx(expected, rel=1e-13)
    assert float(limit.subs({**values, fn.lam2: 2.2})) == pytest.approx(exact_shear(*SPOM1, 2.2, 2.2), rel=1e-13)


def test_hessian_kernel_is_continuous_at_equal_stretches():
    """azimuthal_hessian at a node where λ1 = λ2 exactly (sphere) and at λ1 = λ2(1 ± 1e-9): all 21 entries agree
    to ~1e-9 relative (no 0/0 anywhere)."""
    from balloon_cg.generated import ogden_spom1 as mod

    c, lam = 0.3, 1.8
    s = np.sqrt(1 - c * c)
    mu = np.array(SPOM1[0])

    def entries(factor):  # λ1 = factor·λ2 by scaling the meridional tangent (v, w) of the sphere
        w = -lam * s * factor
        v = lam * c * factor - lam * c
        return np.array(mod.azimuthal_hessian(c, s, lam, v, lam * c, w, 1.0, 2.1, mu))

    at = entries(1.0)
    assert np.all(np.isfinite(at))
    for factor in (1 + 1e-9, 1 - 1e-9):
        assert np.abs(entries(factor) - at).max() < 1e-7 * np.abs(at).max()


# -- brute force: the energy of x0 + ε δx by 2D quadrature, second difference in ε ----------------------------------

def ogden_energy(material, l1, l2):
    return sum(m / a * (l1**a + l2**a + (l1 * l2) ** (-a) - 3) for m, a in zip(material.mu, material.alpha))


def brute_force_energy(eq, u, params, b, c, eps, volume="cone", n_phi=48):
    """E/(2π): Gauss in cos θ, trapezoid in φ, x_φ by FFT of the Cartesian position, principal stretches from the
    eigenvalues of the 2×2 matrix G⁻¹g (orthonormal frame), H² of the coils at the 3D point."""
    s, theta = b.sin_theta, b.theta
    lam2, dlam2, eta, deta = eq.disc.evaluate(u, theta)
    rho, drho = lam2 * s, dlam2 * s + lam2 * b.x
    R, R1, Z, Z1, T, T1 = (v[:, None] for v in b.values(c))
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    cm, sm = np.cos(b.m * phi), np.sin(b.m * phi)
    er = np.stack([np.cos(phi), np.sin(phi), 0 * phi])[:, None]
    ep = np.stack([-np.sin(phi), np.cos(phi), 0 * phi])[:, None]
    ez = np.array([0.0, 0.0, 1.0])[:, None, None]
    X = (rho[:, None] + eps * R * cm) * er + eps * T * sm * ep + (eta[:, None] + eps * Z * cm) * ez
    Xt = (drho[:, None] + eps * R1 * cm) * er + eps * T1 * sm * ep + (deta[:, None] + eps * Z1 * cm) * ez
    k = np.fft.fftfreq(n_phi, 1.0 / n_phi)
    Xp = np.real(np.fft.ifft(1j * k * np.fft.fft(X, axis=-1), axis=-1))
    c11, c12, c22 = (Xt * Xt).sum(0), (Xt * Xp).sum(0) / s[:, None], (Xp * Xp).sum(0) / s[:, None] ** 2
    eig = np.linalg.eigvalsh(np.stack([np.stack([c11, c12], -1), np.stack([c12, c22], -1)], -1))
    W = ogden_energy(eq.scene.material, np.sqrt(eig[..., 1]), np.sqrt(eig[..., 0]))
    if params.M:
        r = np.hypot(X[0], X[1])
        H2 = np.array([[field_squared(r[i, j], X[2][i, j], eq.coils)[0] for j in range(n_phi)]
                       for i in range(r.shape[0])])
        W = W - 0.5 * params.chi * params.M * H2
    if volume == "cone":  # (1/3) x·(x_θ × x_φ)
        dV = (X * np.cross(Xt, Xp, axis=0)).sum(0) / 3
    else:  # ½ ρ² dβ∧dz
        dV = 0.5 * ((X[0] * Xt[1] - X[1] * Xt[0]) * Xp[2] - (X[0] * Xp[1] - X[1] * Xp[0]) * Xt[2])
    return b.weights @ (W - params.P * dV / s[:, None]).mean(axis=1)


def second_difference(eq, u, params, b, c, volume, eps=2e-3):
    E0 = brute_force_energy(eq, u, params, b, c, 0.0, volume)
    d2 = lambda e: (brute_force_energy(eq, u, params, b, c, e, volume)  # noqa: E731
                    + brute_force_energy(eq, u, params, b, c, -e, volume) - 2 * E0) / e**2
    return (4 * d2(eps / 2) - d2(eps)) / 3  # Richardson: O(ε⁴)


@pytest.mark.parametrize("material", ['preset = "SPOM1"', "mu = [1.2, 0.3, -0.02]\nalpha = [1.6, 3.5, -2.2]"])
def test_hessian_equals_brute_force_second_difference(material):
    """Any smooth state (here a deformed, off-centre, non-equilibrium one) in a strong two-coil field: yᵀHy equals
    d²E/dε² of the directly integrated 3D energy, for m = 1, 2, 3, with either volume formula."""
    scene = parse_scene(
        f"[material]\n{material}\n[field]\nM = 0.05\nchi = 1.0\n"
        "[[field.coils]]\nradius = 1.7321\nheight = 1.0\ncurrent = 1.0\n"
        "[[field.coils]]\nradius = 1.7321\nheight = -1.0\ncurrent = -1.0\n",
        name="brute",
    )
    disc = Discretisation(6, symmetric=False, pin_translation=False)
    eq = Equilibrium(scene, disc)
    a, bb = np.zeros(7), np.zeros(7)
    a[[0, 1, 2, 4]], bb[[0, 1, 3]] = (1.3, 0.08, 0.15, 0.03), (0.1, 1.2, 0.08)
    u = disc.join(a, bb)
    params = Parameters(1.7, 0.05, 1.0)
    rng = np.random.default_rng(7)
    for m in (1, 2, 3):
        H, _ = az.azimuthal_hessian(eq, u, params, m, 7)
        b = az.perturbation_basis(eq, m, 7)
        c = rng.normal(size=b.size) / np.arange(1, b.size + 1)
        exact = c @ H @ c
        for volume in ("cone", "cylinder"):
            assert second_difference(eq, u, params, b, c, volume) == pytest.approx(exact, rel=1e-7)


@pytest.fixture(scope="module")
def two_coil_state():
    scene = load_scene(ROOT / "scenes" / "spom1_two_coils_M0.002.toml")
    branch = trace_primary(scene, stop_stretch=1.5, down=False)
    X = branch.X[-1]
    return equilibrium_of(branch), X[:-1], branch.params.with_value("P", X[-1])


def test_relabelling_mode_is_null_at_a_magnetic_equilibrium(two_coil_state):
    """With a field the rigid rotation costs energy (H² is not invariant) but relabelling the material by a rotation
    of the reference sphere does not: an exact zero mode; the rotation's energy is the field's alone."""
    eq, u, params = two_coil_state
    H, G = az.azimuthal_hessian(eq, u, params, 1, 64)  # ≥ the equilibrium degree + 1: modes exact in the basis
    modes = az.special_modes(eq, u, 64)
    scale = np.abs(H).max()
    assert np.abs(H @ modes["relabelling"]).max() < 1e-9 * scale
    # the rigid rotation: elastic and pressure energies are invariant, so at an equilibrium its second variation is
    # the field energy's, −½χM d²/dε² ∫ H²(Q_ε x0) dA (Q_ε: rotation by ε about e_y), computed here directly
    x, w = legendre.leggauss(72)
    theta = np.arccos(x)
    lam2, _, eta, _ = eq.disc.evaluate(u, theta)
    phi = 2 * np.pi * np.arange(48) / 48
    points = np.stack([np.outer(lam2 * np.sin(theta), np.cos(phi)), np.outer(lam2 * np.sin(theta), np.sin(phi)),
                       np.outer(eta, np.ones_like(phi))])

    def field_integral(eps):
        c, s = np.cos(eps), np.sin(eps)
        y = np.einsum("ij,jab->iab", np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]), points)
        r = np.hypot(y[0], y[1])
        H2 = np.array([[field_squared(r[i, j], y[2][i, j], eq.coils)[0] for j in range(phi.size)]
                       for i in range(x.size)])
        return w @ H2.mean(axis=1)

    e = 1e-2
    d2 = (field_integral(e) + field_integral(-e) - 2 * field_integral(0.0)) / e**2
    d2 = (4 * (field_integral(e / 2) + field_integral(-e / 2) - 2 * field_integral(0.0)) / (e / 2) ** 2 - d2) / 3
    rotation = modes["rotation"]
    assert rotation @ H @ rotation == pytest.approx(-0.5 * params.chi * params.M * d2, rel=1e-6)


def test_lowest_eigenvalue_converges_in_the_degree_on_a_magnetic_state(two_coil_state):
    """Free and held readings (MODEL.md §5), m = 1 and 2: degree N and 2N agree to 1e-6. The free balloon between
    the opposed coils (a field minimum) is unstable to sliding sideways; held at its centre it is stable."""
    eq, u, params = two_coil_state
    theta = np.linspace(0, np.pi, 9)
    lam2 = eq.disc.evaluate(u, theta)[0]
    assert np.ptp(lam2) > 1e-3  # not a sphere
    for m, held in ((1, False), (1, True), (2, False)):
        coarse, fine = (az.spectrum(eq, u, params, m, N, 3, held=held) for N in (20, 40))
        assert np.abs(coarse - fine).max() < 1e-6 * max(1.0, np.abs(fine).max())
        if m == 1:
            assert (fine[0] < -1e-2) != held
            assert fine[1] > 1.0


@pytest.mark.parametrize("m", [1, 2])
def test_reflection_classes_split_the_block_of_a_symmetric_state(m):
    """An equator-symmetric state (two opposed coils, a field): H and G have no entries between the reflection
    classes (rounding only), and the two class blocks together give the whole block's spectrum, held and free,
    with every special mode in the class MODE_CLASS names."""
    scene = load_scene(ROOT / "scenes" / "spom1_two_coils_M0.002.toml")
    branch = trace_primary(scene, stop_stretch=1.6, down=False)
    assert branch.disc.symmetric
    eq, X = equilibrium_of(branch), branch.X[-1]
    u, params = X[:-1], branch.params.with_value("P", X[-1])
    H, G = az.azimuthal_hessian(eq, u, params, m, 20)
    b = az.perturbation_basis(eq, m, 20)
    even, odd = b.classes
    assert even.size + odd.size == b.size and min(even.size, odd.size) > 0
    for M in (H, G):
        assert np.abs(M[np.ix_(even, odd)]).max() < 1e-13 * np.abs(M).max()
    if m == 1:
        moments = az.mode_moments(eq, u, b)
        for k, cls in enumerate(az.MODE_CLASS):
            other = b.classes[1 - cls]
            assert np.abs(moments[k, other]).max() < 1e-13 * np.abs(moments[k]).max()
    for held in (True, False):
        split = az.spectrum(eq, u, params, m, 20, 5, held=held)
        exclude = [] if m > 1 else [az.special_modes(eq, u, 20)[az.MODES[k]]
                                    for k in az.excluded_modes(eq, params, held)]
        null = linalg.null_space(np.atleast_2d(exclude) @ G) if exclude else np.eye(b.size)
        whole = linalg.eigh(null.T @ H @ null, null.T @ G @ null, eigvals_only=True)[:5]
        assert np.abs(split - whole).max() < 1e-10 * np.abs(whole).max()
