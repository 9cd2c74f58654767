"""The capsule's piecewise basis: three spectral elements, north cap | cylinder | south cap, joined C⁰ at the joins.

A capsule's reference curvature jumps at its joins x = ±c (c = cos θj, θj = π/(2κ)), so λ2 and η are only C¹ and C²
there and one Legendre series in x = cos θ converges algebraically (O(N⁻³): docs/shapes.md). On each element the
solution is analytic, so a basis that is polynomial per element and continuous across the joins (conforming for the
Ritz energy, which holds first derivatives only) converges spectrally. The elements' coordinates:

    caps       ξ = (2|x| − 1 − c)/(1 − c) ∈ [−1, 1] (linear in x: smooth at the pole, λ2 and η even in θ there),
    cylinder   ξ = (π/2 − θ)/(π/2 − θj) ∈ [−1, 1] (linear in the arclength S = κθ: a polynomial in x would have
               the branch point of θ = acos x just beyond the join, at x = ±1).

The basis is hierarchical (the functions of degree N are the first N + 1 of every higher degree, so transfers to a
higher degree append zeros) and φ_k has the parity (−1)^k in x (the equator symmetry keeps φ_even for λ2 and φ_odd
for η, the reflection z → −z is a_k → (−1)^k a_k as on the Legendre basis):

    φ_0 = 1,   φ_1 = ℓ (ξ on the cylinder, ±1 on the caps),
    then, alternately even and odd, a cylinder bubble B_j = P_j(ξ) − P_{j−2}(ξ) (j ≥ 2, zero on the caps, parity
    (−1)^j) or a cap pair q_j(ξ_north) ± q_j(ξ_south), q_j = P_j + P_{j−1} (j ≥ 1, zero at the joins, + even, − odd),

the element chosen greedily (``sequence``) to keep the polynomial degree per radian of θ (per arclength) alike on the
cylinder (degree j over π − 2θj) and on the caps (degree j in x, 2j in θ over the cap and its mirror, 2θj), the caps
keeping at least half the cylinder's degree up to CAP_FLOOR. Every continuous piecewise polynomial is spanned (1 and
ℓ match any values at the joins; what is left vanishes there). φ_0 = 1 keeps b_0 the rigid translation. The
cylinder's quadrature is Gauss in θ (galerkin/discretisation.py ``split_rule``).
"""
import functools

import numpy as np

from .legendre import legendre_table

CONSTANT, HAT, CYLINDER, CAPS = range(4)  # the families of ``sequence``
# the caps keep at least half the cylinder's degree up to this one, beyond it by arclength: by arclength alone a
# capsule of length 40 gives its caps degree 6 of 162, and the layer where the caps meet the cylinder (about 0.1
# radii wide at 1.5 % hoop strain) is not resolved: its start's pressure is 2.6e-5 off at degree 162 with caps of
# degree 6, 1e-7 with 12, 3.7e-10 with 16, 2e-14 with 24
CAP_FLOOR = 24


@functools.lru_cache(maxsize=32)
def sequence(degree: int, join: float) -> tuple:
    """(family, j) of φ_0..φ_degree for the join x = c (module docstring): (CONSTANT, 0), (HAT, 1), then per parity
    the caps while their next degree is at most min(CAP_FLOOR, half the cylinder's next), else the family with the
    lower degree per radian once the function is added, the caps on a tie."""
    theta_j = float(np.arccos(join))
    cylinder_span, cap_span = np.pi - 2 * theta_j, 2 * theta_j
    out = [(CONSTANT, 0), (HAT, 1)][: degree + 1]
    cylinder = {0: 2, 1: 3}  # the next bubble's degree of each parity
    caps = {0: 1, 1: 1}  # the next cap pair's degree of each parity
    for k in range(2, degree + 1):
        parity = k % 2
        floor = min(CAP_FLOOR, cylinder[parity] / 2)
        if caps[parity] > floor and cylinder[parity] / cylinder_span < 2 * caps[parity] / cap_span:
            out.append((CYLINDER, cylinder[parity]))
            cylinder[parity] += 2
        else:
            out.append((CAPS, caps[parity]))
            caps[parity] += 1
    return tuple(out)


