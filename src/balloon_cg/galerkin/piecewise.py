"""A C⁰ piecewise-polynomial basis on elements of the wire-mapped coordinate s = h(x) (x = cos θ): the banded
sibling of the Legendre series P_k(s) for the perturbations of the second variation (analysis/stability/banded.py).

The interval s ∈ [−1, 1] (or its half [0, 1]: the blocks of an equator-symmetric state, whose integrands are even)
is cut into E elements of equal length in s (the map already clusters them where a wire needs resolution); on
element e, s = s_e + (t + 1) Δs/2, t ∈ [−1, 1], and the element's functions are hierarchical (as the capsule's
bubbles, galerkin/elements.py):

    the vertex hats (1 − t)/2 and (1 + t)/2,    the bubbles B_j = P_j(t) − P_{j−2}(t), j = 2..p (zero at t = ±1),

joined C⁰ at the element boundaries: conforming for the energy, which holds first derivatives only. A function
polynomial in s on the pole element is smooth in x there (h is analytic with h' > 0), as the Legendre series is:
no end condition at the poles. Numbering per field: vertex e at e·p, element e's bubbles at e·p + 1 .. e·p + p − 1,
so each element's functions are consecutive; two fields (δλ2, δη) interleave (2i + field), every element's
2(p + 1) functions are consecutive and the Galerkin matrices are banded with half-bandwidth 2p + 1. On the half
interval a field odd in x vanishes at s = 0: its vertex there is ``dropped``.

Quadrature: Gauss–Legendre with ``quadrature`` nodes per element in t, x = g(s) (``WireMap.x``), weights
w_q Δs/2 / h'(x_q) (dx = ds/h'), doubled on the half interval (the even integrand's other half); d/dx = h'(x) (2/Δs) d/dt.
"""
import functools
from dataclasses import dataclass

import numpy as np

from .coordinate_map import WireMap
from .legendre import gauss_rule, legendre_table


def shape_functions(t: np.ndarray, order: int):
    """(φ_r(t), dφ_r/dt) of one element, r = 0..p: r = 0 the left hat (1 − t)/2, r = 1..p − 1 the bubbles
    P_{r+1} − P_{r−1}, r = p the right hat (1 + t)/2; each of shape (len(t), p + 1)."""
    p, dp = legendre_table(np.asarray(t, dtype=float), order)
    phi, dphi = np.empty((t.size, order + 1)), np.empty((t.size, order + 1))
    phi[:, 0], dphi[:, 0] = 0.5 * (1.0 - t), -0.5
    phi[:, order], dphi[:, order] = 0.5 * (1.0 + t), 0.5
    for r in range(1, order):
        phi[:, r] = p[:, r + 1] - p[:, r - 1]
        dphi[:, r] = dp[:, r + 1] - dp[:, r - 1]
    return phi, dphi


@dataclass(frozen=True)
class PiecewiseBasis:
    """E ``elements`` of polynomial ``order`` p in s (module docstring) with ``quadrature`` Gauss nodes each, on
    ``mapping`` (None: s = x), over [−1, 1] or with ``half`` over [0, 1]; hashable (its tables are cached)."""

    elements: int
    order: int
    quadrature: int
    mapping: WireMap | None = None
    half: bool = False

    def __post_init__(self):
        if self.elements < 1 or self.order < 1 or self.quadrature < self.order + 1:
            raise ValueError(f"PiecewiseBasis: elements = {self.elements}, order = {self.order}, quadrature = "
                             f"{self.quadrature}: need elements ≥ 1, order ≥ 1, quadrature ≥ order + 1")
        for name, value in _tables(self).items():
            object.__setattr__(self, name, value)

    @property
    def functions(self) -> int:
        """Functions per field: E·p + 1."""
        return self.elements * self.order + 1

    def dofs(self, dropped: tuple = (), fields: int = 2) -> np.ndarray:
        """The global index of each element's F(p + 1) local functions of F = ``fields`` interleaved fields
        (local F·r + field: r as ``shape_functions``; m = 0: field 0 δλ2, 1 δη), shape (E, F(p + 1)); −1 for the
        functions of ``dropped`` (field numbers whose vertex at s = 0 is removed: on the half interval, the fields
        odd in x), the rest numbered consecutively."""
        return _dofs(self, tuple(sorted(dropped)), fields)


def _dofs(basis: PiecewiseBasis, dropped: tuple, fields: int) -> np.ndarray:
    p = basis.order
    per_field = np.arange(basis.elements)[:, None] * p + np.arange(p + 1)[None, :]  # (E, p + 1)
    index = np.empty((basis.elements, fields * (p + 1)), dtype=np.int64)
    for field in range(fields):
        index[:, field::fields] = fields * per_field + field
    if dropped and not basis.half:
        raise ValueError("PiecewiseBasis.dofs: only the half interval has a vertex at s = 0 to drop")
    removed = np.zeros(fields * basis.functions, dtype=bool)
    removed[list(dropped)] = True  # field f's vertex at s = 0 is global F·0 + f
    numbers = np.cumsum(~removed) - 1
    out = numbers[index]
    out[removed[index]] = -1
    out.flags.writeable = False
    return out


@functools.lru_cache(maxsize=16)
def _tables(basis: PiecewiseBasis) -> dict:
    """Nodes s and x (E, n_q), weights (dx, doubled on the half interval), φ and dφ/dx of the local functions
    (E, n_q, p + 1), read-only."""
    t, w = gauss_rule(basis.quadrature)
    low = 0.0 if basis.half else -1.0
    bounds = np.linspace(low, 1.0, basis.elements + 1)
    width = np.diff(bounds)[:, None]
    s = bounds[:-1, None] + 0.5 * (t[None, :] + 1.0) * width
    if basis.mapping is None:
        x, slope = s, np.ones_like(s)
    else:
        x = basis.mapping.x(s.ravel()).reshape(s.shape)
        slope = basis.mapping.ds_dx(x.ravel()).reshape(x.shape)
    weights = (2.0 if basis.half else 1.0) * 0.5 * width * w[None, :] / slope
    phi, dphi = shape_functions(t, basis.order)
    derivative = dphi[None, :, :] * (2.0 * slope / width)[:, :, None]  # d/dx = h'(x) (2/Δs) d/dt
    tables = {"s": s, "x": x, "weights": weights, "phi": np.broadcast_to(phi, (basis.elements, *phi.shape)).copy(),
              "dphi_dx": derivative, "bounds": bounds}
    for array in tables.values():
        array.flags.writeable = False
    return tables
