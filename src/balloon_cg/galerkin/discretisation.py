"""Ritz–Galerkin discretisation in x = cos θ with Legendre polynomials.

λ2(θ) = Σ_k a_k P_k(cos θ), η(θ) = Σ_k b_k P_k(cos θ), k = 0..N. Every such pair is smooth at the poles
(λ2 and η are even in the distance from a pole), so the 0/0 pole terms never have to be evaluated: with
dθ sin θ = −dx the energy E = ∫_0^π Π dθ = ∫_{-1}^{1} π̂ dx (π̂ = Π/sin θ) is a smooth integral, computed by
Gauss–Legendre quadrature at interior nodes. At a node
    v = λ2' sin θ = −(1 − x²) dλ2/dx,      w = η' = −sin θ dη/dx.
Equator symmetry (λ2 even, η odd in x) keeps a_even and b_odd, and then every integrand is even in x: the
quadrature runs over the nodes x ≥ 0 with doubled weights (``even_half``). Without a field the translation
η → η + c is removed by dropping b_0 (the energy does not depend on it: an exact zero mode).

A capsule's discretisation (``joins`` = ±c, where its reference curvature jumps) has the piecewise basis φ_k of
galerkin/elements.py in place of P_k (φ_0 = 1, parity (−1)^k, hierarchical: all of the above holds) and a composite
Gauss rule split at the joins; it converges spectrally in the degree where one Legendre series converges as N⁻³.
"""
import functools
from dataclasses import dataclass, replace

import numpy as np
from numba import njit

from .coordinate_map import WireMap
from .elements import element_degree, element_table, families, function_keys, graded_degree, piece_degrees
from .legendre import gauss_rule, legendre_table
from ..generated import HESSIAN_PAIRS


def read_only(array: np.ndarray) -> np.ndarray:
    """A read-only view of ``array``. Every table handed to the jitted node loops is read-only (as a
    Discretisation's are), so that each loop compiles once: numba types a read-only array apart."""
    view = array.view()
    view.flags.writeable = False
    return view


def symmetric_rows(pairs) -> np.ndarray:
    """rows[k, l] = rows[l, k] = r for the r-th (k, l) of ``pairs``: where a symmetric matrix stored as the listed
    entries (the generated HESSIAN_PAIRS) keeps h_kl."""
    n = 1 + max(max(pair) for pair in pairs)
    rows = np.full((n, n), -1)
    for r, (k, l) in enumerate(pairs):
        rows[k, l] = rows[l, k] = r
    return rows


HESSIAN_ROW = symmetric_rows(HESSIAN_PAIRS)  # (k, l) -> row of energy_hessian's output (every axisymmetric layout's)
# below this many unknowns the node state and the Hessian are computed in jitted loops, from it by BLAS
# (the loops win while call overhead dominates: Hessian at 17 unknowns 2.0 µs against 7.3 µs, at 29 5.2 against
# 9.0, at 41 10.6-11.5 against 11.4-12.0, at 49 16-18 against 14-15; node state at 9 0.4 against 1.2, at 29 0.8
# against 1.5, at 49 1.8 against 2.0, at 97 10 against 5; measured single-threaded). Not raised to the
# crossover (~45): the rounding change at 30-44 unknowns tips the pull-in branch of tests/test_dielectric.py
# past max_degree (Discretisation.tail reads the near-fold noise of its zero coefficients as a slow tail;
# docs/numerics.md, "The tail estimate near a fold").
SMALL_SYSTEM = 30
# the gradient's loops (over the blocks of ops that are not zero) win longer: 1.0 µs against 2.3 at 29 unknowns,
# 1.8 against 3.0 at 49, 3.1 against 3.5 at 65, 4.5 against 4.6 at 97, 8.0 against 6.3 at 129
SMALL_GRADIENT = 100