def families(degree: int, join: float) -> tuple:
    """(cylinder, caps): the indices k of the cylinder's bubbles in the order of their degree, and of the caps' pairs
    as (even, odd) columns per degree j (rows, shape (n, 2); the last degree's odd one repeats its even one when
    it is not there yet): the elements' own coefficient series, whose tails ``Discretisation.tail`` reads."""
    order = sequence(degree, join)
    cylinder = [k for k, (family, _) in sorted(enumerate(order), key=lambda item: item[1][1]) if family == CYLINDER]
    even = [k for k, (family, _) in enumerate(order) if family == CAPS and k % 2 == 0]
    odd = [k for k, (family, _) in enumerate(order) if family == CAPS and k % 2 == 1]
    pairs = [(e, odd[j] if j < len(odd) else e) for j, e in enumerate(even)]
    return np.array(cylinder, dtype=int), np.array(pairs, dtype=int).reshape(-1, 2)


def element_table(x: np.ndarray, degree: int, join: float):
    """(φ_k(x), dφ_k/dx) for k = 0..degree, each of shape (len(x), degree + 1), at any x ∈ [−1, 1] (the joins
    belong to the cylinder: φ is continuous there, its derivative the cylinder's)."""
    x = np.asarray(x, dtype=float)
    order = sequence(degree, join)
    theta_j = np.arccos(join)
    cylinder = np.abs(x) <= join
    north = x > join
    side = np.where(north, 1.0, -1.0)  # which cap (on the cylinder unused)
    theta = np.arccos(np.clip(x, -1.0, 1.0))
    xi_cylinder = np.where(cylinder, (0.5 * np.pi - theta) / (0.5 * np.pi - theta_j), 0.0)
    # dξ/dx = 1/((π/2 − θj) sin θ) on the cylinder (sin θ ≥ sin θj > 0 there)
    dxi_cylinder = np.where(cylinder, 1.0 / ((0.5 * np.pi - theta_j) * np.sqrt(np.maximum(1.0 - x * x, 1e-300))), 0.0)
    xi_cap = np.where(cylinder, 0.0, (2.0 * np.abs(x) - 1.0 - join) / (1.0 - join))
    dxi_cap = 2.0 * side / (1.0 - join)  # dξ/dx of the cap the node is on
    top = max(j for _, j in order) + 1
    pc, dpc = legendre_table(xi_cylinder, top)
    pq, dpq = legendre_table(xi_cap, top)
    p, dp = np.zeros((x.size, degree + 1)), np.zeros((x.size, degree + 1))
    for k, (family, j) in enumerate(order):
        if family == CONSTANT:
            p[:, k] = 1.0
        elif family == HAT:
            p[:, k] = np.where(cylinder, xi_cylinder, side)
            dp[:, k] = np.where(cylinder, dxi_cylinder, 0.0)
        elif family == CYLINDER:
            p[:, k] = np.where(cylinder, pc[:, j] - pc[:, j - 2], 0.0)
            dp[:, k] = np.where(cylinder, (dpc[:, j] - dpc[:, j - 2]) * dxi_cylinder, 0.0)
        else:
            sign = np.where(north, 1.0, (-1.0) ** k)  # the south cap's copy: + for even k, − for odd
            p[:, k] = np.where(cylinder, 0.0, sign * (pq[:, j] + pq[:, j - 1]))
            dp[:, k] = np.where(cylinder, 0.0, sign * (dpq[:, j] + dpq[:, j - 1]) * dxi_cap)
    return p, dp


def element_series(coefficients: np.ndarray, join: float) -> tuple:
    """(north cap, cylinder, south cap): the function Σ_k c_k φ_k (k = 0..len − 1) as one Legendre series in each
    element's own ξ (module docstring; the south cap's ξ runs from its join, −1, to its pole, +1, as the north's):

        1 → 1 on each,   ℓ → (1, ξ, −1),   B_j → (0, P_j − P_{j−2}, 0),   q_j pair → (q_j, 0, (−1)^k q_j),

    so that numpy's Legendre series calculus gives any derivative in ξ (the curvatures, post/quantities.py)."""
    order = sequence(len(coefficients) - 1, join)
    top = max(j for _, j in order) + 1
    north, cylinder, south = np.zeros(top), np.zeros(top), np.zeros(top)
    for k, ((family, j), c) in enumerate(zip(order, coefficients)):
        if family == CONSTANT:
            north[0] += c
            cylinder[0] += c
            south[0] += c
        elif family == HAT:
            north[0] += c
            cylinder[1] += c
            south[0] -= c
        elif family == CYLINDER:
            cylinder[j] += c
            cylinder[j - 2] -= c
        else:
            for series, sign in ((north, 1.0), (south, (-1.0) ** k)):
                series[j] += sign * c
                series[j - 1] += sign * c
    return north, cylinder, south
