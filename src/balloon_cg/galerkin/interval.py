"""Ritz–Galerkin discretisation of a meridian over an interval without poles: a tube over its arclength S ∈ [0, L].

The sibling of discretisation.py (Legendre in cos θ between two poles) for a meridian whose ends are not on the
axis (codegen/meridian.py: R = 1, R' = 0, S' = 1, Z = −S). In x = 2S/L − 1 ∈ [−1, 1]

    λ2(x) = Σ_{k=0}^{N} a_k P_k(x),      η(x) = −λ̄ (L/2) x + Σ_{k=0}^{N−2} b_k (P_{k+2} − P_k)(x),

u = (a_0..a_N, λ̄, b_0..b_{N−2}) (2N + 1 unknowns). The bubbles P_{k+2} − P_k vanish at x = ±1, so η(±1) = ∓λ̄L/2: the
ends are the planes Z = ±λ̄L/2, η fixed on each, their distance λ̄L an unknown (closed ends: its equation is the axial
balance, the ends carrying the pressure on their faces) or held (``axial_stretch`` λ: λ̄ = λ stays in u, fixed, and its
row, the axial balance, is not an equation; ``free`` lists the other unknowns). Sliding ends (planes of symmetry) leave
the radius free there (ρ' = 0 is the natural end condition); plugged ends (rigid plugs of the reference radius) hold
ρ(±1) = 1: λ2 = 1 + Σ_{k=0}^{N−2} a_k (P_{k+2} − P_k)(x), u = (a_0..a_{N−2}, λ̄, b) (2N − 1 unknowns). At a node

    ρ = λ2 R = λ2,   v = λ2' R = (2/L) dλ2/dx,   w = η' = (2/L) dη/dx,

and the energy E/(2π) = ∫_0^L π̂ dS = (L/2) Σ_q w_q π̂(x_q) by Gauss–Legendre quadrature (π̂ = Π/R, R = 1: the
tube's kernels). The uniform tube (λ2 = λθ, η = −λz(S − L/2)) is exact in the basis: a_0 = λθ, λ̄ = λz, the rest 0.

Mirror symmetry S → L − S (x → −x) in place of the sphere's equator symmetry: a state is mirror-symmetric when λ2
is even and η odd in x, i.e. its a_odd and b_even vanish (P_{k+2} − P_k has the parity of k); the Hessian of a
symmetric state splits into the even block (a_even, λ̄, b_odd) and the odd block (a_odd, b_even), whose first
modes are the bulge modes cos(πS/L) (odd: a bulge at one end, a neck at the other) and cos(2πS/L) (even).

The node arrays ``cos_theta`` and ``sin_theta`` hold the meridian's R' = 0 and R = 1 (the names of the sphere's
node values, for galerkin/equilibrium.py and model/meridian.py: λ1 = sqrt((λ2 R' + v)² + w²)/S', the field at
(λ2 R, η)); the tube's kernels take neither.
"""
import enum
import functools
from dataclasses import dataclass

import numpy as np

from .discretisation import HESSIAN_ROW, gauss_nodes, geometric_tail, read_only
from .legendre import gauss_rule, legendre_table
from ..scene.tables import Ends

CREST_SAMPLES = 401  # the samples of ρ(S) the crest is searched on (``IntervalDiscretisation.crests``)
CREST_BISECTIONS = 52  # halvings of a sample interval: to the rounding of x ∈ [−1, 1]


class Mirror(enum.StrEnum):
    """A block of the second variation of a mirror-symmetric state (module docstring)."""

    EVEN = "even"
    ODD = "odd"


