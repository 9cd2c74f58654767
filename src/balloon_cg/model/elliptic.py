"""Complete elliptic integrals K(m), E(m) of parameter m by the arithmetic–geometric mean.

    K(m) = ∫_0^{π/2} (1 − m sin²t)^{-1/2} dt,   E(m) = ∫_0^{π/2} (1 − m sin²t)^{1/2} dt,   0 ≤ m < 1.

With a_0 = 1, b_0 = √(1 − m), c_0² = m and a_{n+1} = (a_n + b_n)/2, b_{n+1} = √(a_n b_n),
c_{n+1} = c_n² / (4 a_{n+1})  (= (a_n − b_n)/2, written without cancellation):

    K = π / (2 a_∞),   E = K (1 − Σ_{n≥0} 2^{n−1} c_n²) = K (1 − m/2 − T),   T = Σ_{n≥1} 2^{n−1} c_n²

(Abramowitz & Stegun 17.6). Convergence is quadratic (machine precision in ≤ 10 steps even for 1 − m = 1e-300).
E = K (1 − m/2 − T) loses ~log10(K) digits to cancellation as m → 1; (1 − m/2) K − E = K T never cancels.
"""
import math

from numba import njit

_MAX_STEPS = 40


@njit(cache=True)
def _agm(m, m1):
    """(K, T) with T = Σ_{n≥1} 2^{n−1} c_n², so that E = K (1 − m/2 − T); NaN unless 0 ≤ m and m1 > 0."""
    if not (m >= 0.0 and m1 > 0.0):
        return math.nan, math.nan
    a = 1.0
    b = math.sqrt(m1)
    c2 = m
    weight = 0.5
    total = 0.0
    for _ in range(_MAX_STEPS):
        a_next = 0.5 * (a + b)
        b = math.sqrt(a * b)
        c2 = (c2 / (4.0 * a_next)) ** 2
        a = a_next
        weight *= 2.0
        total += weight * c2
        if c2 <= 1e-36 * a * a:
            break
    return 0.5 * math.pi / a, total


@njit(cache=True)
def complete_elliptic(m, m1=None):
    """(K(m), E(m)) for 0 ≤ m < 1, NaN outside. ``m1`` = 1 − m may be given when the caller knows it to full
    relative precision (near m = 1, where K ≈ ln(4/√m1) and rounding 1 − m would cost digits)."""
    if m1 is None:
        k, t = _agm(m, 1.0 - m)
    else:
        k, t = _agm(m, m1)
    return k, k * (1.0 - 0.5 * m - t)


@njit(cache=True)
def loop_elliptic(m, m1):
    """(K(m), N(m)) with N = (1 − m/2) K − E = K Σ_{n≥1} 2^{n−1} c_n², m1 = 1 − m: N is a sum of positive
    terms, so it keeps full relative precision where forming (1 − m/2) K − E from K and E would cancel
    (N = π m²/32 + O(m³)). N/m² is the loop's stream-function shape G (balloon_cg.field)."""
    k, t = _agm(m, m1)
    return k, k * t
