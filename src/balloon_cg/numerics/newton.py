"""Newton's method for square systems assembled from n equations plus bordering rows.

Solves R(X) = 0 (n equations, X of size n + k) together with k linear rows C X = d, which fix what the
equations leave free: a pseudo-arclength condition, a prescribed pole stretch or a fixed parameter.
Every loop is bounded; the result says whether it converged and why not.

The Jacobian is evaluated and LU-factored only when it is needed (simplified Newton, Hairer & Wanner, *Solving
ODEs II*, §IV.8): it is reused while the corrections contract fast enough (``REFRESH_RATIO``) and refreshed at
the current iterate as soon as they do not. The slow step is then dropped, so every accepted step is a Newton
step or a chord step that contracted fast, and the observed ratios estimate the contraction. With a fresh
Jacobian every iteration this is plain Newton; from a good start (a continuation predictor, a neighbouring
solution) one or two factorisations serve the whole solve, and the other iterations cost one residual each.
Converged when both the last correction and the error estimate ρ/(1 − ρ)·|dx| (observed contraction
ρ = |dx_k|/|dx_{k−1}|, Hairer & Wanner IV.8.10) are below the tolerance.
"""
import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.linalg.lapack import dgetrf, dgetrs  # LAPACK directly: scipy.linalg's wrappers cost ~10-20 µs a call

# A stale Jacobian is kept while |dx_k| ≤ ratio·|dx_{k−1}|. A Jacobian (assembly and LU) costs about two
# residuals below ~100 unknowns, where call overhead dominates, and about eight at 200 (O(n_q n²) assembly):
# small systems refresh early, large ones ride the chord longer (Hairer & Wanner's advice for costly Jacobians).
# Measured on the baseline points (benchmarks/baselines.py): best of {1e-3, 1e-2, 1e-1} at each size.
REFRESH_RATIO = 0.01
REFRESH_RATIO_LARGE = 0.1
LARGE_SYSTEM = 100
# below this many unknowns the correction is one jitted call (``_correction``: right-hand side, LU substitutions
# and scaled size), from it LAPACK's dgetrs between two jitted calls: 0.6 µs against 3.1 at 10 unknowns, 1.1
# against 3.3 at 30, equal at 50, 12 against 9 at 100 (single-threaded, on a loaded machine)
SMALL_SOLVE = 50


@dataclass
class NewtonResult:
    x: np.ndarray
    converged: bool
    iterations: int  # corrections computed (a dropped stale-Jacobian correction counts too)
    residual: float  # max-norm of R at the returned x
    step: float  # the last correction in the scaled max-norm max_i |dx_i|/(1 + |x_i|)
    message: str
    jacobians: int = 0  # Jacobian evaluations and factorisations
    factors: tuple | None = None  # converged: dgetrf's (lu, pivots) of the last [∂R/∂x; rows] (at an earlier iterate)


