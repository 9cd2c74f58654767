"""The capsule's piecewise basis: spectral elements north cap | cylinder elements | south cap, joined C⁰ at the joins.

A capsule's reference curvature jumps at its caps' joins x = ±c (c = cos θj, θj = π/(2κ)), so λ2 and η are only C¹
and C² there and one Legendre series in x = cos θ converges algebraically (O(N⁻³): docs/shapes.md). On each element
the solution is analytic, so a basis that is polynomial per element and continuous across the joins (conforming for
the Ritz energy, which holds first derivatives only) converges spectrally. The cylinder is cut into n elements of
equal arclength (model/meridian.joins: a long cylinder's bulge fronts want an element a few radii long, not one
polynomial over its whole length); ``joins`` are all the element boundaries in x, ascending, −c first and c last,
mirror-symmetric. The elements' coordinates:

    caps       ξ = (2|x| − 1 − c)/(1 − c) ∈ [−1, 1] (linear in x: smooth at the pole, λ2 and η even in θ there),
    cylinder   ξ = (π/2 − θ)/(π/2 − θj) ∈ [−1, 1] (linear in the arclength S = κθ: a polynomial in x would have
               the branch point of θ = acos x just beyond the join, at x = ±1), element e (e = 0..n−1, ascending in
               x) between ξ_e = (2e − n)/n and ξ_{e+1}, its own t = (2ξ − ξ_e − ξ_{e+1})/(ξ_{e+1} − ξ_e) ∈ [−1, 1].

The basis is hierarchical (the functions of degree N are the first N + 1 of every higher degree, so transfers to a
higher degree append zeros) and φ_k has the parity (−1)^k in x (the equator symmetry keeps φ_even for λ2 and φ_odd
for η, the reflection z → −z is a_k → (−1)^k a_k as on the Legendre basis):

    φ_0 = 1,   φ_1 = ℓ (ξ on the cylinder, ±1 on the caps),
    the hats h_i of the cylinder's inner boundaries ξ_i (piecewise linear, 1 at ξ_i, 0 at ξ_{i±1}) as mirror pairs
    h_i ± h_{n−i} (i > n/2; the middle one, i = n/2, even alone),
    then, alternately even and odd, a cylinder bubble B_j = P_j(t) − P_{j−2}(t) (j ≥ 2, zero off its element) on a
    mirror pair of elements, B_j(t_e) ± (−1)^j B_j(t_{n−1−e}) (the middle element of an odd n alone: parity (−1)^j),
    or a cap pair q_j(ξ_north) ± q_j(ξ_south), q_j = P_j + P_{j−1} (j ≥ 1, zero at the joins, + even, − odd),

the element chosen greedily (``sequence``) to keep the polynomial degree per radian of θ (per arclength) alike on
every cylinder element (degree j over (π − 2θj)/n) and on the caps (degree j in x, 2j in θ over the cap and its
mirror, 2θj), the caps keeping at least half the degree of the cylinder's bubbles up to CAP_FLOOR. Every continuous
piecewise polynomial is spanned (1, ℓ and the hats match any values at the joins; what is left vanishes there).
φ_0 = 1 keeps b_0 the rigid translation. The cylinder's quadrature is Gauss in θ (galerkin/discretisation.py
``split_rule``). With n = 1 (joins ±c) the basis is the three elements north cap | cylinder | south cap.
"""
import functools
from dataclasses import dataclass

import numpy as np

from .legendre import legendre_table

CONSTANT, HAT, VERTEX, CYLINDER, CAPS = range(5)  # the families of ``sequence``
CAPS_GROUP = -1  # the caps' entry in ``groups``
# the caps keep at least half the cylinder's degree up to this one, beyond it by arclength: by arclength alone a
# capsule of length 40 gives its caps degree 6 of 162, and the layer where the caps meet the cylinder (about 0.1
# radii wide at 1.5 % hoop strain) is not resolved: its start's pressure is 2.6e-5 off at degree 162 with caps of
# degree 6, 1e-7 with 12, 3.7e-10 with 16, 2e-14 with 24
CAP_FLOOR = 24


