"""Axisymmetric bifurcations of the pressurised sphere (any isotropic energy) at M = 0, from the continuum second variation.

An independent check on the Galerkin/Newton branch-point detection (derivation: docs/sphere_bifurcation.md,
SymPy verification: docs/derivations/sphere_second_variation.py). The sphere of radius λ under
P = 2Φ1/λ² is perturbed by a normal displacement w = W P_n(cos θ) and a tangential one u = U dP_n(cos θ)/dθ;
modes n decouple and the Hessian of E in (W, U), divided by ∫_0^π P_n(cos θ)² sin θ dθ = 2/(2n+1), is

    K_n = [[ 2S + (N − 4) t,   −N (S − t)                ],
           [ −N (S − t),        N ((N − 1) Φ11 + Φ12 − t) ]],

N = n(n+1), t = Φ1/λ (the true membrane tension), S = Φ11 + Φ12, all derivatives of Φ(λ1, λ2) at λ1 = λ2 = λ
(Φ1 = Φ2, Φ11 = Φ22 by isotropy). The bifurcation conditions (zeros of ``bifurcation_condition``):

- n = 0 (uniform inflation, a pressure-control limit point): K_0 = 2S − 4t = 0 ⇔ dP/dλ = 0;
- n = 1: K_1 = 2(S − t) [[1, −1], [−1, 1]] always has the rigid translation (W, U) = (1, 1) as a null vector; the
  other eigenvalue is tr K_1 = 4(S − t) and the pear-shaped bifurcation is S = t ⇔ d(Φ1/λ)/dλ = 0
  ⇔ d(λP)/dλ = 0 (the membrane tension t = λP/2 is stationary);
- n ≥ 2: det K_n = N(N − 2) Δ_n, Δ_n = Φ11² − Φ12² + t((N − 1)Φ11 + 3Φ12) − 2t² = 0.

Runtime module: numpy/scipy only.
"""
import numpy as np
from scipy.optimize import brentq, minimize_scalar

from .membrane import stretch_derivatives
from .sphere import sphere_pressure
from ..scene.energies import StrainEnergy

_GRID_POINTS = 4000


def sphere_derivatives(material, stretch):
    """(Φ1, Φ11, Φ12) of Φ(λ1, λ2) at λ1 = λ2 = stretch (scalar or array; Φ2 = Φ1, Φ22 = Φ11): Ogden in closed
    form, any other strain energy from its kernels (model/membrane.py)."""
    if isinstance(material, StrainEnergy):
        d = stretch_derivatives(material, stretch, stretch)
        values = d["phi_1"], d["phi_11"], d["phi_12"]
        return tuple(map(float, values)) if np.ndim(stretch) == 0 else values
    mu = np.asarray(material.mu, dtype=float)[:, None]
    alpha = np.asarray(material.alpha, dtype=float)[:, None]
    lam = np.atleast_1d(np.asarray(stretch, dtype=float))[None, :]
    phi1 = np.sum(mu * (lam ** (alpha - 1) - lam ** (-2 * alpha - 1)), axis=0)
    phi11 = np.sum(mu * ((alpha - 1) * lam ** (alpha - 2) + (alpha + 1) * lam ** (-2 * alpha - 2)), axis=0)
    phi12 = np.sum(mu * alpha * lam ** (-2 * alpha - 2), axis=0)
    if np.ndim(stretch) == 0:
        return float(phi1[0]), float(phi11[0]), float(phi12[0])
    return phi1, phi11, phi12


def mode_matrix(material, stretch, n):
    """K_n(λ): the Hessian of E in (W_n, U_n) about the sphere of radius ``stretch`` at its equilibrium
    pressure, divided by 2/(2n+1). For n = 0 the U row and column are zero (dP_0/dθ ≡ 0: no such mode)."""
    n = _mode(n)
    phi1, phi11, phi12 = sphere_derivatives(material, float(stretch))
    N = n * (n + 1)
    t = phi1 / stretch
    S = phi11 + phi12
    off = -N * (S - t)
    return np.array([[2 * S + (N - 4) * t, off], [off, N * ((N - 1) * phi11 + phi12 - t)]])


def bifurcation_condition(material, stretch, n):
    """The scalar whose zeros in λ are the mode-n bifurcations of the sphere (vectorised in ``stretch``):
    K_0 for n = 0, the non-translation eigenvalue tr K_1 = 4(S − t) for n = 1, Δ_n = det K_n / (N(N − 2))
    for n ≥ 2. Each is positive at λ = 1 (the unstretched sphere is stable) for the presets."""
    n = _mode(n)
    phi1, phi11, phi12 = sphere_derivatives(material, stretch)
    t = phi1 / np.asarray(stretch, dtype=float)
    S = phi11 + phi12
    if n == 0:
        return 2 * S - 4 * t
    if n == 1:
        return 4 * (S - t)
    N = n * (n + 1)
    return phi11**2 - phi12**2 + t * ((N - 1) * phi11 + 3 * phi12) - 2 * t**2


def bifurcation_stretches(material, n, lam_max=10.0, lam_min=1.0):
    """Sorted stretches λ in [lam_min, lam_max] where the mode-n condition vanishes (for n = 1 not the rigid
    translation, which is a zero mode at every λ). Sign changes on a fine geometric grid are refined by brentq
    (xtol 1e-14); interior extrema of the condition that dip through zero between grid points are split by a
    bounded minimisation first, so a close pair of roots is not lost. A tangential (double) zero that does not
    change sign is not reported."""
    n = _mode(n)
    if not 0 < lam_min < lam_max:
        raise ValueError(f"need 0 < lam_min < lam_max (got {lam_min}, {lam_max})")

    def f(lam):
        return float(bifurcation_condition(material, lam, n))

    points = np.geomspace(lam_min, lam_max, _GRID_POINTS)
    fvals = bifurcation_condition(material, points, n)
    # An interior extremum of f on the grid without a sign change around it may still cross zero between the
    # neighbouring grid points: replace the grid point by the extremum found by a bounded minimisation.
    for i in range(1, len(points) - 1):
        fl, fc, fr = fvals[i - 1], fvals[i], fvals[i + 1]
        if (fc - fl) * (fr - fc) < 0 and fl * fr > 0 and fc * fl > 0:
            sign = np.sign(fc)
            res = minimize_scalar(lambda x: sign * f(x), bounds=(points[i - 1], points[i + 1]), method="bounded",
                                  options={"xatol": 1e-15})
            if res.fun < 0:
                points[i], fvals[i] = res.x, sign * res.fun
    roots = []
    for a, b, fa, fb in zip(points[:-1], points[1:], fvals[:-1], fvals[1:]):
        if fa == 0.0:
            roots.append(a)
        elif fa * fb < 0:
            roots.append(brentq(f, a, b, xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=200))
    if fvals[-1] == 0.0:
        roots.append(points[-1])
    return np.array(sorted(roots))


def bifurcation_pressures(material, n, lam_max=10.0, lam_min=1.0):
    """(stretches, pressures) of the mode-n bifurcation points of the sphere in [lam_min, lam_max]."""
    stretches = bifurcation_stretches(material, n, lam_max=lam_max, lam_min=lam_min)
    pressures = sphere_pressure(material, stretches) if len(stretches) else np.empty(0)
    return stretches, np.asarray(pressures, dtype=float)


def _mode(n):
    if int(n) != n or n < 0:
        raise ValueError(f"mode n must be a non-negative integer (got {n!r})")
    return int(n)
