"""Spectral elements over a tube's arclength: the sibling of interval.py's one Legendre series that resolves a front.

A propagating bulge joins two nearly uniform states by a front a few radii wide: one Legendre series over the whole
tube resolves it only algebraically in practice (docs/tubes.md: tail ~5e-4 at degree 160 on the plateau). Here
x = 2S/L − 1 ∈ [−1, 1] is cut at ``bounds`` x_1 < … < x_{E−1} into E elements, on element e its own
t = (2x − x_e − x_{e+1})/(x_{e+1} − x_e) ∈ [−1, 1], and both fields are continuous piecewise polynomials of degree p
(``order``; conforming for the Ritz energy, which holds first derivatives only), in a hierarchical basis (the
capsule's, galerkin/elements.py):

    λ2 = a_0 + a_1 x + Σ_i a_hat_i h_i(x) + Σ_e Σ_{j=2..p} a_ej B_j(t_e),          (E p + 1 functions)
    η  = −λ̄ (L/2) x + Σ_i b_hat_i h_i(x) + Σ_e Σ_{j=2..p} b_ej B_j(t_e),             (E p − 1 functions)

h_i the hat of inner bound x_i (1 there, 0 at its neighbours), B_j = P_j − P_{j−2} zero off its element. η's
functions vanish at x = ±1 as interval.py's bubbles do, so the unknowns are laid out as there with N = E p:
u = (a, λ̄, b), a_0 the constant (the uniform tube a_0 = λθ, λ̄ = λz exact), sliding or plugged ends alike (plugged:
λ2 = 1 + η's kind of functions). Quadrature: ``quadrature`` Gauss nodes per element (0: the default rule at p,
discretisation.gauss_nodes). A layout with an element split in two holds every function of the unsplit one, so
states transfer exactly to a refined layout (``collocated``).

The error estimate (``tail``) is the Legendre tail of each element's own series in t (``element_tails``: the
geometric_tail of max(|c_j|, |d_j|)/ρ̄, λ2's and η's bubble part's coefficients, ρ̄ the mean radius) and the
largest of them: the refinement reads where it is large (tube/front.py). There are no mirror blocks (a layout
graded towards a front is not mirror-symmetric): the bulge branch is traced on every unknown.
"""
import functools
from dataclasses import dataclass

import numpy as np

from .discretisation import gauss_nodes, geometric_tail, read_only
from .discretisation import HESSIAN_ROW
from .interval import IntervalDiscretisation
from .legendre import gauss_rule, legendre_table
from ..scene.tables import Ends


