"""Legendre polynomials P_k(x) and their derivatives (the Galerkin bases: galerkin/discretisation.py, elements.py,
interval.py), the orthonormal associated Legendre functions P̄_k^j(cos θ) with their θ-derivatives: the azimuthal
perturbation bases (analysis/stability/azimuthal.py) and the spherical harmonics of the whole-sphere engine
(surface/basis.py); the Gauss–Legendre rules every discretisation integrates with."""
import functools

import numpy as np
from numpy.polynomial import legendre


@functools.lru_cache(maxsize=64)
def gauss_rule(n: int) -> tuple[np.ndarray, np.ndarray]:
    """(nodes, weights) of the n-node Gauss–Legendre rule on [−1, 1] (numpy's ``leggauss``: an O(n³) eigenvalue
    solve), computed once per n and shared read-only (a branch's points rebuild the same few rules)."""
    nodes, weights = legendre.leggauss(n)
    nodes.flags.writeable = weights.flags.writeable = False
    return nodes, weights


def legendre_table(x: np.ndarray, degree: int):
    """(P_k(x), P_k'(x)) for k = 0..degree, each of shape (len(x), degree + 1), by the three-term recurrence."""
    p = np.zeros((x.size, degree + 1))
    dp = np.zeros_like(p)
    p[:, 0] = 1.0
    if degree >= 1:
        p[:, 1] = x
        dp[:, 1] = 1.0
    for k in range(1, degree):
        p[:, k + 1] = ((2 * k + 1) * x * p[:, k] - k * p[:, k - 1]) / (k + 1)
        dp[:, k + 1] = dp[:, k - 1] + (2 * k + 1) * p[:, k]
    return p, dp


def legendre_values(x: np.ndarray, degree: int, order: int) -> np.ndarray:
    """P̄_k^order(x) for k = 0..degree (zero for k < order), shape (len(x), degree + 1); orthonormal on [−1, 1]
    (∫ P̄_k^j P̄_l^j dx = δ_kl), Condon–Shortley phase, stable three-term recurrence; valid at x = ±1."""
    x = np.asarray(x, dtype=float)
    s = np.sqrt(np.clip(1.0 - x * x, 0.0, None))
    p = np.zeros((x.size, degree + 1))
    j = order
    if j > degree:
        return p
    pjj = np.full(x.size, np.sqrt(0.5))
    for i in range(1, j + 1):
        pjj = -np.sqrt((2 * i + 1) / (2 * i)) * s * pjj
    p[:, j] = pjj
    if j + 1 <= degree:
        p[:, j + 1] = np.sqrt(2 * j + 3) * x * pjj
    for k in range(j + 2, degree + 1):
        a = np.sqrt((4 * k * k - 1) / (k * k - j * j))
        b = np.sqrt(((k - 1) ** 2 - j * j) / (4 * (k - 1) ** 2 - 1))
        p[:, k] = a * (x * p[:, k - 1] - b * p[:, k - 2])
    return p


def assoc_legendre(x: np.ndarray, degree: int, order: int):
    """(P̄_k^order(x), dP̄_k^order/dθ) for k = 0..degree at interior points x = cos θ ∈ (−1, 1), using
    dP_k^j/dθ = (k x P_k^j − (k + j) P_{k−1}^j)/sin θ (normalised)."""
    x = np.asarray(x, dtype=float)
    p = legendre_values(x, degree, order)
    dp = np.zeros_like(p)
    s = np.sqrt(1.0 - x * x)
    for k in range(order, degree + 1):
        c = np.sqrt((k * k - order * order) * (2 * k + 1) / (2 * k - 1)) if k > order else 0.0
        previous = p[:, k - 1] if k > order else 0.0
        dp[:, k] = (k * x * p[:, k] - c * previous) / s
    return p, dp


def theta_derivative(x: np.ndarray, degree: int, order: int) -> np.ndarray:
    """dP̄_k^order/dθ for k = 0..degree at any x = cos θ ∈ [−1, 1] (the poles included), from the neighbouring
    orders: ½[√((k − j)(k + j + 1)) P̄_k^{j+1} − √((k + j)(k − j + 1)) P̄_k^{j−1}], and √(k(k + 1)) P̄_k^1 for
    j = 0 (Condon–Shortley phase, as ``legendre_values``)."""
    k = np.arange(degree + 1)
    up = legendre_values(x, degree, order + 1)
    if order == 0:
        return np.sqrt(k * (k + 1.0)) * up
    down = legendre_values(x, degree, order - 1)
    j = order
    out = 0.5 * (np.sqrt(np.clip((k - j) * (k + j + 1.0), 0.0, None)) * up
                 - np.sqrt(np.clip((k + j) * (k - j + 1.0), 0.0, None)) * down)
    out[:, k < j] = 0.0
    return out