@dataclass(frozen=True)
class IntervalDiscretisation:
    """Legendre ``degree`` N over a tube of ``length`` L (reference radii) with ``ends``, ``quadrature`` Gauss nodes
    (0: the sphere's default rule at N, discretisation.gauss_nodes), the ends' distance over L held at
    ``axial_stretch`` (None: an unknown)."""

    degree: int
    length: float
    quadrature: int = 0
    ends: Ends = Ends.SLIDING
    axial_stretch: float | None = None

    def __post_init__(self):
        if self.degree < 2:
            raise ValueError(f"an interval discretisation needs degree ≥ 2 (the bubbles of η), not {self.degree}")

    @property
    def hoops(self) -> int:
        """The number of λ2's coefficients: N + 1 (sliding ends), N − 1 (plugged: bubbles about λ2 = 1)."""
        return self.degree + 1 if self.ends == Ends.SLIDING else self.degree - 1

    @property
    def size(self) -> int:
        return self.hoops + self.degree

    @property
    def axial_index(self) -> int:
        """The position of λ̄ (the ends' distance over L) in u."""
        return self.hoops

    @property
    def tables(self) -> dict:
        """The node tables (``_tables``: nodes, weights per dS, R' and R, the state maps), cached per disc."""
        return _tables(self)

    def rule(self) -> tuple:
        """(x, w): the Gauss–Legendre rule in x (``quadrature`` nodes; 0: the sphere's default rule at N)."""
        return gauss_rule(self.quadrature or gauss_nodes(self.degree))

    def functions(self, x: np.ndarray) -> tuple:
        """(λ2's basis functions, their d/dx, η's bubbles, their d/dx) at the points x, each (len(x), count): λ2's
        P_0..P_N (sliding) or the bubbles P_{k+2} − P_k about 1 (plugged), η's P_{k+2} − P_k, k = 0..N − 2."""
        n = self.degree
        p, dp = legendre_table(np.asarray(x, dtype=float), n)
        bubbles, slopes = p[:, 2:] - p[:, : n - 1], dp[:, 2:] - dp[:, : n - 1]
        return (p, dp, bubbles, slopes) if self.ends == Ends.SLIDING else (bubbles, slopes, bubbles, slopes)

    @property
    def x(self) -> np.ndarray:
        return self.tables["x"]

    @property
    def weights(self) -> np.ndarray:
        """(L/2) w_q: the quadrature weights per dS."""
        return self.tables["weights"]

    @property
    def cos_theta(self) -> np.ndarray:
        """R' = 0 at the nodes (module docstring)."""
        return self.tables["rate"]

    @property
    def sin_theta(self) -> np.ndarray:
        """R = 1 at the nodes (module docstring)."""
        return self.tables["radius"]

    @property
    def maps(self) -> np.ndarray:
        """(4, n_q, size): the node values of (λ2, v, η, w) as linear maps of u (the state is T u)."""
        return self.tables["maps"]

    def node_state(self, u: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """(λ2, v, η, w) at the nodes, (4, n_q), into ``out`` if given (plugged ends: λ2's 1 added)."""
        out = np.matmul(self.maps, u, out=out)
        if self.ends == Ends.PLUGGED:
            out[0] += 1.0
        return out

    def gradient(self, pointwise: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """∂E/∂u = Σ_q W_q Σ_k ∂π̂/∂s_k T_k[q] from ``pointwise`` (4, n_q): energy_gradient at the nodes."""
        return np.einsum("kq,kqj->j", pointwise * self.weights, self.maps, out=out)

    def hessian(self, pointwise: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """∂²E/∂u² = Σ_kl T_kᵀ diag(W h_kl) T_l from ``pointwise`` (10, n_q): energy_hessian at the nodes, into the
        leading columns of ``out`` if given (a bordered Jacobian's). λ2 and v are maps of λ2's coefficients only,
        η and w of (λ̄, b) only, so each of the three blocks is one product over its own columns."""
        weighted = pointwise * self.weights
        out = np.zeros((self.size, self.size)) if out is None else out
        k = self.axial_index
        columns = (slice(0, k), slice(k, self.size))
        for i, j in ((0, 0), (0, 1), (1, 1)):
            h = weighted[HESSIAN_ROW[2 * i: 2 * i + 2, 2 * j: 2 * j + 2]]  # (2, 2, n_q): W h_kl of the block
            block = self.hessian_block(i, j, h)
            out[columns[i], columns[j]] = block
            if i != j:
                out[columns[j], columns[i]] = block.T
        return out

    def hessian_block(self, i: int, j: int, h: np.ndarray) -> np.ndarray:
        """Σ_kl T_kᵀ diag(W h_kl) T_l of the column groups i, j (0: λ2's coefficients, read by (λ2, v); 1: (λ̄, b),
        by (η, w)); ``h`` (2, 2, n_q) the weighted h_kl."""
        maps = (self.tables["hoop_maps"], self.tables["axial_maps"])  # (2, n_q, columns): (λ2, v), (η, w)
        scaled = h[:, 0, :, None] * maps[j][0] + h[:, 1, :, None] * maps[j][1]  # Σ_l W h_kl T_l
        return maps[i].reshape(-1, maps[i].shape[2]).T @ scaled.reshape(-1, maps[j].shape[2])

    def hessian_product(self, pointwise: np.ndarray, w: np.ndarray) -> np.ndarray:
        """(∂²E/∂u²) w = Σ_kl T_kᵀ diag(W h_kl) T_l w without the matrix: the node values T w (``node_state``, the
        plugged ends' constant taken off), h_kl applied at each node, then ``gradient``."""
        change = self.node_state(w)
        if self.ends == Ends.PLUGGED:
            change[0] -= 1.0
        return self.gradient(np.einsum("klq,lq->kq", pointwise[HESSIAN_ROW], change))

    def uniform(self, hoop: float, axial: float) -> np.ndarray:
        """u of the uniform tube with sliding ends: λ2 = λθ, η = −λz(S − L/2)."""
        if self.ends != Ends.SLIDING:
            raise ValueError(f"a tube with {self.ends.value} ends is not uniform")
        u = np.zeros(self.size)
        u[0], u[self.axial_index] = hoop, axial
        return u

    def reference(self) -> np.ndarray:
        """u of the unstressed tube (λ2 = 1, η = −(S − L/2)); held ends: at their distance (η = −λ(S − L/2))."""
        u = np.zeros(self.size)
        u[self.axial_index] = self.axial_stretch if self.held else 1.0
        if self.ends == Ends.SLIDING:
            u[0] = 1.0
        return u

    @property
    def free(self) -> np.ndarray:
        """The indices into u of the unknowns: all but λ̄ where the ends are held."""
        return np.flatnonzero(np.arange(self.size) != (self.axial_index if self.held else -1))

    @property
    def held(self) -> bool:
        """Whether the ends' distance is held (``axial_stretch``)."""
        return self.axial_stretch is not None

    def block(self, mirror: Mirror) -> np.ndarray:
        """The indices into u of a mirror block's unknowns (module docstring; λ̄, even, where it is one)."""
        parity = 0 if mirror == Mirror.EVEN else 1
        a = np.arange(parity, self.hoops, 2)
        b = self.hoops + 1 + np.arange(1 - parity, self.degree - 1, 2)
        axial = [self.axial_index] if mirror == Mirror.EVEN and not self.held else []
        return np.concatenate([a, axial, b]).astype(int)

    def profile(self, u: np.ndarray, s: np.ndarray) -> tuple:
        """(ρ, η) at reference arclengths s ∈ [0, L]."""
        x = 2 * np.asarray(s, dtype=float) / self.length - 1
        hoop, _, bubbles, _ = self.functions(x)
        k = self.axial_index
        rho = hoop @ u[:k] + (0.0 if self.ends == Ends.SLIDING else 1.0)
        return rho, -u[k] * self.length / 2 * x + bubbles @ u[k + 1:]

    def series(self, u: np.ndarray) -> tuple:
        """(λ2's Legendre coefficients c_0..c_N, those of η's bubble part Σ b_k (P_{k+2} − P_k)): the bubbles'
        coefficients c_k = b_{k−2} − b_k (plugged ends: λ2 = 1 + bubbles, c_0 with the 1)."""
        k, n = self.axial_index, self.degree

        def bubbles(b):
            c = np.zeros(n + 1)
            c[2:] += b
            c[: n - 1] -= b
            return c

        hoop = u[:k].copy() if self.ends == Ends.SLIDING else bubbles(u[:k])
        if self.ends == Ends.PLUGGED:
            hoop[0] += 1.0
        return hoop, bubbles(u[k + 1:])

    def tail(self, u: np.ndarray) -> float:
        """Spectral error estimate of u, the sphere's (discretisation.geometric_tail): the neglected tail E·r/(1 − r)
        of the envelope max(|c_k|, |d_k|)/|c_0| of λ2's and η's bubble part's Legendre coefficients (``series``),
        in units of the mean radius c_0. Zero on the uniform tube (exact in the basis)."""
        hoop, axial = self.series(u)
        return geometric_tail(np.maximum(np.abs(hoop), np.abs(axial)) / abs(hoop[0]))

    def radius(self, states: np.ndarray, x: np.ndarray) -> tuple:
        """(ρ, dρ/dx) of each state (rows of ``states``) at its own point x_i ∈ [−1, 1]."""
        hoop, slope, _, _ = self.functions(x)
        a = np.atleast_2d(states)[:, : self.axial_index]
        rho = np.einsum("ij,ij->i", hoop, a) + (0.0 if self.ends == Ends.SLIDING else 1.0)
        return rho, np.einsum("ij,ij->i", slope, a)

    def crests(self, states: np.ndarray) -> tuple:
        """(S, η) of each state's crest, its largest radius ρ: the reference arclength and the height (measured from
        the tube's middle plane, where a mirror-symmetric field's coils lie). The largest of ρ on CREST_SAMPLES evenly
        spaced S, refined between its neighbours: the crest is the largest ρ among the neighbours, the sample and
        the roots of ρ' (found by bisection to rounding) on each side where ρ' falls through zero."""
        states = np.atleast_2d(np.asarray(states, dtype=float))
        grid = np.linspace(-1.0, 1.0, CREST_SAMPLES)
        k = self.axial_index
        top = np.argmax(states[:, :k] @ self.functions(grid)[0].T, axis=1)
        candidates = [grid[np.maximum(top - 1, 0)], grid[top], grid[np.minimum(top + 1, grid.size - 1)]]
        for lo, hi in ((candidates[0], candidates[1]), (candidates[1], candidates[2])):
            falls = (self.radius(states, lo)[1] > 0) & (self.radius(states, hi)[1] < 0)
            lo, hi = lo.copy(), hi.copy()
            for _ in range(CREST_BISECTIONS):
                mid = 0.5 * (lo + hi)
                rising = self.radius(states, mid)[1] > 0
                lo, hi = np.where(rising, mid, lo), np.where(rising, hi, mid)
            candidates.append(np.where(falls, 0.5 * (lo + hi), candidates[1]))
        x = np.array(candidates)
        heights = np.array([self.radius(states, c)[0] for c in x])
        best = x[np.argmax(heights, axis=0), np.arange(len(states))]
        eta = -states[:, k] * self.length / 2 * best + np.einsum("ij,ij->i", self.functions(best)[2], states[:, k + 1:])
        return (best + 1) * self.length / 2, eta

    def crest(self, u: np.ndarray) -> tuple:
        """(S, η) of the crest of one state u (``crests``)."""
        S, eta = self.crests(u[None])
        return float(S[0]), float(eta[0])


@functools.lru_cache(maxsize=16)
def _tables(disc: IntervalDiscretisation) -> dict:
    """Nodes, weights per dS, the meridian's R' and R at the nodes and the state maps (read-only; also split by the
    columns each reads: (λ2, v) of λ2's coefficients, (η, w) of (λ̄, b)), from the disc's ``rule`` and ``functions``."""
    length = disc.length
    x, w = disc.rule()
    hoop, rate, bubbles, slopes = disc.functions(x)
    k = disc.axial_index
    maps = np.zeros((4, x.size, disc.size))
    maps[0, :, :k], maps[1, :, :k] = hoop, 2 / length * rate
    maps[2, :, k] = -length / 2 * x
    maps[2, :, k + 1:] = bubbles
    maps[3, :, k] = -1.0
    maps[3, :, k + 1:] = 2 / length * slopes
    tables = {"x": x, "weights": length / 2 * w, "rate": np.zeros_like(x), "radius": np.ones_like(x), "maps": maps,
              "hoop_maps": maps[:2, :, :k].copy(), "axial_maps": maps[2:, :, k:].copy()}
    return {name: read_only(table) for name, table in tables.items()}