@njit(cache=True)
def _weighted_bases(pointwise, weights, A, B):
    """W_q Σ_l h_kl(q) ∂state_l/∂u at every node: against the a-basis A = (∂λ2, ∂v) for k ∈ {λ2, v}
    (2, n_q, n_a) and against the b-basis B = (∂η, ∂w) for every k (4, n_q, n_b)."""
    n_q, n_a, n_b = weights.shape[0], A.shape[2], B.shape[2]
    against_a = np.empty((2, n_q, n_a))
    against_b = np.empty((4, n_q, n_b))
    for k in range(4):
        for q in range(n_q):
            if k < 2:
                c0 = pointwise[HESSIAN_ROW[k, 0], q] * weights[q]
                c1 = pointwise[HESSIAN_ROW[k, 1], q] * weights[q]
                for i in range(n_a):
                    against_a[k, q, i] = c0 * A[0, q, i] + c1 * A[1, q, i]
            c2 = pointwise[HESSIAN_ROW[k, 2], q] * weights[q]
            c3 = pointwise[HESSIAN_ROW[k, 3], q] * weights[q]
            for i in range(n_b):
                against_b[k, q, i] = c2 * B[0, q, i] + c3 * B[1, q, i]
    return against_a, against_b


def even_half(x: np.ndarray, weights: np.ndarray):
    """(the nodes kept, their weights) of a mirror-symmetric node set (x_{n−1−q} = −x_q) for integrands even in x:
    the nodes x ≥ 0, weights doubled where x > 0 (the node x = 0 of an odd rule counts once)."""
    keep = np.flatnonzero(x >= 0.0)
    return keep, np.where(x[keep] > 0.0, 2.0, 1.0) * weights[keep]


def assemble_gradient(pointwise, weights, A, B, gradient_ops, out=None) -> np.ndarray:
    """Σ_q W_q Σ_k g_k(q) ops[k, q, :] for g (4, n_q), ops' blocks that are not zero A = (∂λ2, ∂v)/∂a (2, n_q, n_a)
    and B = (∂η, ∂w)/∂b (2, n_q, n_b); ``gradient_ops`` is ops as a contiguous (size, 4 n_q)."""
    size = A.shape[2] + B.shape[2]
    if size < SMALL_GRADIENT:
        # into a contiguous array: a column of a matrix as ``out`` would compile a second layout of the loops
        target = out if out is not None and out.flags.c_contiguous else np.empty(size)
        _gradient_loops(np.ascontiguousarray(pointwise), weights, A, B, target)
        if out is None or out is target:
            return target
        out[:] = target
        return out
    return np.matmul(gradient_ops, (pointwise * weights).ravel(), out=out)


def assemble_hessian(pointwise, weights, A, B, out=None) -> np.ndarray:
    """Σ_q W_q Σ_kl h_kl(q) ∂state_k/∂u ∂state_l/∂u from energy_hessian's output (10, n_q) and the bases
    A = (∂λ2, ∂v)/∂a (2, n_q, n_a), B = (∂η, ∂w)/∂b (2, n_q, n_b) at the nodes.

    (λ2, v) depend only on the a-coefficients and (η, w) only on the b-coefficients, so each of the three blocks
    aa, ab, bb is one BLAS product of the stacked basis with its node-wise weighted partner; below SMALL_SYSTEM
    unknowns the same sums are one jitted pass (``_hessian_loops``). ``out``: the leading na + nb columns of a
    C-ordered array (a bordered Jacobian's rows) take the Hessian."""
    na, nb = A.shape[2], B.shape[2]
    out = np.empty((na + nb, na + nb)) if out is None else out
    if na + nb < SMALL_SYSTEM:
        _hessian_loops(np.ascontiguousarray(pointwise), weights, A, B, out)
        return out[:, :na + nb]
    out = out[:, :na + nb]
    weighted_a, weighted_b = _weighted_bases(np.ascontiguousarray(pointwise), weights, A, B)
    stacked_a, stacked_b = A.reshape(-1, na), B.reshape(-1, nb)
    np.matmul(stacked_a.T, weighted_a.reshape(-1, na), out=out[:na, :na])
    np.matmul(stacked_a.T, weighted_b[:2].reshape(-1, nb), out=out[:na, na:])
    out[na:, :na] = out[:na, na:].T
    np.matmul(stacked_b.T, weighted_b[2:].reshape(-1, nb), out=out[na:, na:])
    return out