@dataclass(frozen=True)
class ElementInterval(IntervalDiscretisation):
    """Spectral elements of ``order`` p between the inner ``bounds`` (in x, ascending) over a tube of ``length``
    (module docstring); ``degree`` is E p (the Legendre series of the same number of unknowns): build it with
    ``element_interval``."""

    order: int = 2
    bounds: tuple = ()

    def __post_init__(self):
        edges = np.array((-1.0, *self.bounds, 1.0))
        if self.order < 2 or np.any(np.diff(edges) <= 0):
            raise ValueError(f"spectral elements need order ≥ 2 (the bubbles) and bounds ascending inside (−1, 1), "
                             f"not order {self.order}, bounds {self.bounds}")
        if self.degree != self.count * self.order:
            raise ValueError(f"degree {self.degree} is not elements × order = {self.count} × {self.order}")

    @property
    def count(self) -> int:
        """The number of elements E."""
        return len(self.bounds) + 1

    @property
    def edges(self) -> np.ndarray:
        """x_0 = −1, the inner bounds, x_E = 1."""
        return np.array((-1.0, *self.bounds, 1.0))

    def rule(self) -> tuple:
        """(x, w): ``quadrature`` (0: gauss_nodes(p)) Gauss nodes on each element, the weights in x."""
        t, w = gauss_rule(self.quadrature or gauss_nodes(self.order))
        edges = self.edges
        half = 0.5 * np.diff(edges)[:, None]
        return ((edges[:-1, None] + half * (t[None, :] + 1.0)).ravel(), (half * w[None, :]).ravel())

    def functions(self, x: np.ndarray) -> tuple:
        """(λ2's functions, d/dx, η's functions, d/dx) at the points x (module docstring; at an inner bound the
        element above it)."""
        x = np.asarray(x, dtype=float)
        edges, p, n = self.edges, self.order, self.count
        element = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, n - 1)
        width = edges[element + 1] - edges[element]
        t = (2.0 * x - edges[element] - edges[element + 1]) / width
        dt = 2.0 / width
        leg, dleg = legendre_table(t, p)
        hats, slopes = np.zeros((x.size, n - 1)), np.zeros((x.size, n - 1))
        for i in range(1, n):
            below, above = element == i - 1, element == i
            hats[:, i - 1] = np.where(below, 0.5 * (1 + t), 0.0) + np.where(above, 0.5 * (1 - t), 0.0)
            slopes[:, i - 1] = np.where(below, 0.5 * dt, 0.0) - np.where(above, 0.5 * dt, 0.0)
        bubbles, bubble_slopes = np.zeros((x.size, n * (p - 1))), np.zeros((x.size, n * (p - 1)))
        for e in range(n):
            on = element == e
            columns = slice(e * (p - 1), (e + 1) * (p - 1))
            bubbles[:, columns] = np.where(on[:, None], leg[:, 2:] - leg[:, :-2], 0.0)
            bubble_slopes[:, columns] = np.where(on[:, None], (dleg[:, 2:] - dleg[:, :-2]) * dt[:, None], 0.0)
        axial, daxial = np.hstack([hats, bubbles]), np.hstack([slopes, bubble_slopes])
        if self.ends != Ends.SLIDING:
            return axial, daxial, axial, daxial
        ones = np.ones((x.size, 1))
        return np.hstack([ones, x[:, None], axial]), np.hstack([0 * ones, ones, daxial]), axial, daxial

    def node_state(self, u: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """(λ2, v, η, w) at the nodes, (4, n_q), element by element on ``_local_maps`` (the dense maps, 4 n_q
        columns of E p + 1 values each, are read from memory at every call: ~10 ms at E p = 400)."""
        out = np.empty((4, self.x.size)) if out is None else out
        k = self.axial_index
        for group, (rows, coefficients) in enumerate(((slice(0, 2), u[:k]), (slice(2, 4), u[k:]))):
            columns, local = _local_maps(self)[group]
            values = np.einsum("ekqc,ec->keq", local, coefficients[columns])
            out[rows] = values.reshape(2, -1)
        if self.ends == Ends.PLUGGED:
            out[0] += 1.0
        return out

    def gradient(self, pointwise: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """∂E/∂u = Σ_q W_q Σ_k ∂π̂/∂s_k T_k[q] element by element (``node_state``), added into the columns."""
        weighted = (pointwise * self.weights).reshape(4, self.count, -1)
        out = np.empty(self.size) if out is None else out
        k = self.axial_index
        for group, (rows, columns) in enumerate(((slice(0, 2), slice(0, k)), (slice(2, 4), slice(k, self.size)))):
            index, local = _local_maps(self)[group]
            parts = np.einsum("keq,ekqc->ec", weighted[rows], local)
            out[columns] = np.bincount(index.ravel(), parts.ravel(), minlength=columns.stop - columns.start)
        return out

    def hessian_block(self, i: int, j: int, h: np.ndarray) -> np.ndarray:
        """interval.py's block product element by element (``_element_blocks``), the blocks added into their
        columns: O(n_q p²), not O(n_q (E p)²)."""
        index, shape = _block_index(self, i, j)
        return np.bincount(index, self._element_blocks(i, j, h).ravel(), minlength=shape[0] * shape[1]).reshape(shape)

    def _element_blocks(self, i: int, j: int, h: np.ndarray) -> np.ndarray:
        """(E, m_i, m_j): block e is Σ_kl T_ekᵀ diag(W h_kl) T_el on its ``_local_maps`` columns (the nodes of element
        e read only its p + 1 functions and the global ones); ``h`` (2, 2, n_q) the weighted h_kl."""
        (_, left), (_, right) = _local_maps(self)[i], _local_maps(self)[j]
        count, _, nodes, _ = left.shape
        h = h.reshape(2, 2, count, nodes).transpose(2, 0, 1, 3)  # (E, k, l, q)
        scaled = h[:, :, 0, :, None] * right[:, None, 0] + h[:, :, 1, :, None] * right[:, None, 1]  # (E, k, q, m_j)
        return left.reshape(count, 2 * nodes, -1).transpose(0, 2, 1) @ scaled.reshape(count, 2 * nodes, -1)

    def sparse_hessian(self, pointwise: np.ndarray, column: np.ndarray | None = None):
        """∂²E/∂u² (``hessian``) as a scipy.sparse CSC matrix from the element blocks, O(E p²) entries (a sliding tube's
        2E p + 1 unknowns couple only within an element but for 1, x and λ̄), with ``column`` appended as its last
        column if given (a bordered Jacobian's ∂R/∂P): for numerics/newton.SparseFactors."""
        from scipy import sparse  # here: a sphere's `run` imports this module (io/tube_file) but never scipy.sparse
        weighted = pointwise * self.weights
        blocks = [self._element_blocks(i, j, weighted[HESSIAN_ROW[2 * i: 2 * i + 2, 2 * j: 2 * j + 2]]).ravel()
                  for i, j in ((0, 0), (0, 1), (1, 1))]
        entry, indices, indptr = _sparse_pattern(self)
        data = np.bincount(entry, np.concatenate([blocks[0], blocks[1], blocks[1], blocks[2]]), minlength=indices.size)
        shape = (self.size, self.size)
        if column is not None:
            data, indices = np.concatenate([data, column]), np.concatenate([indices, np.arange(self.size)])
            indptr, shape = np.append(indptr, indptr[-1] + self.size), (self.size, self.size + 1)
        return sparse.csc_matrix((data, indices, indptr), shape=shape)

    def arrow_order(self, unknowns: np.ndarray) -> tuple:
        """(order, local, bandwidth): the positions in ``unknowns`` (indices into u) laid out so that the Hessian on
        them is an arrow (numerics/band_ldlt.ArrowLDLT): its first ``local`` rows banded with half-bandwidth
        ``bandwidth`` (the columns of one element, ``_local_maps``, within it of each other), the global columns (1,
        x and λ̄: on every element, where there are more than two) last. Each local column goes with the last element
        it lies on, after the ones it shares with the element before (a bound's hats, then the bubbles): 2p + 1."""
        k = self.axial_index
        maps = _local_maps(self)
        elements = [np.concatenate([hoop, axial + k]) for hoop, axial in zip(maps[0][0], maps[1][0])]
        first, last = np.full(self.size, self.count), np.full(self.size, -1)
        for e, columns in enumerate(elements):
            first[columns] = np.minimum(first[columns], e)
            last[columns] = np.maximum(last[columns], e)
        overall = (first == 0) & (last == self.count - 1) & (self.count > 2)
        ranked = np.lexsort((first[unknowns], last[unknowns]))
        banded = ~overall[unknowns[ranked]]
        order = np.concatenate([ranked[banded], ranked[~banded]])
        local = int(banded.sum())
        position = np.full(self.size, -1)
        position[unknowns[order[:local]]] = np.arange(local)
        width = max(int(np.ptp(p[p >= 0])) for p in (position[c] for c in elements) if np.any(p >= 0))
        return order, local, width

    def block(self, mirror):
        raise ValueError("spectral elements over a tube have no mirror blocks (their bounds need not be "
                         "mirror-symmetric): the mirror-symmetric branches are traced on interval.py's Legendre basis")

    def element_series(self, u: np.ndarray) -> tuple:
        """(λ2's, η's bubble part's) Legendre coefficients in each element's t, each (E, p + 1) (plugged ends:
        λ2's with the 1)."""
        projection = _projections(self)
        k = self.axial_index
        hoop = projection["hoop"] @ u[:k]
        if self.ends == Ends.PLUGGED:
            hoop[:, 0] += 1.0
        return hoop, projection["axial"] @ u[k + 1:]

    def element_tails(self, u: np.ndarray) -> np.ndarray:
        """The geometric_tail of each element's envelope max(|c_j|, |d_j|)/ρ̄ (module docstring), ρ̄ = ∫λ2 dS / L."""
        hoop, axial = self.element_series(u)
        mean = abs(self.weights @ self.node_state(u)[0]) / self.length
        envelope = np.maximum(np.abs(hoop), np.abs(axial)) / mean
        return np.array([geometric_tail(row) for row in envelope])

    def tail(self, u: np.ndarray) -> float:
        """The spectral error estimate of u: the largest of ``element_tails``."""
        return float(self.element_tails(u).max())

    def series(self, u: np.ndarray) -> tuple:
        raise ValueError("spectral elements have one Legendre series per element: element_series")

def element_interval(length: float, order: int, bounds, ends: Ends = Ends.SLIDING, quadrature: int = 0,
                     axial_stretch: float | None = None) -> ElementInterval:
    """The ElementInterval of ``order`` p between inner ``bounds`` (in x) over a tube of ``length``."""
    bounds = tuple(float(b) for b in bounds)
    return ElementInterval((len(bounds) + 1) * order, length, quadrature, ends, axial_stretch, order, bounds)


def collocated(disc: IntervalDiscretisation, u: np.ndarray, onto: ElementInterval) -> np.ndarray:
    """u of ``disc`` (a Legendre series or another layout; one state or rows of states, or of tangents: the map is
    linear) on the layout ``onto`` of the same tube: λ2 and η's bubble part collocated at order + 1 Gauss points of
    each of onto's elements and its inner bounds, by least squares (exact where onto's space holds the state: the
    uniform tube, a layout with elements split or of a higher order)."""
    k, onto_k = disc.axial_index, onto.axial_index
    t, _ = gauss_rule(onto.order + 1)
    edges = onto.edges
    x = np.concatenate([(edges[:-1, None] + 0.5 * np.diff(edges)[:, None] * (t[None, :] + 1.0)).ravel(), edges[1:-1]])
    hoop, _, axial, _ = disc.functions(x)
    onto_hoop, _, onto_axial, _ = onto.functions(x)
    rows = np.atleast_2d(u)
    out = np.empty((rows.shape[0], onto.size))
    out[:, :onto_k] = np.linalg.lstsq(onto_hoop, hoop @ rows[:, :k].T, rcond=None)[0].T
    out[:, onto_k] = rows[:, k]
    out[:, onto_k + 1:] = np.linalg.lstsq(onto_axial, axial @ rows[:, k + 1:].T, rcond=None)[0].T
    return out.reshape(np.shape(u)[:-1] + (onto.size,))


@functools.lru_cache(maxsize=16)
def _local_maps(disc: ElementInterval) -> tuple:
    """Per column group (0: λ2's coefficients, read by (λ2, v); 1: (λ̄, b), by (η, w)): (columns (E, m), maps
    (E, 2, n_e, m)): the columns whose functions are not zero on element e (its hats, bubbles and the global ones)
    and their values at its n_e nodes (the rule's nodes run element by element); rows padded to the largest m with
    a column of zero values."""
    tables = disc.tables
    out = []
    for maps in (tables["hoop_maps"], tables["axial_maps"]):
        per_element = maps.reshape(2, disc.count, -1, maps.shape[2])
        columns = [np.flatnonzero(np.any(per_element[:, e] != 0.0, axis=(0, 1))) for e in range(disc.count)]
        width = max(c.size for c in columns)
        index = np.zeros((disc.count, width), dtype=int)
        local = np.zeros((disc.count, 2, per_element.shape[2], width))
        for e, c in enumerate(columns):
            index[e, : c.size] = c
            local[e, :, :, : c.size] = per_element[:, e][:, :, c]
        out.append((read_only(index), read_only(local)))
    return tuple(out)


@functools.lru_cache(maxsize=16)
def _block_index(disc: ElementInterval, i: int, j: int) -> tuple:
    """(the flat positions of the element blocks' entries in the (i, j) block of the Hessian, its shape)."""
    (rows, _), (columns, _) = _local_maps(disc)[i], _local_maps(disc)[j]
    k = disc.axial_index
    shape = tuple(k if g == 0 else disc.size - k for g in (i, j))
    return read_only((rows[:, :, None] * shape[1] + columns[:, None, :]).ravel()), shape


@functools.lru_cache(maxsize=16)
def _sparse_pattern(disc: ElementInterval) -> tuple:
    """(entry, indices, indptr): the CSC pattern of ``sparse_hessian`` and the position in it of each entry of the
    element blocks (0, 0), (0, 1), their transpose and (1, 1), raveled (padding entries hold zeros)."""
    k, size = disc.axial_index, disc.size
    (hoop, _), (axial, _) = _local_maps(disc)
    offsets = {0: hoop, 1: axial + k}
    rows, columns = [], []
    for i, j, transpose in ((0, 0, False), (0, 1, False), (0, 1, True), (1, 1, False)):
        a, b = np.broadcast_arrays(offsets[i][:, :, None], offsets[j][:, None, :])
        rows.append((b if transpose else a).ravel())
        columns.append((a if transpose else b).ravel())
    keys, entry = np.unique(np.concatenate(columns) * size + np.concatenate(rows), return_inverse=True)
    indptr = np.searchsorted(keys, np.arange(size + 1) * size)
    return read_only(entry.ravel()), read_only(keys % size), read_only(indptr)


@functools.lru_cache(maxsize=16)
def _projections(disc: ElementInterval) -> dict:
    """The maps from λ2's and η's coefficients to each element's Legendre coefficients (E, p + 1, columns): Gauss
    quadrature of degree p + 1 on each element, c_j = (2j + 1)/2 Σ_q w_q f(t_q) P_j(t_q) (exact for degree p)."""
    t, w = gauss_rule(disc.order + 1)
    leg, _ = legendre_table(t, disc.order)
    scale = (2 * np.arange(disc.order + 1) + 1) / 2
    edges = disc.edges
    out = {"hoop": [], "axial": []}
    for e in range(disc.count):
        x = edges[e] + 0.5 * (edges[e + 1] - edges[e]) * (t + 1.0)
        hoop, _, axial, _ = disc.functions(np.clip(x, edges[e], np.nextafter(edges[e + 1], edges[e])))
        weights = (leg * w[:, None] * scale[None, :]).T  # (p + 1, nodes)
        out["hoop"].append(weights @ hoop)
        out["axial"].append(weights @ axial)
    return {name: read_only(np.array(rows)) for name, rows in out.items()}
