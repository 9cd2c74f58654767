"""The m ≥ 1 perturbation basis of a capsule: spectral elements north cap | cylinder elements | south cap, C⁰ joined.

The sphere's basis (analysis/stability/azimuthal.py) expands U = R + T, D = R − T and Z in associated Legendre
functions of cos θ, smooth on the sphere and for m ≥ 1 regular at the poles: U ∈ sin^(m+1)θ · C^∞,
D ∈ sin^(m−1)θ · C^∞, Z ∈ sin^m θ · C^∞. A capsule's perturbations are smooth on each piece only (its reference
curvature jumps at the joins, as its states' second derivatives do: galerkin/elements.py), so each field is expanded
per element, the elements joined continuously (the energy holds first derivatives only: conforming):

    caps       F = sin^j ψ · P̂_k^(j,0)(2 cos ψ − 1), k = 0..n_cap, ψ = κd ∈ [0, π/2] the hemisphere's polar angle
               (d the angle θ from the cap's pole, κ = 1 + L/π): regular at the pole (sin^j ψ is sin^j θ times a
               smooth positive function of cos θ there); the Jacobi polynomials P^(j,0) are orthogonal under
               (1 − ξ)^j dξ, ξ = 2 cos ψ − 1, and the Gram weight sin^(2j) ψ d(cos ψ) is that times (1 + cos ψ)^j
               ∈ [1, 2^j], so the caps' Gram matrix stays well conditioned (P̂: normalised under (1 − ξ)^j),
    cylinder   F = P̂_k(t), k = 0..n_e, t ∈ [−1, 1] linear in θ on each cylinder element (model/meridian.joins),

with j = m, m + 1, m − 1 for Z, U, D. Continuity of each field at each element boundary is imposed by the null space
of its jump rows, together with its parity under the reflection
θ → π − θ (the elements are mirror images: the caps' functions of ψ alike, a cylinder element's P_k(t) the
mirror's P_k(−t) = (−1)^k P_k(t)): the basis is the union of the two reflection classes (R, T even, Z odd | R, T
odd, Z even, as the sphere's ``AzimuthalBasis.classes``), so that an equator-symmetric state's block splits into
two of half the size. Each field's functions of one class are then recombined orthonormal under ‖δx‖² (below):
the Gram matrix is the identity, and each pencil's reduction a scaling, as on the sphere. The degrees: the caps' and each cylinder element's
in the equilibrium's piecewise basis of the same degree N (galerkin/elements.sequence: the caps' in x, an element's
in θ), at least MIN_DEGREE; a capsule of length 0 (no joins: the sphere) has two hemispheres of degree N.

Integrals are Gauss–Legendre in θ on each element (every integrand is smooth in θ there, even about a pole):
d²E/dε² = ∫ yᵀ h y sin θ dθ (h per d(cos θ), the kernel's), and the Gram matrix is that of
‖δx‖² = ½ ∫ (R² + T² + Z²) S' R(θ) dθ (per 2π over the reference surface, dA = R S' dθ dφ: the sphere's at length 0).
"""
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import linalg, special

from ...galerkin.elements import CAPS, CYLINDER, layout, sequence
from ...model.meridian import capsule_rate, hoop, joins
from ...numerics import eigen
from ...scene.tables import Geometry

MIN_DEGREE = 4  # the fewest polynomial degrees of a field on one element
NODE_MARGIN = 24  # Gauss nodes per element beyond three times its degree (the kernel's coefficients are not
#                   polynomials: the rule is taken well past the products' degree)


@dataclass(frozen=True)
class Element:
    """One element: θ from ``low`` to ``high``, ``kind`` 'north', 'cylinder' or 'south', polynomial ``degree``."""

    kind: str
    low: float
    high: float
    degree: int