def newton(residual, jacobian, x0, rows, targets, tol: float, max_iter: int,
           factors: tuple | None = None) -> NewtonResult:
    """Solve R(x) = 0, rows @ x = targets; converged when the correction and the estimated error are below tol in
    the scaled max-norm max_i |dx_i|/(1 + |x_i|) (absolute for small components, relative for large ones: a
    pressure of 10³ does not loosen the tolerance on the shape coefficients). ``factors``: dgetrf's factors of
    [∂R/∂x; rows] at a neighbouring point with the same rows (a NewtonResult's), the chord to start from: stale,
    refreshed as soon as its corrections contract too slowly.

    Near a singular point Newton converges only linearly (ratio ρ) even with a fresh Jacobian, and the
    remaining error ρ/(1 − ρ)|dx| may exceed |dx|: the estimate accounts for that.

    ``residual(x)`` returns R (n), ``jacobian(x)`` returns ∂R/∂x (n × (n + k)); rows is (k, n + k).
    """
    x = np.array(x0, dtype=float)
    refresh_ratio = REFRESH_RATIO_LARGE if x.size >= LARGE_SYSTEM else REFRESH_RATIO
    rows = np.array(rows, dtype=float, ndmin=2, copy=None)  # as np.atleast_2d, np.atleast_1d: one C call each
    targets = np.array(targets, dtype=float, ndmin=1)
    previous = np.inf
    fresh, jacobians, growth = False, 0, 0
    r, step = None, np.inf
    n = x.size - rows.shape[0]  # equations R
    matrix = np.empty((x.size, x.size), order="F")  # [∂R/∂x; rows], factored in place (LAPACK's column order)
    rhs = np.empty(x.size)
    for iteration in range(1, max_iter + 1):
        try:
            if r is None:
                r = residual(x)
            if factors is None:
                matrix[:n] = jacobian(x)
                matrix[n:] = rows
                lu, pivots, info = dgetrf(matrix, overwrite_a=True)
                factors, fresh, jacobians = (lu, pivots), True, jacobians + 1
                if info != 0:
                    message = "singular Newton matrix" if info > 0 else "invalid Newton matrix"
                    return _failed(x, iteration, r, np.inf, message, jacobians)
        except ArithmeticError as error:
            return NewtonResult(x, False, iteration, np.inf, np.inf, f"state left the domain: {error}", jacobians)
        if x.size < SMALL_SOLVE:
            dx, step = rhs, _correction(*factors, r, rows, targets, x, rhs)
        else:
            _right_hand_side(r, rows, targets, x, rhs)
            dx, _ = dgetrs(*factors, rhs)
            step = _scaled_size(dx, x)
        if not math.isfinite(step):
            return _failed(x, iteration, r, np.inf, "non-finite Newton step", jacobians)
        ratio = step / previous if math.isfinite(previous) and previous > 0 else None
        if ratio is not None and ratio > refresh_ratio and not fresh:
            factors = None  # a stale Jacobian contracts too slowly: drop its step, redo it with a fresh one here
            continue
        fresh = False
        x = x + dx
        r = None
        error = step if ratio is None else max(step, step * min(ratio, 0.99) / (1.0 - min(ratio, 0.99)))
        if error <= tol:
            try:
                final = max_abs(residual(x))
            except ArithmeticError as failure:
                return NewtonResult(x, False, iteration, np.inf, step, f"state left the domain: {failure}",
                                    jacobians)
            if not math.isfinite(final):
                return NewtonResult(x, False, iteration, final, step, "non-finite residual at the solution", jacobians)
            return NewtonResult(x, True, iteration, final, step, "converged", jacobians, factors)
        growth = growth + 1 if step > previous else 0
        if growth >= 3:
            return NewtonResult(x, False, iteration, np.inf, step, "Newton corrections grow", jacobians)
        previous = step
    return NewtonResult(x, False, max_iter, np.inf, step, f"no convergence in {max_iter} iterations", jacobians)


@njit(cache=True)
def finite(a) -> bool:
    """Whether every entry of the array ``a`` is finite."""
    for value in a.ravel():
        if not math.isfinite(value):
            return False
    return True


@njit(cache=True)
def max_abs(a) -> float:
    """max_i |a_i| of a 1-D array, NaN if an entry is NaN (as np.abs(a).max())."""
    size = 0.0
    for value in a:
        if math.isnan(value):
            return math.nan
        size = max(size, abs(value))
    return size


@njit(cache=True)
def _right_hand_side(r, rows, targets, x, rhs):
    """rhs = (−R, targets − rows·x)."""
    n = r.shape[0]
    for i in range(n):
        rhs[i] = -r[i]
    for k in range(rows.shape[0]):
        total = 0.0
        for j in range(x.shape[0]):
            total += rows[k, j] * x[j]
        rhs[n + k] = targets[k] - total  # returns nothing: boxing a returned array costs ~0.4 µs a call


@njit(cache=True)
def _correction(lu, pivots, r, rows, targets, x, dx) -> float:
    """The Newton correction dx = A⁻¹ (−R, targets − rows·x) from dgetrf's factors P A = L U (``lu`` column-major,
    ``pivots`` 0-based as scipy returns them: row i was interchanged with row pivots[i]) by LAPACK dgetrs'
    column-oriented substitutions, into ``dx``; returns ``_scaled_size(dx, x)``."""
    _right_hand_side(r, rows, targets, x, dx)
    size = dx.shape[0]
    for i in range(size):
        p = pivots[i]
        if p != i:
            dx[i], dx[p] = dx[p], dx[i]
    for j in range(size):  # L y = P b, L unit lower triangular
        c = dx[j]
        for i in range(j + 1, size):
            dx[i] -= lu[i, j] * c
    for j in range(size - 1, -1, -1):  # U dx = y
        dx[j] /= lu[j, j]
        c = dx[j]
        for i in range(j):
            dx[i] -= lu[i, j] * c
    return _scaled_size(dx, x)


@njit(cache=True)
def _scaled_size(dx, x) -> float:
    """max_i |dx_i|/(1 + |x_i|); inf when an entry of dx is not finite."""
    size = 0.0
    for i in range(dx.shape[0]):
        if not math.isfinite(dx[i]):
            return math.inf
        size = max(size, abs(dx[i]) / (1.0 + abs(x[i])))
    return size


def _failed(x, iteration, r, step, message, jacobians) -> NewtonResult:
    return NewtonResult(x, False, iteration, float(np.abs(r).max()), step, message, jacobians)