@njit(cache=True)
def _hessian_loops(pointwise, weights, A, B, out):
    """Discretisation.hessian's blocks aa, ab, bb (ba = abᵀ) in one pass over the nodes, into the leading columns
    of ``out``: at node q the
    bases' weighted partners W_q Σ_l h_kl ∂state_l/∂u (as ``_weighted_bases``), then their outer products with the
    basis, each row's sums over whole contiguous rows (faster than over the upper triangle alone: 5.2 against 7.7 µs
    at 29 unknowns), the lower triangle then overwritten by the upper's mirror (exactly symmetric)."""
    n_q, na, nb = weights.shape[0], A.shape[2], B.shape[2]
    out[:, :na + nb] = 0.0
    partner_a = np.empty((2, na))
    partner_b = np.empty((4, nb))
    for q in range(n_q):
        w = weights[q]
        h00, h01, h11 = (pointwise[HESSIAN_ROW[0, 0], q] * w, pointwise[HESSIAN_ROW[0, 1], q] * w,
                         pointwise[HESSIAN_ROW[1, 1], q] * w)
        h02, h03, h12, h13 = (pointwise[HESSIAN_ROW[0, 2], q] * w, pointwise[HESSIAN_ROW[0, 3], q] * w,
                              pointwise[HESSIAN_ROW[1, 2], q] * w, pointwise[HESSIAN_ROW[1, 3], q] * w)
        h22, h23, h33 = (pointwise[HESSIAN_ROW[2, 2], q] * w, pointwise[HESSIAN_ROW[2, 3], q] * w,
                         pointwise[HESSIAN_ROW[3, 3], q] * w)
        for i in range(na):
            a0, a1 = A[0, q, i], A[1, q, i]
            partner_a[0, i] = h00 * a0 + h01 * a1
            partner_a[1, i] = h01 * a0 + h11 * a1
        for i in range(nb):
            b0, b1 = B[0, q, i], B[1, q, i]
            partner_b[0, i] = h02 * b0 + h03 * b1
            partner_b[1, i] = h12 * b0 + h13 * b1
            partner_b[2, i] = h22 * b0 + h23 * b1
            partner_b[3, i] = h23 * b0 + h33 * b1
        for i in range(na):
            a0, a1 = A[0, q, i], A[1, q, i]
            row = out[i]
            for j in range(na):
                row[j] += a0 * partner_a[0, j] + a1 * partner_a[1, j]
            for j in range(nb):
                row[na + j] += a0 * partner_b[0, j] + a1 * partner_b[1, j]
        for i in range(nb):
            b0, b1 = B[0, q, i], B[1, q, i]
            row = out[na + i]
            for j in range(nb):
                row[na + j] += b0 * partner_b[2, j] + b1 * partner_b[3, j]
    for i in range(na + nb):
        for j in range(i):
            out[i, j] = out[j, i]


@njit(cache=True)
def _gradient_loops(pointwise, weights, A, B, out):
    """Discretisation.gradient: out_i = Σ_k Σ_q W_q g_k(q) ∂state_k(q)/∂u_i over the blocks of ops that are not zero
    (A = (∂λ2, ∂v)/∂a, B = (∂η, ∂w)/∂b), in the order of the sum over all of ops (the zeros add nothing)."""
    na = A.shape[2]
    out[:] = 0.0
    for k in range(4):
        for q in range(weights.shape[0]):
            c = weights[q] * pointwise[k, q]
            if k < 2:
                for i in range(na):
                    out[i] += c * A[k, q, i]
            else:
                for i in range(B.shape[2]):
                    out[na + i] += c * B[k - 2, q, i]


@njit(cache=True)
def _state_loops(A, B, u, out):
    """Discretisation.node_state: (λ2, v) = A·a and (η, w) = B·b at every node, u = (a, b)."""
    na = A.shape[2]
    for q in range(A.shape[1]):
        for k in range(2):
            total = 0.0
            for i in range(na):
                total += A[k, q, i] * u[i]
            out[k, q] = total
            total = 0.0
            for i in range(B.shape[2]):
                total += B[k, q, i] * u[na + i]
            out[2 + k, q] = total


def basis_table(x: np.ndarray, degree: int, joins: tuple = (), degrees: tuple = ()):
    """(φ_k(x), dφ_k/dx) for k = 0..degree: P_k(x), or with ``joins`` (a capsule's element boundaries, −c … c) the
    elements' piecewise basis (galerkin/elements.py; graded with ``degrees`` per element group)."""
    return element_table(x, degree, joins, degrees) if joins else legendre_table(x, degree)


