"""The resolution of a state of the capsule over (θ, φ) and the refinement of its basis along a branch (the tube's:
tube/surface/resolution.py, the same names: the policy of trace.py). In units of the mean hoop stretch ρ̄ (λ2's
coefficient of φ_0 = 1), per state c:

- the axis tail: the axisymmetric state's own (Discretisation.tail: each element's series);
- the mode tail: per order m ≥ 1 the RMS over the reference surface of what its field loses in its L² projection on
  the perturbation basis DEGREE_STEP degrees lower (capsule_basis' functions are orthonormalised per reflection class,
  not hierarchical: the content of its last degrees is read from the field itself, not from its coefficients);
- the order tail: the RMS of the highest order's field (the next order is smaller by about the amplitude).

RMS: ‖δx‖_G/sqrt(½ ∫ dA), ‖δx‖²_G = cᵀ G c = ½ ∫ (R² + T² + Z²) dA (per 2π). The degree refined is the disc's
(order 0) or the perturbation bases' (m ≥ 1), by DEGREE_STEP where its tail exceeds solver.max_error; the orders by
the next multiple of m.
"""
from dataclasses import replace

import numpy as np


MAX_DEGREE = 256  # the finest degree the policy raises the disc or the perturbation bases to
MAX_HARMONICS = 16  # the most multiples k of the branch's order m (orders 0, m, …, km)
DEGREE_STEP = 8


def _area(basis) -> np.ndarray:
    W, R, _, rate = basis.rule()
    return W * R * rate


def _full(basis, m: int, block: np.ndarray) -> np.ndarray:
    """The order's coefficients on its whole CapsuleBasis (the columns ``equator`` leaves out zero)."""
    out = np.zeros(basis.perturbations(m).size)
    out[basis.kept(m)] = block
    return out


def projected(field: np.ndarray, theta_values, target) -> np.ndarray:
    """The coefficients on the CapsuleBasis ``target`` of the L² projection of a field whose (R, Z, T) at any θ are
    ``theta_values(θ)`` (CapsuleBasis.displacement of another basis): G⁻¹ ½ Σ_q area_q (R, T, Z) · (F_R, F_T, F_Z)."""
    R, Z, T = theta_values(field, target.theta)
    return np.linalg.solve(target.gram, target.moments.T @ np.concatenate([R, T, Z]))


def tails(basis, c: np.ndarray) -> tuple:
    """(the axis tail, the mode tail, the order tail) of c (module docstring)."""
    radius = abs(basis.disc.split(c[basis.block(0)])[0][0])
    area = _area(basis)
    scale = radius * np.sqrt(0.5 * area.sum())
    lost = [0.0]
    for m in basis.orders[1:]:
        b, full = basis.perturbations(m), _full(basis, m, c[basis.block(m)])
        lower = basis.perturbations(m, basis.mode_degree - DEGREE_STEP)
        back = lower.displacement(projected(full, b.displacement, lower), b.theta)
        here = np.array(b.displacement(full, b.theta))
        lost.append(np.sqrt(0.5 * area @ ((here - back) ** 2).sum(axis=0)))
    top = c[basis.block(basis.orders[-1])] if len(basis.orders) > 1 else np.zeros(0)
    order_tail = np.sqrt(top @ basis.gram(basis.orders[-1]) @ top) if top.size else 0.0
    return basis.disc.tail(c[basis.block(0)]), max(lost) / scale, float(order_tail) / scale


def error_estimate(basis, c: np.ndarray) -> float:
    """The largest of the ``tails``: the error estimate of a point of a branch."""
    return max(tails(basis, c))


def refined(basis, c: np.ndarray, m: int, max_error: float):
    """The next basis for c, a state of the branch born at an m-th zero (module docstring): ``basis`` itself when
    every tail is below ``max_error``; None when a degree would pass MAX_DEGREE or the multiples MAX_HARMONICS."""
    axis_tail, mode_tail, order_tail = tails(basis, c)
    degree = basis.disc.degree + DEGREE_STEP * (axis_tail > max_error)
    mode_degree = basis.mode_degree + DEGREE_STEP * (mode_tail > max_error)
    k = len(basis.orders) - 1 + (order_tail > max_error)
    if max(degree, mode_degree) > MAX_DEGREE or k > MAX_HARMONICS:
        return None
    if (degree, mode_degree, k) == (basis.disc.degree, basis.mode_degree, len(basis.orders) - 1):
        return basis
    disc = basis.disc if degree == basis.disc.degree else replace(basis.disc, degree=degree, quadrature=0)
    return type(basis)(disc, basis.geometry, mode_degree, tuple(m * j for j in range(k + 1)), 0, basis.equator)
