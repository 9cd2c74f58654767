"""Axisymmetric bifurcations of the M = 0 sphere from the continuum second variation (balloon_cg.model.sphere_modes),
checked against a brute-force second variation: E of MODEL.md §2 evaluated by Gauss–Legendre quadrature for the
sphere perturbed by one Legendre mode, differentiated twice by finite differences."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy.polynomial import legendre
from scipy.optimize import brentq
from scipy.special import roots_legendre

from balloon_cg.scene.materials import Material, get_preset
from balloon_cg.model.sphere import sphere_pressure
from balloon_cg.model.sphere_modes import (
    bifurcation_condition,
    bifurcation_pressures,
    bifurcation_stretches,
    mode_matrix,
)

PRESETS = ["SPOM1", "SPOM2", "FPOM1", "FPOM2", "TPOM1", "TPOM2"]
# Single-term Ogden with α = 1.05 (Σ μα = 4): unstable to n = 2, 3, 4, ... in [1, 10], exercises n ≥ 2 roots.
SOFT = Material("alpha1.05", (4 / 1.05,), (1.05,))
ROOT = Path(__file__).resolve().parents[1]

# ---------------------------------------------------------------------------------------------------------------
# Brute force: E(a, b) for ρ = (λ + w) sin θ + u cos θ, η = (λ + w) cos θ − u sin θ, w = a P_n(cos θ),
# u = b dP_n(cos θ)/dθ; λ1 = sqrt(ρ'² + η'²), λ2 = ρ / sin θ; Φ evaluated directly (no derivatives of Φ).

_THETA, _WEIGHTS = roots_legendre(240)
_THETA, _WEIGHTS = np.pi / 2 * (_THETA + 1), np.pi / 2 * _WEIGHTS


def energy(material, stretch, pressure, n, a, b):
    s, c = np.sin(_THETA), np.cos(_THETA)
    p = legendre.Legendre.basis(n)
    dp, ddp = p.deriv(1), p.deriv(2)
    psi, dpsi, ddpsi = p(c), -s * dp(c), -c * dp(c) + s * s * ddp(c)  # P_n(cos θ) and its θ-derivatives
    w, dw, u, du = a * psi, a * dpsi, b * dpsi, b * ddpsi
    rho = (stretch + w) * s + u * c
    drho = dw * s + (stretch + w) * c + du * c - u * s
    deta = dw * c - (stretch + w) * s - du * s - u * c
    l1, l2 = np.hypot(drho, deta), rho / s
    phi = sum(m / al * (l1**al + l2**al + (l1 * l2) ** (-al) - 3) for m, al in zip(material.mu, material.alpha))
    return np.sum(_WEIGHTS * (phi * s + 0.5 * pressure * rho**2 * deta))


_D2 = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560])  # 8th order
_D1 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])


def _stencil(weights, f, h, power):
    return sum(wk * f(k * h) for wk, k in zip(weights, range(-4, 5))) / h**power


def brute_force(material, stretch, n):
    """(gradient, Hessian) of E in (a, b) at the sphere, by 8th-order central differences."""
    pressure = sphere_pressure(material, stretch)
    h = 0.01 * stretch / max(1, n * n)  # u' ~ n² b: shrink the step with n
    E = lambda a, b: energy(material, stretch, pressure, n, a, b)  # noqa: E731
    grad = np.array([_stencil(_D1, lambda e: E(e, 0), h, 1), _stencil(_D1, lambda e: E(0, e), h, 1)])
    haa = _stencil(_D2, lambda e: E(e, 0), h, 2)
    hbb = _stencil(_D2, lambda e: E(0, e), h, 2)
    hab = (_stencil(_D2, lambda e: E(e, e), h, 2) - _stencil(_D2, lambda e: E(e, -e), h, 2)) / 4
    return grad, np.array([[haa, hab], [hab, hbb]])


def brute_force_condition(material, stretch, n):
    """The brute-force analogue of bifurcation_condition: H_aa for n = 0 (no tangential mode), the trace (the
    non-translation eigenvalue) for n = 1, det H for n ≥ 2."""
    H = brute_force(material, stretch, n)[1]
    return H[0, 0] if n == 0 else np.trace(H) if n == 1 else np.linalg.det(H)


def _materials():
    return [get_preset(name) for name in PRESETS] + [SOFT]


# ---------------------------------------------------------------------------------------------------------------
# (a) the closed form against the brute force


@pytest.mark.parametrize("material", _materials(), ids=lambda m: m.name)
@pytest.mark.parametrize("n", [0, 1, 2, 3, 4])
def test_mode_matrix_is_the_brute_force_hessian(material, n):
    for stretch in (1.05, 1.6, 2.5, 6.0):
        grad, H = brute_force(material, stretch, n)
        K = mode_matrix(material, stretch, n) * 2 / (2 * n + 1)
        scale = np.abs(K).max()
        assert np.abs(grad).max() < 1e-9 * scale  # the sphere is an equilibrium at P(λ)
        assert np.abs(H - K).max() < 1e-7 * scale, (stretch, H, K)
        if n == 1:  # rigid translation (W, U) = (1, 1): a zero mode at every λ
            assert np.abs(H @ [1.0, 1.0]).max() < 1e-7 * scale


def _root_cases():
    for material in _materials():
        for n in (0, 1, 2, 3, 4):
            for root in bifurcation_stretches(material, n):
                yield pytest.param(material, n, root, id=f"{material.name}-n{n}-{root:.4f}")


@pytest.mark.parametrize("material, n, root", list(_root_cases()))
def test_brute_force_condition_changes_sign_at_the_same_stretch(material, n, root):
    f = lambda lam: brute_force_condition(material, lam, n)  # noqa: E731
    assert f(root - 1e-6) * f(root + 1e-6) < 0
    brute_root = brentq(f, root - 1e-3, root + 1e-3, xtol=1e-13)
    assert abs(brute_root - root) < 1e-8, (brute_root, root)


def test_derivation_script_checks_pass():
    pytest.importorskip("sympy")
    script = ROOT / "docs" / "derivations" / "sphere_second_variation.py"
    result = subprocess.run([sys.executable, str(script), "2"], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert result.stdout.count("OK") == 4


# ---------------------------------------------------------------------------------------------------------------
# (b) n = 0 is the pressure extremum of the exact P(λ); n = 1 is the extremum of λP(λ) (stationary tension)


def _extrema(g, material, lam_max=10.0):
    """Zeros of the derivative of g(λ) (central differences), bracketed on a grid."""
    h = 1e-5
    dg = lambda lam: (g(material, lam + h) - g(material, lam - h)) / (2 * h)  # noqa: E731
    grid = np.geomspace(1.0 + 2 * h, lam_max, 2000)
    values = np.array([dg(x) for x in grid])
    return np.array([brentq(dg, a, b, xtol=1e-14) for a, b, fa, fb in zip(grid, grid[1:], values, values[1:])
                     if fa * fb < 0])


@pytest.mark.parametrize("material", _materials() + [get_preset("neo-Hookean"), get_preset("Mooney-Rivlin")],
                         ids=lambda m: m.name)
def test_n0_is_the_pressure_maximum(material):
    roots = bifurcation_stretches(material, 0)
    extrema = _extrema(sphere_pressure, material)
    assert len(roots) == len(extrema) >= 1
    np.testing.assert_allclose(roots, extrema, atol=1e-8)
    first = roots[0]  # the first one is the pressure maximum (the limit point under pressure control)
    assert sphere_pressure(material, first) > max(sphere_pressure(material, first + d) for d in (-1e-2, 1e-2))


@pytest.mark.parametrize("material", _materials() + [get_preset("neo-Hookean"), get_preset("Mooney-Rivlin")],
                         ids=lambda m: m.name)
def test_n1_is_the_stationary_membrane_tension(material):
    roots = bifurcation_stretches(material, 1)
    extrema = _extrema(lambda m, lam: lam * sphere_pressure(m, lam), material)
    assert len(roots) == len(extrema)
    np.testing.assert_allclose(roots, extrema, atol=1e-8)


def test_neo_hookean_values():
    """neo-Hookean: P = 4(λ⁻¹ − λ⁻⁷), maximum at λ = 7^(1/6); λP = 4(1 − λ⁻⁶) is monotone: no pear shape."""
    nh = get_preset("neo-Hookean")
    np.testing.assert_allclose(bifurcation_stretches(nh, 0), [7 ** (1 / 6)], rtol=1e-14)
    for n in range(1, 8):
        assert len(bifurcation_stretches(nh, n)) == 0


def test_mode_matrix_structure():
    m = get_preset("SPOM1")
    for n in range(6):
        K = mode_matrix(m, 2.0, n)
        assert K[0, 1] == K[1, 0]
    assert mode_matrix(m, 2.0, 0)[1].tolist() == [0.0, 0.0]
    K1 = mode_matrix(m, 2.0, 1)
    np.testing.assert_allclose(K1 @ [1.0, 1.0], 0.0, atol=1e-14 * np.abs(K1).max())
    assert np.trace(K1) == pytest.approx(bifurcation_condition(m, 2.0, 1), rel=1e-14)
    for n in range(2, 6):
        N = n * (n + 1)
        det = np.linalg.det(mode_matrix(m, 2.0, n))
        assert det == pytest.approx(N * (N - 2) * bifurcation_condition(m, 2.0, n), rel=1e-12)
    for lam in (1.0, 1.0 + 1e-9):  # the unstretched sphere is stable in every mode but translation
        for n in range(8):
            assert bifurcation_condition(m, lam, n) > 0
    with pytest.raises(ValueError):
        mode_matrix(m, 2.0, -1)
    with pytest.raises(ValueError):
        bifurcation_stretches(m, 1.5)


def test_close_root_pair_is_not_lost(monkeypatch):
    """A condition that dips through zero between two grid points still gives both roots: SPOM2's pear pair
    (λ ≈ 2.115, 2.435) on a 6-point grid, where the condition is positive at every grid point."""
    import balloon_cg.model.sphere_modes as sphere_modes

    m = get_preset("SPOM2")
    roots = bifurcation_stretches(m, 1)
    monkeypatch.setattr(sphere_modes, "_GRID_POINTS", 6)
    assert np.all(bifurcation_condition(m, np.geomspace(1, 10, 6), 1) > 0)
    np.testing.assert_allclose(bifurcation_stretches(m, 1), roots, atol=1e-13)


# ---------------------------------------------------------------------------------------------------------------
# (c) every preset: the pear (n = 1) and prolate/oblate (n = 2) bifurcations of the sphere in λ ∈ [1, 10].
# Regression values from the closed form (10 digits), each confirmed by the brute force above.

EXPECTED = {
    ("SPOM1", 0): ([1.3655005846, 6.5256316267], [2.5684644615, 0.6678408720]),
    ("SPOM1", 1): ([1.6798568821, 3.5739523842], [2.2647316688, 0.9147998725]),
    ("SPOM1", 2): ([], []),
    ("SPOM2", 0): ([1.3775206203, 7.2253904597], [2.5172446524, 0.8317625316]),
    ("SPOM2", 1): ([2.1152612007, 2.4346635022], [1.8437540370, 1.6008082031]),
    ("SPOM2", 2): ([], []),
    ("FPOM1", 0): ([1.3624669770, 8.1932531905], [2.5668129511, 0.4607627596]),
    ("FPOM1", 1): ([1.6512216947, 4.5332971206], [2.2880585882, 0.6262434318]),
    ("FPOM1", 2): ([], []),
    ("FPOM2", 0): ([1.3739101989, 9.4666193393], [2.5143984461, 0.5990016427]),
    ("FPOM2", 1): ([1.8879436213, 3.4755918175], [2.0347242792, 1.0635576916]),
    ("FPOM2", 2): ([], []),
    ("TPOM1", 0): ([1.3575430692], [2.5488344699]),
    ("TPOM1", 1): ([1.6205273191], [2.2963451725]),
    ("TPOM1", 2): ([2.6734111460], [1.1314909561]),
    ("TPOM2", 0): ([1.3816739420], [2.4796357520]),
    ("TPOM2", 1): ([2.6093643499], [1.5139067613]),
    ("TPOM2", 2): ([], []),
}


def test_preset_table(capsys):
    rows = []
    for name in PRESETS:
        material = get_preset(name)
        for n in (0, 1, 2):
            stretches, pressures = bifurcation_pressures(material, n)
            want_l, want_p = EXPECTED[(name, n)]
            np.testing.assert_allclose(stretches, want_l, atol=1e-9)
            np.testing.assert_allclose(pressures, want_p, atol=1e-9)
            rows.append(f"{name:6s} n={n}  " + "  ".join(f"λ={l:.10f} P={p:.10f}" for l, p in zip(stretches,
                                                                                                   pressures)))
        assert len(bifurcation_stretches(material, 3)) == 0  # no higher mode for the presets
    with capsys.disabled():
        print("\nsphere bifurcations, λ ∈ [1, 10]\n" + "\n".join(rows))
    # What the continuum condition gives: SPOM and FPOM have two pear points (an isola between them), TPOM one,
    # and TPOM's pear pressure decreases with α1 (the paper's statements); TPOM1 also has an n = 2 point.
    for name in ("SPOM1", "SPOM2", "FPOM1", "FPOM2"):
        assert len(EXPECTED[(name, 1)][0]) == 2
    for name in ("TPOM1", "TPOM2"):
        assert len(EXPECTED[(name, 1)][0]) == 1
    assert EXPECTED[("TPOM2", 1)][1][0] < EXPECTED[("TPOM1", 1)][1][0]