def elements(geometry: Geometry, degree: int) -> tuple:
    """The capsule's elements in ascending θ (module docstring)."""
    kappa = capsule_rate(geometry)
    theta_j = 0.5 * np.pi / kappa
    bounds = joins(geometry)
    if not bounds:  # length 0: two hemispheres
        return Element("north", 0.0, theta_j, degree), Element("south", np.pi - theta_j, np.pi, degree)
    order = sequence(degree, bounds)
    shape = layout(bounds)
    cap = max([j for family, j, _ in order if family == CAPS], default=0)
    # a bubble (CYLINDER, j, k) lies on the element k and its mirror
    per_element = {e: max([j for family, j, k in order if family == CYLINDER and k in (e, shape.mirror(e))],
                          default=1) for e in range(shape.count)}
    theta = np.arccos(np.asarray(bounds, dtype=float))[::-1]  # ascending θ: the joins and the inner boundaries
    cylinder = tuple(Element("cylinder", float(theta[i]), float(theta[i + 1]),
                             max(MIN_DEGREE, per_element[shape.count - 1 - i])) for i in range(shape.count))
    return (Element("north", 0.0, float(theta[0]), max(MIN_DEGREE, cap)), *cylinder,
            Element("south", float(theta[-1]), np.pi, max(MIN_DEGREE, cap)))


def _field_functions(element: Element, kappa: float, order: int, theta: np.ndarray):
    """(F, dF/dθ) of the element's functions of regularity ``order`` (j) at θ, each (len(θ), degree + 1)."""
    k = np.arange(element.degree + 1)
    if element.kind == "cylinder":
        span = element.high - element.low
        t = (2.0 * theta - element.low - element.high) / span
        scale = np.sqrt((2 * k + 1) / 2.0)
        p = special.eval_legendre(k[None, :], t[:, None]) * scale
        dp = np.zeros_like(p)
        dp[:, 1:] = (k[1:] + 1) / 2.0 * special.eval_jacobi(k[None, 1:] - 1, 1, 1, t[:, None]) * scale[1:]
        return p, dp * 2.0 / span
    north = element.kind == "north"
    psi = kappa * (theta if north else np.pi - theta)
    rate = kappa if north else -kappa  # dψ/dθ
    sin, cos = np.sin(psi)[:, None], np.cos(psi)[:, None]
    xi = 2.0 * cos - 1.0
    scale = np.sqrt((2 * k + order + 1) / 2.0 ** (order + 1))  # P^(j,0)_k has the norm² 2^(j+1)/(2k + j + 1)
    jacobi = special.eval_jacobi(k[None, :], order, 0, xi) * scale
    slope = np.zeros_like(jacobi)  # dP^(j,0)_k/dξ = (k + j + 1)/2 P^(j+1,1)_(k−1)
    slope[:, 1:] = (k[1:] + order + 1) / 2.0 * special.eval_jacobi(k[None, 1:] - 1, order + 1, 1, xi) * scale[1:]
    weight = sin**order
    dweight = order * sin ** max(order - 1, 0) * cos if order else 0.0 * sin
    return weight * jacobi, rate * (dweight * jacobi + weight * slope * (-2.0 * sin))