@functools.lru_cache(maxsize=64)
def _cached_table(theta_bytes: bytes, degree: int, mapping: WireMap | None = None, joins: tuple = (),
                  degrees: tuple = ()):
    """(φ_k(x), dφ_k/dx) at x = cos θ (P_k(s), s = h(x) on a map), for a θ grid met again and again (stability
    nodes, profiles)."""
    x = np.cos(np.frombuffer(theta_bytes))
    if mapping is None:
        return basis_table(x, degree, joins, degrees)
    p, dp = legendre_table(np.clip(mapping.s(x), -1.0, 1.0), degree)
    return p, dp * mapping.ds_dx(x)[:, None]


@dataclass(frozen=True)
class Discretisation:
    """Basis, quadrature and the unknown-coefficient layout u = (a[kept], b[kept]).

    With a ``mapping`` (coordinate_map.WireMap) the basis is P_k(s), s = h(x): Gauss nodes s_q in s, x_q = g(s_q),
    weights w_q/h'(x_q) (dx = ds/h'), and d/dx = h'(x) d/ds; everything else is unchanged.

    ``x`` holds every Gauss node (least-squares fits: ``projection``, ``transfer``); ``cos_theta``, ``sin_theta``,
    ``weights`` and ``ops`` are the quadrature's nodes, all of them or, on the symmetric layout, those with x ≥ 0.
    """

    degree: int
    symmetric: bool
    pin_translation: bool
    quadrature: int = 0
    mapping: WireMap | None = None
    joins: tuple = ()  # x where the basis and the quadrature split (a capsule's ±c, where its reference curvature
    #                    jumps, and its cylinder's element boundaries between: the piecewise basis of
    #                    galerkin/elements.py, a composite Gauss rule)
    element_degrees: tuple = ()  # with joins: a degree per element group (elements.graded_sequence) in place of
    #                              the greedy order of ``degree`` (``graded``)

    def __reduce__(self):
        """Pickled as its seven defining fields (the tables are rebuilt): results holding one stay small."""
        return Discretisation, (self.degree, self.symmetric, self.pin_translation, self.quadrature, self.mapping,
                                self.joins, self.element_degrees)

    def __post_init__(self):
        """Basis and quadrature tables from ``_tables`` (built once per set of fields, shared, read-only)."""
        if self.joins and self.mapping is not None:
            raise ValueError("Discretisation: a split quadrature (joins) and a wire map are not built together")
        if self.element_degrees and not self.joins:
            raise ValueError("Discretisation: element_degrees need the elements' joins")
        for name, value in _tables(self).items():
            object.__setattr__(self, name, value)

    @property
    def projection(self) -> np.ndarray:
        """Values at the nodes -> Legendre coefficients in s, by least squares (the Gauss-weight formula
        (k + ½) Σ_q w_q P_k(s_q) f_q loses ~1e-9 at degree 320 at the poles: numpy's end weights carry ~3e-14);
        shared by equal discretisations (``_projection``)."""
        return _projection(self)

    def split(self, u: np.ndarray):
        """Full Legendre coefficient vectors (a, b) of length degree + 1 from the unknowns u (for a held mapped
        basis b_0 = −Σ m_k b_k, so that η = Σ b_k P_k(s))."""
        a = np.zeros(self.degree + 1)
        b = np.zeros(self.degree + 1)
        a[self.a_index] = u[: self.a_index.size]
        b[self.b_index] = u[self.a_index.size:]
        b[0] -= self.eta_mean @ u[self.a_index.size:]
        return a, b

    def join(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return np.concatenate([a[self.a_index], b[self.b_index]])

    def node_state(self, u: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """(λ2, v, η, w) = ops @ u at the quadrature nodes, shape (4, n_q) (into ``out`` if given); below
        SMALL_SYSTEM unknowns a jitted loop over the blocks of ops that are not zero (``_state_loops``)."""
        out = np.empty((4, self.weights.size)) if out is None else out
        if self.size < SMALL_SYSTEM:
            _state_loops(self.basis_a, self.basis_b, u, out)
            return out
        return np.matmul(self.ops, u, out=out)

    def gradient(self, pointwise: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Σ_q W_q Σ_k g_k(q) ∂state_k(q)/∂u for pointwise derivatives g (4, n_q) (into ``out`` if given)."""
        return assemble_gradient(pointwise, self.weights, self.basis_a, self.basis_b, self._gradient_ops, out)

    def hessian(self, pointwise: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Σ_q W_q Σ_kl h_kl(q) ∂state_k/∂u ∂state_l/∂u; pointwise is energy_hessian's output (10, n_q), the
        entries (k, l) of HESSIAN_PAIRS (``assemble_hessian``), into the leading size columns of ``out`` (C-ordered,
        size × size or a bordered Jacobian's size × (size + k)) if given."""
        return assemble_hessian(pointwise, self.weights, self.basis_a, self.basis_b, out)

    def pole_rows(self):
        """Rows r with λ2(north) = r_n·u, λ2(south) = r_s·u, η(north), η(south) (read-only, built once: every
        continuation step's stop test reads them)."""
        return dict(self._pole_rows)

    @functools.cached_property
    def _pole_rows(self) -> dict:
        ones = basis_table(np.ones(1), self.degree, self.joins, self.element_degrees)[0][0]  # φ_k(1): all ones on Legendre's
        sign = (-1.0) ** np.arange(self.degree + 1) * ones  # φ_k(−1) = (−1)^k φ_k(1)
        zero = np.zeros(self.degree + 1)
        rows = {
            "lam2_top": self.join(ones, zero),
            "lam2_bottom": self.join(sign, zero),
            "eta_top": self.join(zero, ones) - np.append(np.zeros(self.a_index.size), self.eta_mean),
            "eta_bottom": self.join(zero, sign) - np.append(np.zeros(self.a_index.size), self.eta_mean),
        }
        for row in rows.values():
            row.flags.writeable = False
        return rows

    def evaluate(self, u: np.ndarray, theta: np.ndarray):
        """(λ2, λ2', η, η') on any θ grid (poles included); u is one unknown vector or a stack of them (rows)."""
        p, dp = _cached_table(theta.tobytes(), self.degree, self.mapping, self.joins, self.element_degrees)
        s = np.sin(theta)
        U = np.atleast_2d(u)
        na = self.a_index.size
        a, b = U[:, :na], U[:, na:]
        values = (a @ p[:, self.a_index].T, -s * (a @ dp[:, self.a_index].T),
                  b @ (p[:, self.b_index] - self.eta_mean).T, -s * (b @ dp[:, self.b_index].T))
        return values if np.ndim(u) == 2 else tuple(v[0] for v in values)

    def nests_in(self, other: "Discretisation") -> bool:
        """Every function of this basis lies in ``other``'s (same map and joins, degree no higher; on elements
        every function of this one found among ``other``'s, ``elements.function_keys``): transfers are exact."""
        if other.mapping != self.mapping or other.joins != self.joins:
            return False
        if not (self.element_degrees or other.element_degrees):
            return other.degree >= self.degree
        return _embedding(self, other) is not None

    @property
    def function_keys(self) -> tuple:
        """What names each φ_k (``elements.function_keys``; the Legendre basis: its degrees k)."""
        if not self.joins:
            return tuple(range(self.degree + 1))
        return function_keys(self.degree, self.joins, self.element_degrees)

    def transfer(self, u: np.ndarray, other: "Discretisation") -> np.ndarray:
        """The same functions in the basis of ``other``; u may be (.., size + 1), trailing entries (P, ...) kept.

        When this basis nests in ``other``, each coefficient moves to its function's place there and the others
        are zero (exact: on the Legendre basis and the greedy element order zeros appended). Otherwise λ2 and η are
        evaluated at ``other``'s nodes and fitted by least squares (``projection``).
        """
        U = np.atleast_2d(u)
        rest = U[:, self.size:]
        if self.nests_in(other):
            out, place = [], _embedding(self, other)
            for row in U[:, : self.size]:
                a, b = self.split(row)
                wide_a, wide_b = np.zeros(other.degree + 1), np.zeros(other.degree + 1)
                wide_a[place], wide_b[place] = a, b
                out.append(other.join(wide_a, wide_b))
            coefficients = np.array(out)
        else:
            lam2, _, eta, _ = self.evaluate(U[:, : self.size], np.arccos(other.x))
            a, b = lam2 @ other.projection.T, eta @ other.projection.T
            coefficients = np.hstack([a[:, other.a_index], b[:, other.b_index]])
        result = np.hstack([coefficients, rest])
        return result if np.ndim(u) == 2 else result[0]

    def reflected(self) -> "Discretisation":
        """The basis holding this one's functions reflected z → −z (x → −x, ``reflect``): itself without a map, the
        same fields on the mirrored map otherwise (``WireMap.mirrored``)."""
        return self if self.mapping is None else replace(self, mapping=self.mapping.mirrored())

    @functools.cached_property
    def _reflection_signs(self) -> np.ndarray:
        signs = self.join((-1.0) ** np.arange(self.degree + 1), -(-1.0) ** np.arange(self.degree + 1))
        signs.flags.writeable = False
        return signs

    def reflect(self, u: np.ndarray) -> np.ndarray:
        """The reflection z → −z of u (one unknown vector or rows, (.., size + k): trailing entries P, ... kept), on
        ``reflected()``: θ → π − θ, i.e. x → −x, with λ2̃(x) = λ2(−x) and η̃(x) = −η(−x) (η is the axial
        coordinate z), so a_k → (−1)^k a_k and b_k → (−1)^(k+1) b_k, exactly. On a map the mirrored map has
        P_k(h̃(x)) = (−1)^k P_k(h(−x)) and hold means m̃_k = (−1)^k m_k, so the same signs hold. An
        equator-symmetric state (a_even, b_odd) is its own reflection."""
        U = np.array(u, dtype=float, ndmin=2)
        U[:, : self.size] *= self._reflection_signs
        return U if np.ndim(u) == 2 else U[0]

    def tail(self, u: np.ndarray) -> float:
        """Spectral error estimate: the neglected tail Σ_{k>N} of a geometric series, E·r/(1 − r)
        (``geometric_tail`` of the envelope max(|a_k|, |b_k|)/|a_0|); on a capsule's piecewise basis the largest of
        its elements' own series (``elements.families``: each cylinder element's bubbles, the caps' pairs, by
        degree), each falling at its own rate."""
        a, b = self.split(u)
        envelope = np.maximum(np.abs(a), np.abs(b)) / abs(a[0])
        if not self.joins:
            return geometric_tail(envelope)
        return max(self.element_tails(u))

    def element_tails(self, u: np.ndarray) -> tuple:
        """Per element group (``elements.groups``: the cylinder's middle element or mirror pairs outwards, then the
        caps) the geometric tail of its own series (``tail``), each falling at its own rate."""
        return tuple(tail for tail, _ in self.element_decay(u))

    def element_decay(self, u: np.ndarray) -> tuple:
        """Per element group (tail, decay per degree r) of its own series (``geometric_fit``)."""
        return tuple(geometric_fit(envelope) for envelope in self.element_envelopes(u))

    def element_envelopes(self, u: np.ndarray) -> tuple:
        """Per element group (``elements.groups``) the envelope max(|a|, |b|)/|a_0| of its own series, one entry per
        degree, the last one the group's highest."""
        a, b = self.split(u)
        envelope = np.maximum(np.abs(a), np.abs(b)) / abs(a[0])
        return tuple(envelope[group] if group.ndim == 1 else envelope[group].max(axis=1)
                     for group in families(self.degree, self.joins, self.element_degrees))


def graded(disc: Discretisation, degrees: tuple) -> Discretisation:
    """``disc`` (a capsule's, with joins) on the graded basis with ``degrees`` per element group
    (``elements.graded_sequence``), its quadrature the default rule of its highest element degree."""
    return replace(disc, degree=graded_degree(tuple(degrees), disc.joins), quadrature=0,
                   element_degrees=tuple(int(d) for d in degrees))


@functools.lru_cache(maxsize=64)
def _embedding(source: Discretisation, target: Discretisation):
    """Where each φ_k of ``source`` sits in ``target``'s order (an index per k), None if one is not there."""
    place = {key: k for k, key in enumerate(target.function_keys)}
    if any(key not in place for key in source.function_keys):
        return None
    return np.array([place[key] for key in source.function_keys], dtype=int)


def geometric_tail(envelope: np.ndarray) -> float:
    """E·r/(1 − r) for a coefficient envelope of length n + 1: E its largest value over the last window of n/8
    entries, r the decay per entry between that window and the one 2 windows earlier (capped at 0.999). The last
    coefficients alone under-read the error by ~r/(1 − r) when the decay is slow (near a wire: r ≈ 0.91, 10×; the
    two-coil λ = 1.8 point at degree 192 has P error 1.3e-9 against 2.8e-11 from its last two coefficients and
    1.9e-9 from this estimate, tests/test_tail.py). Fewer than 5 entries (no two windows): their largest (none: 0)."""
    return geometric_fit(envelope)[0]


def geometric_fit(envelope: np.ndarray) -> tuple:
    """(``geometric_tail``, its decay per entry r); fewer than 5 entries: (their largest, 0.999)."""
    if envelope.size < 5:
        return float(envelope.max(initial=0.0)), 0.999
    n, window = envelope.size - 1, max(2, (envelope.size - 1) // 8)
    last = float(envelope[n - window + 1:].max())
    earlier = float(envelope[max(n - 3 * window + 1, 0): n - 2 * window + 1].max())
    rate = min((last / earlier) ** (1.0 / (2 * window)), 0.999) if earlier > 0.0 else 0.999
    return last * rate / (1.0 - rate), rate


def gauss_nodes(degree: int) -> int:
    """Gauss–Legendre nodes of the default rule at Legendre degree N (``Discretisation.quadrature`` = 0)."""
    return (3 * degree) // 2 + 8


def piece_nodes(degree: int, joins: tuple = (), degrees: tuple = ()) -> int:
    """Gauss nodes of the default rule at degree N: ``gauss_nodes`` of N, or with ``joins`` of the highest degree
    of any element (each piece of ``split_rule`` holds one element's polynomial)."""
    return gauss_nodes(element_degree(degree, joins, degrees) if joins else degree)


def split_rule(n_q, joins: tuple = ()):
    """(nodes, weights) on [−1, 1], ascending: Gauss–Legendre with n_q nodes, or with ``joins`` (sorted, in (−1, 1))
    n_q nodes on each piece between them (n_q a tuple: its own count on each piece, ascending; a composite rule, where a kink of the integrand at a join costs a single
    rule O(n_q⁻²)): Gauss in x on the two end pieces (the caps: exact for a polynomial in x of degree < 2 n_q) and
    in θ on the inner ones (the cylinder, whose basis is polynomial in θ: ∫f dx = ∫f sin θ dθ; Gauss in x there
    samples the ends of a high-degree polynomial in θ too sparsely, and the node table of a capsule of length 40
    had the condition 3.7e8 at degree 320 against 4e2 at 200). Mirror-symmetric to the last bit when the joins are
    (an odd rule's middle node at x = 0 exactly: ``even_half`` counts it once)."""
    if not joins:
        return gauss_rule(n_q)
    ends = (-1.0, *joins, 1.0)
    counts = n_q if isinstance(n_q, tuple) else (n_q,) * (len(ends) - 1)
    out_nodes, out_weights = [], []
    for i, (a, b) in enumerate(zip(ends[:-1], ends[1:])):
        nodes, weights = gauss_rule(counts[i])
        if i in (0, len(joins)):
            out_nodes.append(0.5 * (b - a) * nodes + 0.5 * (b + a))
            out_weights.append(0.5 * (b - a) * weights)
        else:
            low, high = np.arccos(b), np.arccos(a)  # θ ascending as x descends: reversed to ascend in x
            theta = (0.5 * (high - low) * nodes + 0.5 * (high + low))[::-1]
            out_nodes.append(np.cos(theta))
            out_weights.append((0.5 * (high - low) * weights)[::-1] * np.sin(theta))
    x, w = np.concatenate(out_nodes), np.concatenate(out_weights)
    if joins == tuple(-join for join in reversed(joins)):
        x, w = 0.5 * (x - x[::-1]), 0.5 * (w + w[::-1])
    return x, w


@functools.lru_cache(maxsize=4)
def _projection(disc: Discretisation) -> np.ndarray:
    """``Discretisation.projection``, computed once per set of fields (a pseudo-inverse: ~1 s of CPU at degree 320;
    the search for the plain degree of a point, ``analysis.branches.resolution``, builds the one its caller then transfers
    to), read-only."""
    projection = np.linalg.pinv(disc._node_table)
    projection.flags.writeable = False
    return projection


@functools.lru_cache(maxsize=16)
def _tables(disc: Discretisation) -> dict:
    """The node, weight and basis tables of a Discretisation (keyed by its seven fields: equal discretisations
    share them; every tracer, stability basis and branch point rebuilds the same few), read-only."""
    n_q = disc.quadrature or piece_nodes(disc.degree, disc.joins, disc.element_degrees)
    if disc.element_degrees and not disc.quadrature:  # graded: each piece the rule of its own element's degree
        n_q = tuple(gauss_nodes(degree) for degree in piece_degrees(disc.joins, disc.element_degrees))
    nodes, s_weights = split_rule(n_q, disc.joins)
    p, dp = basis_table(nodes, disc.degree, disc.joins, disc.element_degrees)
    if disc.mapping is None:
        x, weights = nodes, s_weights
    else:
        x = disc.mapping.x(nodes)
        jacobian = disc.mapping.ds_dx(x)
        weights, dp = s_weights / jacobian, dp * jacobian[:, None]
    k = np.arange(disc.degree + 1)
    a_keep = k[k % 2 == 0] if disc.symmetric else k
    b_keep = k[k % 2 == 1] if disc.symmetric else (k[1:] if disc.pin_translation else k)
    # held (b_0 = 0 means ∫η dx = 0) on a mapped general basis: η = Σ b_k (P_k(s) − m_k), m_k = ½∫P_k(s(x)) dx,
    # so that the hold is the same physical constraint in every basis (m = 0 without a map)
    held_mapped = disc.mapping is not None and disc.pin_translation and not disc.symmetric
    eta_mean = 0.5 * weights @ p[:, b_keep] if held_mapped else np.zeros(b_keep.size)
    na = a_keep.size
    size = na + b_keep.size
    fitting = {"_node_table": p, "x": x}  # every node: least-squares fits (projection, transfer) need them all
    if disc.symmetric:
        # equator-symmetric subspace (λ2 even, η odd in x; the field even in z): every integrand of E, R, J and
        # ∂R/∂(P, M) is even in x and the Gauss nodes in s are mirror-symmetric, so the quadrature needs only the
        # nodes s ≥ 0 (``even_half``): half the work for the field, the kernels and the assembly
        keep, weights = even_half(nodes, weights)
        x, p, dp = x[keep], p[keep], dp[keep]
    s = np.sqrt(1.0 - x * x)
    # state at the (quadrature) nodes is linear in u: state_k = ops[k] @ u, for (λ2, v, η, w)
    zeros_a = np.zeros((x.size, na))
    zeros_b = np.zeros((x.size, b_keep.size))
    ops = np.stack([
        np.hstack([p[:, a_keep], zeros_b]),
        np.hstack([-(1 - x * x)[:, None] * dp[:, a_keep], zeros_b]),
        np.hstack([zeros_a, p[:, b_keep] - eta_mean]),
        np.hstack([zeros_a, -s[:, None] * dp[:, b_keep]]),
    ])
    tables = {
        **fitting, "weights": weights, "cos_theta": x, "sin_theta": s, "a_index": a_keep,
        "b_index": b_keep, "eta_mean": eta_mean, "ops": ops,
        # the blocks of ops that are not identically zero: (∂λ2, ∂v)/∂a and (∂η, ∂w)/∂b, contiguous for BLAS
        "basis_a": np.ascontiguousarray(ops[0:2, :, :na]),
        "basis_b": np.ascontiguousarray(ops[2:4, :, na:]),
        "_gradient_ops": np.ascontiguousarray(ops.reshape(-1, size).T),  # (size, 4 n_q) for gemv
    }
    for array in tables.values():
        array.flags.writeable = False
    return tables | {"size": size}
