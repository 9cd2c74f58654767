"""The resolution of a state of the tube over (S, φ) and the policy that refines its basis along a branch (as the
sphere's analysis/surface/resolution.py): the error estimate of a state, and, where it exceeds solver.max_error, the
next basis from the fitted decay of its coefficients, in the Legendre degree and in the Fourier order separately.

In units of the mean radius ρ̄ (λ2's Legendre coefficient of degree 0), per state c:

- the degree tail: discretisation.geometric_tail of the envelope e_k = max over the orders and their fields of the
  Legendre coefficient of degree k (a bubble series Σ b_k (P_{k+2} − P_k) read as Legendre coefficients b_{k−2} − b_k,
  galerkin/interval.py ``series``): at order 0 alone this is IntervalDiscretisation.tail;
- the order tail: the largest coefficient of the highest order (the next order is smaller by about the amplitude, so
  this bounds what the truncation in φ cuts off).

The orders of a branch born at an m-th zero are the multiples 0, m, …, km of its dihedral symmetry (MODEL.md §8).
"""
from dataclasses import replace

import numpy as np

from .basis import TubeSurfaceBasis
from ...analysis.surface.resolution import increment
from ...galerkin.discretisation import geometric_tail

MAX_DEGREE = 96  # the finest Legendre degree the policy raises to
MAX_HARMONICS = 16  # the most multiples k of the branch's order m (orders 0, m, …, km)
DEGREE_STEP, ORDER_STEP = 4, 1  # the smallest increments (in the degree; in the multiples of m)


def _legendre(coefficients: np.ndarray, degree: int) -> np.ndarray:
    """The Legendre coefficients of degree 0..N of a field: itself on P_0..P_N, a bubble series read as above."""
    if coefficients.size == degree + 1:
        return coefficients
    out = np.zeros(degree + 1)
    out[2:] += coefficients
    out[:degree - 1] -= coefficients
    return out


def spectra(basis: TubeSurfaceBasis, c: np.ndarray) -> tuple:
    """(e_k for k = 0..N over ρ̄, the largest coefficient of each order over ρ̄) of c (module docstring)."""
    degree = basis.disc.degree
    hoop, axial = basis.disc.series(c[basis.block(0)])
    radius = abs(hoop[0])
    envelope = np.maximum(np.abs(hoop), np.abs(axial))
    by_order = [1.0]
    for m in basis.orders[1:]:
        block, start = c[basis.block(m)], 0
        for size in basis.fields(m):
            envelope = np.maximum(envelope, np.abs(_legendre(block[start:start + size], degree)))
            start += size
        by_order.append(float(np.max(np.abs(block))) / radius)
    return envelope / radius, np.array(by_order)


def tails(basis: TubeSurfaceBasis, c: np.ndarray) -> tuple:
    """(the degree tail, the order tail) of c (module docstring)."""
    return _tails(basis, *spectra(basis, c))


def _tails(basis: TubeSurfaceBasis, by_degree: np.ndarray, by_order: np.ndarray) -> tuple:
    """(the degree tail, the order tail) of a state's ``spectra``."""
    return geometric_tail(by_degree), (float(by_order[-1]) if len(basis.orders) > 1 else 0.0)


def error_estimate(basis: TubeSurfaceBasis, c: np.ndarray) -> float:
    """The larger of the ``tails``: the error estimate of a point of a branch."""
    return max(tails(basis, c))


def harmonics(m: int, k: int) -> tuple:
    """The orders 0, m, …, km."""
    return tuple(m * j for j in range(k + 1))


def refined(basis: TubeSurfaceBasis, c: np.ndarray, m: int, max_error: float) -> TubeSurfaceBasis | None:
    """The next basis for c, a state of the branch born at an m-th zero: where a tail exceeds ``max_error``, the
    degree and the number of multiples of m extended as far as the geometric decay fitted to the last coefficients
    (analysis/surface/resolution.increment) predicts is needed for a tail of max_error/4; ``basis`` itself when both
    tails are below max_error; None when the degree would pass MAX_DEGREE or the multiples MAX_HARMONICS."""
    by_degree, by_order = spectra(basis, c)
    degree_tail, order_tail = _tails(basis, by_degree, by_order)
    degree, k = basis.disc.degree, len(basis.orders) - 1
    if degree_tail > max_error:
        degree += increment(by_degree, max_error / 4, DEGREE_STEP, 4 * DEGREE_STEP)
    if order_tail > max_error:
        k += increment(by_order, max_error / 4, ORDER_STEP, 4 * ORDER_STEP)
    if degree > MAX_DEGREE or k > MAX_HARMONICS:
        return None
    if degree == basis.disc.degree and k == len(basis.orders) - 1:
        return basis
    disc = basis.disc if degree == basis.disc.degree else replace(basis.disc, degree=degree, quadrature=0)
    return TubeSurfaceBasis(disc, harmonics(m, k))