@dataclass(frozen=True)
class CapsuleBasis:
    """The cos mφ perturbations of a capsule (module docstring) at its Gauss nodes in θ: ``ops`` (6, n_q, size) the
    values of (R, R', Z, Z', T, T') per coefficient (columns: Z's, then U's and D's), ``weights`` for ∫ … d(cos θ),
    ``gram`` and its ``factor``, ``moments`` (the L2 projection's rows, as AzimuthalBasis's); no reflection
    ``classes`` (the block is solved whole)."""

    m: int
    degree: int
    geometry: Geometry

    def __post_init__(self):
        m = self.m
        if m < 1:
            raise ValueError(f"m = {m}: the azimuthal second variation needs m ≥ 1 (m = 0 is Equilibrium.jacobian)")
        kappa = capsule_rate(self.geometry)
        parts = elements(self.geometry, self.degree)
        nodes, weights = [], []
        for e in parts:
            s, w = np.polynomial.legendre.leggauss(3 * e.degree + NODE_MARGIN)
            nodes.append(0.5 * (e.high - e.low) * s + 0.5 * (e.high + e.low))
            weights.append(0.5 * (e.high - e.low) * w)
        theta, theta_weights = np.concatenate(nodes), np.concatenate(weights)
        put = object.__setattr__
        put(self, "theta", theta)
        put(self, "x", np.cos(theta))
        put(self, "sin_theta", np.sin(theta))
        put(self, "weights", theta_weights * np.sin(theta))
        put(self, "elements", parts)
        area = theta_weights * kappa * hoop(self.geometry, np.cos(theta), np.sin(theta))  # S' R dθ
        # columns: Z, U, D, each its reflection class 0 then 1 (class 0: Z odd, U and D even under θ → π − θ), each
        # group orthonormal under ‖δx‖² (R² + T² = (U² + D²)/2: G has no entries between the groups)
        offsets, columns, fields, parity, combinations = {}, 0, {}, [], {}
        for name, order, first, share in (("Z", m, -1, 0.5), ("U", m + 1, 1, 0.25), ("D", m - 1, 1, 0.25)):
            pieces = [_orthonormal(*_joined(parts, kappa, order, nodes, sign), share * area)
                      for sign in (first, -first)]
            *values, combinations[name] = (np.hstack(arrays) for arrays in zip(*pieces))
            fields[name] = tuple(values)
            offsets[name] = slice(columns, columns + fields[name][0].shape[1])
            columns += fields[name][0].shape[1]
            parity += [0] * pieces[0][0].shape[1] + [1] * pieces[1][0].shape[1]
        ops = np.zeros((6, theta.size, columns))
        ops[2, :, offsets["Z"]], ops[3, :, offsets["Z"]] = fields["Z"]
        for name, sign in (("U", 1.0), ("D", -1.0)):  # R = (U + D)/2, T = (U − D)/2
            value, slope = fields[name]
            ops[0, :, offsets[name]], ops[1, :, offsets[name]] = value / 2, slope / 2
            ops[4, :, offsets[name]], ops[5, :, offsets[name]] = sign * value / 2, sign * slope / 2
        put(self, "blocks", offsets)
        put(self, "combinations", combinations)
        put(self, "size", columns)
        put(self, "ops", ops)
        nz = offsets["Z"].stop
        put(self, "ops_z", np.ascontiguousarray(ops[2:4, :, :nz]))
        put(self, "ops_ud", np.ascontiguousarray(ops[[0, 1, 4, 5], :, nz:]))
        values = ops[[0, 4, 2]]
        put(self, "gram", 0.5 * np.einsum("aqi,q,aqj->ij", values, area, values))  # I to rounding
        put(self, "factor", eigen.GramFactor(self.gram, orthogonal=True))
        put(self, "moments", np.ascontiguousarray((0.5 * values * area[None, :, None]).reshape(-1, columns)))
        # the reflection classes, as AzimuthalBasis's: ``even`` the nodes (here all), weights and each class's columns
        # of ops_ud and ops_z (Z ones first) for the assembly of an equator-symmetric state's two blocks
        parity = np.array(parity)
        classes = tuple(np.flatnonzero(parity == p) for p in (0, 1))
        put(self, "classes", classes)
        put(self, "class_factors", tuple(eigen.GramFactor(self.gram[np.ix_(c, c)], orthogonal=True) for c in classes))
        put(self, "even", (np.arange(theta.size), self.weights, tuple(
            (np.ascontiguousarray(self.ops_ud[:, :, c[c >= nz] - nz]), np.ascontiguousarray(self.ops_z[:, :, c[c < nz]]))
            for c in classes)))

    def values(self, c: np.ndarray) -> np.ndarray:
        """(R, R', Z, Z', T, T') at the nodes for coefficients c, shape (6, n_q)."""
        return self.ops @ c

    def displacement(self, c: np.ndarray, theta: np.ndarray, rate: bool = False) -> np.ndarray:
        """(R, Z, T) on any θ grid in [0, π] for coefficients c (one vector or rows): the amplitudes of
        δρ = R cos mφ, δz = Z cos mφ, δφ = T sin mφ, shape (3, n_θ) or (rows, 3, n_θ) (AzimuthalBasis's);
        R = (U + D)/2, T = (U − D)/2 from each field's broken functions times its ``combinations``; with ``rate``
        their derivatives d/dθ (at a join the first element's)."""
        theta = np.asarray(theta, dtype=float)
        kappa = capsule_rate(self.geometry)
        rows = np.atleast_2d(np.asarray(c, dtype=float))
        field = {name: _broken(self.elements, kappa, order, theta, rate) @ self.combinations[name] @ rows[:, self.blocks[name]].T
                 for name, order in (("Z", self.m), ("U", self.m + 1), ("D", self.m - 1))}
        shapes = np.stack([(field["U"] + field["D"]) / 2, field["Z"], (field["U"] - field["D"]) / 2]).transpose(2, 0, 1)
        return shapes[0] if np.ndim(c) == 1 else shapes