@dataclass(frozen=True)
class Layout:
    """The elements of ``joins``: the caps' join c, the cylinder's half span π/2 − θj in θ, and its n elements'
    bounds ξ_0 = −1 < ξ_1 < … < ξ_n = 1 in the cylinder's ξ (module docstring)."""

    join: float
    half_span: float
    bounds: tuple

    @property
    def count(self) -> int:
        return len(self.bounds) - 1

    def mirror(self, element: int) -> int:
        return self.count - 1 - element


@functools.lru_cache(maxsize=32)
def layout(joins: tuple) -> Layout:
    """The Layout of ascending ``joins`` (−c, inner cylinder boundaries, c): ξ_e = (2e − n)/n, exactly
    antisymmetric (model/meridian.joins puts the inner boundaries at x = sin(ξ_e (π/2 − θj)))."""
    join = float(joins[-1])
    n = len(joins) - 1
    return Layout(join, 0.5 * np.pi - float(np.arccos(join)), tuple((2 * e - n) / n for e in range(n + 1)))


@functools.lru_cache(maxsize=64)
def sequence(degree: int, joins: tuple, degrees: tuple = ()) -> tuple:
    """(family, j, element) of φ_0..φ_degree for ``joins``: ``graded_sequence`` of ``degrees`` (one per element
    group) if given, else the greedy order (module docstring): (CONSTANT, 0, 0), (HAT, 1, 0), the
    inner boundaries' hats (VERTEX, 1, i) of each parity while there are any, then per parity the caps while their
    next degree is at most min(CAP_FLOOR, half the cylinder elements' next), else the family with the lower degree
    per radian once the function is added, the caps on a tie (the cylinder's degree in the floor: that of one
    element holding all its bubbles of the parity so far, so that the caps' floor does not fall with n); a bubble (CYLINDER, j, e) names the northern
    element e of its mirror pair (the middle element of an odd n its own mirror)."""
    if degrees:
        order = graded_sequence(degrees, joins)
        if len(order) != degree + 1:
            raise ValueError(f"element degrees {degrees}: {len(order)} functions, not degree + 1 = {degree + 1}")
        return order
    shape = layout(joins)
    n, theta_j = shape.count, 0.5 * np.pi - shape.half_span
    element_span, cap_span = (np.pi - 2 * theta_j) / n, 2 * theta_j
    out = [(CONSTANT, 0, 0), (HAT, 1, 0)][: degree + 1]
    # the northern inner boundary of each mirror pair of hats, from the middle outwards (the middle one even only)
    vertices = {0: list(range((n + 1) // 2, n)), 1: list(range(n // 2 + 1, n))}
    elements = list(range(n // 2, n))  # the northern element of each mirror pair, from the middle outwards
    step = {e: 2 if shape.mirror(e) == e else 1 for e in elements}
    cylinder = {e: {0: 2, 1: 3 if step[e] == 2 else 2} for e in elements}  # the next bubble's degree per parity
    caps = {0: 1, 1: 1}  # the next cap pair's degree of each parity
    # the next degree of one cylinder element holding the cylinder's bubbles of each parity so far (the caps'
    # floor: the layer where they meet the cylinder wants it whatever the cylinder's elements)
    whole = {0: 2, 1: 3}
    for k in range(2, degree + 1):
        parity = k % 2
        if vertices[parity]:
            out.append((VERTEX, 1, vertices[parity].pop(0)))
            continue
        e = min(elements, key=lambda element: cylinder[element][parity])
        floor = min(CAP_FLOOR, whole[parity] / 2)
        if caps[parity] > floor and cylinder[e][parity] / element_span < 2 * caps[parity] / cap_span:
            out.append((CYLINDER, cylinder[e][parity], e))
            cylinder[e][parity] += step[e]
            whole[parity] += 2
        else:
            out.append((CAPS, caps[parity], 0))
            caps[parity] += 1
    return tuple(out)


def element_degree(degree: int, joins: tuple, degrees: tuple = ()) -> int:
    """The highest polynomial degree of any element at basis degree N (the caps' in x, a cylinder element's in θ):
    what each piece's quadrature must integrate (galerkin/discretisation.py ``piece_nodes``)."""
    return max(j for _, j, _ in sequence(degree, joins, degrees))


def groups(joins: tuple) -> tuple:
    """The element groups of ``joins``, each one degree of a graded basis: the northern element e of each mirror
    pair of cylinder elements from the middle outwards (the middle element of an odd n its own mirror), then the
    caps (CAPS_GROUP) — the order of ``families``."""
    shape = layout(joins)
    return (*range(shape.count // 2, shape.count), CAPS_GROUP)


def group_degrees(degree: int, joins: tuple, degrees: tuple = ()) -> tuple:
    """Per element group (``groups``) the highest degree j of its functions at basis degree N: a cylinder group's
    bubbles (1 without any: the hats' lines), the caps' pairs (0 without any)."""
    top = {group: (0 if group == CAPS_GROUP else 1) for group in groups(joins)}
    for family, j, e in sequence(degree, joins, degrees):
        group = CAPS_GROUP if family == CAPS else e if family == CYLINDER else None
        if group is not None:
            top[group] = max(top[group], j)
    return tuple(top[group] for group in groups(joins))


def piece_degrees(joins: tuple, degrees: tuple) -> tuple:
    """The degree of each piece of the quadrature (ascending in x: the south cap, cylinder elements 0..n − 1, the
    north cap) on the graded basis of ``degrees`` per group (``groups``; an element's its mirror pair's)."""
    shape = layout(joins)
    of = dict(zip(groups(joins), degrees))
    cylinder = tuple(of[max(e, shape.mirror(e))] for e in range(shape.count))
    return (of[CAPS_GROUP], *cylinder, of[CAPS_GROUP])


@functools.lru_cache(maxsize=64)
def graded_sequence(degrees: tuple, joins: tuple) -> tuple:
    """(family, j, element) of a basis with a degree per element group (``groups``): φ_0 = 1, φ_1 = ℓ, the inner
    boundaries' hats, then every bubble j = 2..d_e of each cylinder group (both parities on a mirror pair, (−1)^j on
    the middle element) and every cap pair j = 1..d_caps (both parities), ordered by j and then by group within
    each parity and interleaved so that φ_k has the parity (−1)^k. The counts of the two parities differ by at most
    one (1 and ℓ, the hats and the pairs balance; the middle element's B_j alternate, from j = 2), so the layout is
    that of every other basis (a_even, b_odd, the reflection signs). A graded basis holds another one's functions
    when its degrees are at least the other's per group (``Discretisation.nests_in``): transfers permute."""
    shape = layout(joins)
    names = groups(joins)
    if len(degrees) != len(names):
        raise ValueError(f"element degrees {degrees}: one per element group, {len(names)} for {len(joins) - 1} "
                         "cylinder elements and the caps")
    n = shape.count
    by_parity = {0: [(VERTEX, 1, i) for i in range((n + 1) // 2, n)], 1: [(VERTEX, 1, i) for i in range(n // 2 + 1, n)]}
    rest = {0: [], 1: []}
    for group, top in zip(names, degrees):
        if group == CAPS_GROUP:
            rest[0] += [(j, len(names), (CAPS, j, 0)) for j in range(1, top + 1)]
            rest[1] += [(j, len(names), (CAPS, j, 0)) for j in range(1, top + 1)]
        for j in range(2, top + 1) if group != CAPS_GROUP else ():
            parities = (j % 2,) if shape.mirror(group) == group else (0, 1)
            for parity in parities:
                rest[parity].append((j, group, (CYLINDER, j, group)))
    for parity in (0, 1):
        by_parity[parity] += [function for *_, function in sorted(rest[parity])]
    even, odd = by_parity[0], by_parity[1]
    out = [(CONSTANT, 0, 0), (HAT, 1, 0)]
    for k in range(len(even) + len(odd)):
        out.append((even if k % 2 == 0 else odd)[k // 2])
    return tuple(out)


def _pairs(indices: list) -> np.ndarray:
    """Rows (even, odd) of the k of one element group's functions per degree j, given as (k, j) in order; a degree
    whose odd function is not there yet repeats its even one (and the reverse)."""
    by_degree = {}
    for k, j in indices:
        by_degree.setdefault(j, [None, None])[k % 2] = k
    rows = [(even if even is not None else odd, odd if odd is not None else even)
            for _, (even, odd) in sorted(by_degree.items())]
    return np.array(rows, dtype=int).reshape(-1, 2)


def graded_degree(degrees: tuple, joins: tuple) -> int:
    """The basis degree N (N + 1 functions) of the graded basis with ``degrees`` per element group."""
    return len(graded_sequence(degrees, joins)) - 1


@functools.lru_cache(maxsize=64)
def function_keys(degree: int, joins: tuple, degrees: tuple = ()) -> tuple:
    """(family, j, element, parity) of φ_0..φ_degree: what names a function whatever its place in the order (a mirror
    pair's bubble and a cap pair come once per parity), so that one basis's functions are found in another's."""
    return tuple((family, j, e, k % 2) for k, (family, j, e) in enumerate(sequence(degree, joins, degrees)))


def families(degree: int, joins: tuple, degrees: tuple = ()) -> tuple:
    """The elements' own coefficient series, whose tails ``Discretisation.tail`` reads: per cylinder group the
    indices k of its bubbles in the order of their degree (the middle element of an odd n: one column) or as
    (even, odd) rows per degree j (a mirror pair of elements), and the caps' pairs as (even, odd) rows per j."""
    order = sequence(degree, joins, degrees)
    shape = layout(joins)
    series = []
    for e in range(shape.count // 2, shape.count):
        bubbles = [(k, j) for k, (family, j, element) in enumerate(order) if family == CYLINDER and element == e]
        if shape.mirror(e) == e:
            series.append(np.array([k for k, _ in sorted(bubbles, key=lambda item: item[1])], dtype=int))
        else:
            series.append(_pairs(bubbles))
    series.append(_pairs([(k, j) for k, (family, j, _) in enumerate(order) if family == CAPS]))
    return tuple(series)


def cylinder_coordinates(x: np.ndarray, shape: Layout):
    """(element e, t, dt/dx) at cylinder nodes x (module docstring; at an inner boundary the northern element)."""
    theta = np.arccos(np.clip(x, -1.0, 1.0))
    xi = (0.5 * np.pi - theta) / shape.half_span
    bounds = np.array(shape.bounds)
    element = np.clip(np.searchsorted(bounds, xi, side="right") - 1, 0, shape.count - 1)
    low, high = bounds[element], bounds[element + 1]
    # dξ/dx = 1/((π/2 − θj) sin θ) on the cylinder (sin θ ≥ sin θj > 0 there)
    dxi = 1.0 / (shape.half_span * np.sqrt(np.maximum(1.0 - x * x, 1e-300)))
    return element, (2.0 * xi - (low + high)) / (high - low), 2.0 / (high - low) * dxi


def element_table(x: np.ndarray, degree: int, joins: tuple, degrees: tuple = ()):
    """(φ_k(x), dφ_k/dx) for k = 0..degree, each of shape (len(x), degree + 1), at any x ∈ [−1, 1] (the caps'
    joins belong to the cylinder, an inner boundary to its northern element: φ is continuous there, its
    derivative that element's)."""
    x = np.asarray(x, dtype=float)
    order = sequence(degree, joins, degrees)
    shape = layout(joins)
    join = shape.join
    cylinder = np.abs(x) <= join
    north = x > join
    side = np.where(north, 1.0, -1.0)  # which cap (on the cylinder unused)
    element, t, dt = cylinder_coordinates(np.where(cylinder, x, 0.0), shape)
    element = np.where(cylinder, element, -1)
    xi_cylinder = np.where(cylinder, (0.5 * np.pi - np.arccos(np.clip(x, -1.0, 1.0))) / shape.half_span, 0.0)
    dxi_cylinder = np.where(cylinder, 1.0 / (shape.half_span * np.sqrt(np.maximum(1.0 - x * x, 1e-300))), 0.0)
    t, dt = np.where(cylinder, t, 0.0), np.where(cylinder, dt, 0.0)
    xi_cap = np.where(cylinder, 0.0, (2.0 * np.abs(x) - 1.0 - join) / (1.0 - join))
    dxi_cap = 2.0 * side / (1.0 - join)  # dξ/dx of the cap the node is on
    top = max(j for _, j, _ in order) + 1
    pc, dpc = legendre_table(t, top)
    pq, dpq = legendre_table(xi_cap, top)
    p, dp = np.zeros((x.size, degree + 1)), np.zeros((x.size, degree + 1))

    def hat(i):
        """The hat of inner boundary ξ_i and its dx-derivative: (1 + t)/2 on element i − 1, (1 − t)/2 on i."""
        below, above = element == i - 1, element == i
        return (np.where(below, 0.5 * (1 + t), 0.0) + np.where(above, 0.5 * (1 - t), 0.0),
                np.where(below, 0.5 * dt, 0.0) - np.where(above, 0.5 * dt, 0.0))

    for k, (family, j, e) in enumerate(order):
        sign = (-1.0) ** k
        if family == CONSTANT:
            p[:, k] = 1.0
        elif family == HAT:
            p[:, k] = np.where(cylinder, xi_cylinder, side)
            dp[:, k] = dxi_cylinder
        elif family == VERTEX:
            p[:, k], dp[:, k] = hat(e)
            if shape.count - e != e:
                mirrored, slope = hat(shape.count - e)
                p[:, k] += sign * mirrored
                dp[:, k] += sign * slope
        elif family == CYLINDER:
            weight = np.where(element == e, 1.0, 0.0)
            if shape.mirror(e) != e:  # B_j(t_e) + (−1)^(k+j) B_j(t_mirror): parity (−1)^k
                weight = weight + np.where(element == shape.mirror(e), sign * (-1.0) ** j, 0.0)
            p[:, k] = weight * (pc[:, j] - pc[:, j - 2])
            dp[:, k] = weight * (dpc[:, j] - dpc[:, j - 2]) * dt
        else:
            cap_sign = np.where(north, 1.0, sign)  # the south cap's copy: + for even k, − for odd
            p[:, k] = np.where(cylinder, 0.0, cap_sign * (pq[:, j] + pq[:, j - 1]))
            dp[:, k] = np.where(cylinder, 0.0, cap_sign * (dpq[:, j] + dpq[:, j - 1]) * dxi_cap)
    return p, dp


def element_series(coefficients: np.ndarray, joins: tuple, degrees: tuple = ()) -> tuple:
    """(north cap, cylinder elements, south cap): the function Σ_k c_k φ_k (k = 0..len − 1) as one Legendre series
    in each element's own coordinate (module docstring; the south cap's ξ runs from its join, −1, to its pole, +1,
    as the north's; the cylinder's (n, top) rows ascending in x, each in its own t):

        1 → 1 on each,   ℓ → (1, ξ_mid + t Δξ/2, −1),   hat h_i → (1 + t)/2 on e = i − 1, (1 − t)/2 on e = i,
        bubble → ±(P_j − P_{j−2}) on its elements,   q_j pair → (q_j, 0, (−1)^k q_j),

    so that numpy's Legendre series calculus gives any derivative (the curvatures, post/quantities.py)."""
    order = sequence(len(coefficients) - 1, joins, degrees)
    shape = layout(joins)
    top = max(j for _, j, _ in order) + 1
    north, south, cylinder = np.zeros(top), np.zeros(top), np.zeros((shape.count, top))
    bounds = np.array(shape.bounds)
    middle, half = 0.5 * (bounds[1:] + bounds[:-1]), 0.5 * (bounds[1:] - bounds[:-1])

    def add_hat(i, c):
        cylinder[i - 1, :2] += (0.5 * c, 0.5 * c)
        cylinder[i, :2] += (0.5 * c, -0.5 * c)

    for k, ((family, j, e), c) in enumerate(zip(order, coefficients)):
        sign = (-1.0) ** k
        if family == CONSTANT:
            north[0] += c
            south[0] += c
            cylinder[:, 0] += c
        elif family == HAT:
            north[0] += c
            south[0] -= c
            cylinder[:, 0] += c * middle
            cylinder[:, 1] += c * half
        elif family == VERTEX:
            add_hat(e, c)
            if shape.count - e != e:
                add_hat(shape.count - e, sign * c)
        elif family == CYLINDER:
            mirrored = [(shape.mirror(e), sign * (-1.0) ** j)] if shape.mirror(e) != e else []
            for element, weight in [(e, 1.0), *mirrored]:
                cylinder[element, j] += weight * c
                cylinder[element, j - 2] -= weight * c
        else:
            for series, cap_sign in ((north, 1.0), (south, sign)):
                series[j] += cap_sign * c
                series[j - 1] += cap_sign * c
    return north, cylinder, south