def _broken(parts: tuple, kappa: float, order: int, theta: np.ndarray, rate: bool = False) -> np.ndarray:
    """The broken functions of regularity ``order`` (every element's, columns element by element; with ``rate``
    their derivatives d/dθ) at any θ in [0, π]: an element's own functions on it, zero elsewhere (a boundary point
    on the first element holding it)."""
    out = np.zeros((theta.size, sum(e.degree + 1 for e in parts)))
    column, free = 0, np.ones(theta.size, dtype=bool)
    for e in parts:
        on = free & (theta >= e.low) & (theta <= e.high)
        out[on, column:column + e.degree + 1] = _field_functions(e, kappa, order, theta[on])[int(rate)]
        free &= ~on
        column += e.degree + 1
    if free.any():
        raise ValueError(f"theta = {theta[free][0]!r}: outside the capsule's meridian; allowed: [0, π]")
    return out


def _joined(parts: tuple, kappa: float, order: int, nodes: list, parity: int) -> tuple:
    """(F, dF/dθ, C) at every element's ``nodes`` (stacked) of one field of regularity ``order`` on the C⁰ joined
    elements with F(π − θ) = ``parity`` · F(θ): the broken functions times C, an orthonormal basis of the null space
    of the jumps at the boundaries and of c − parity · (the mirror's coefficients)."""
    blocks, ends = [], []
    for e, theta in zip(parts, nodes):
        blocks.append(_field_functions(e, kappa, order, theta))
        ends.append(_field_functions(e, kappa, order, np.array([e.low, e.high]))[0])
    sizes = [b[0].shape[1] for b in blocks]
    starts = np.concatenate([[0], np.cumsum(sizes)])
    jumps = np.zeros((len(parts) - 1, starts[-1]))
    for i in range(len(parts) - 1):  # the value at the end of element i equals that at the start of i + 1
        jumps[i, starts[i]:starts[i + 1]] = ends[i][1]
        jumps[i, starts[i + 1]:starts[i + 2]] -= ends[i + 1][0]
    mirror = np.zeros((starts[-1], starts[-1]))  # the coefficients of F(π − θ)
    for i, e in enumerate(parts):
        j = len(parts) - 1 - i
        signs = (-1.0) ** np.arange(sizes[i]) if e.kind == "cylinder" else np.ones(sizes[i])
        mirror[starts[i]:starts[i + 1], starts[j]:starts[j + 1]] = np.diag(signs)
    joined = linalg.null_space(np.vstack([jumps, np.eye(starts[-1]) - parity * mirror]))
    value = linalg.block_diag(*[b[0] for b in blocks]) @ joined
    slope = linalg.block_diag(*[b[1] for b in blocks]) @ joined
    return value, slope, joined


def _orthonormal(value: np.ndarray, slope: np.ndarray, combination: np.ndarray, weights: np.ndarray) -> tuple:
    """(F, dF/dθ, C) of the columns recombined orthonormal under Σ_q weights_q F_i F_j (L⁻ᵀ of its Cholesky factor;
    C the broken functions' coefficients of the new columns): the Gram matrix is then the identity (GramFactor
    ``orthogonal``: the pencils' reduction is a scaling)."""
    lower = np.linalg.cholesky(value.T @ (weights[:, None] * value))
    inverse = linalg.solve_triangular(lower, np.eye(lower.shape[0]), lower=True).T
    return value @ inverse, slope @ inverse, combination @ inverse


@lru_cache(maxsize=32)
def capsule_basis(m: int, degree: int, geometry: Geometry) -> CapsuleBasis:
    return CapsuleBasis(int(m), int(degree), geometry)
