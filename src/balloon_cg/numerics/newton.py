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

The attainable accuracy. A residual evaluated in floating point carries rounding δR ~ ε|A||x| (its terms), so
the corrections of an iterate at the solution are A⁻¹δR: in the scaled norm at most ε·κ∞(A D), D = diag(1 + |x_i|)
(the limiting accuracy of Newton's method in floating point, Tisseur, SIAM J. Matrix Anal. Appl. 22 (2001)
1038–1057; Higham, *Accuracy and Stability of Numerical Algorithms*, §12.1). Where that floor is above the
tolerance the corrections stop contracting short of it, and converge or not by the luck of the rounding. A
correction from a fresh Jacobian at least as large as the last one (no contraction at all: even at a singular
root Newton contracts by ½) and below ε·κ∞(A D) (dgecon's estimate, computed only then) therefore ends the solve
as ``Convergence.AT_ROUNDING`` if the caller accepts that accuracy (``rounding_limit``; default 0: the rule is
off), as ``ILL_CONDITIONED`` (not a solution) above it: the iterate is returned with that correction as its
attained accuracy (``step``, above tol), never as CONVERGED.
"""
import enum
import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.linalg.lapack import dgecon, dgetrf, dgetrs  # LAPACK directly: scipy.linalg's wrappers: ~10-20 µs a call

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
EPSILON = np.finfo(float).eps


class Convergence(enum.StrEnum):
    """How a Newton solve ended."""

    CONVERGED = "converged"  # the correction and its error estimate below tol
    AT_ROUNDING = "at_rounding"  # corrections stopped contracting below ε·κ∞(A D), above tol (module docstring)
    ILL_CONDITIONED = "ill_conditioned"  # the same above the caller's rounding_limit: a nearly singular system
    FAILED = "failed"  # no solution: ``message`` says why


@dataclass
class NewtonResult:
    x: np.ndarray
    outcome: Convergence
    iterations: int  # corrections computed (a dropped stale-Jacobian correction counts too)
    residual: float  # max-norm of R at the returned x
    step: float  # the last correction in the scaled max-norm max_i |dx_i|/(1 + |x_i|); AT_ROUNDING: the accuracy
    message: str
    jacobians: int = 0  # Jacobian evaluations and factorisations
    factors: object = None  # solved: dgetrf's (lu, pivots) or SparseFactors of the last [∂R/∂x; rows] (earlier x)

    @property
    def converged(self) -> bool:
        """Whether x solves the system: to tol (CONVERGED) or to the attainable accuracy ``step`` (AT_ROUNDING)."""
        return self.outcome in (Convergence.CONVERGED, Convergence.AT_ROUNDING)


def newton(residual, jacobian, x0, rows, targets, tol: float, max_iter: int,
           factors: tuple | None = None, rounding_limit: float = 0.0) -> NewtonResult:
    """Solve R(x) = 0, rows @ x = targets; converged when the correction and the estimated error are below tol in
    the scaled max-norm max_i |dx_i|/(1 + |x_i|) (absolute for small components, relative for large ones: a
    pressure of 10³ does not loosen the tolerance on the shape coefficients), or at the rounding floor above tol
    (``Convergence.AT_ROUNDING``, module docstring) where that is at most ``rounding_limit``. ``factors``: dgetrf's
    factors of [∂R/∂x; rows] at a neighbouring point with the same rows (a NewtonResult's), the chord to start from:
    stale, refreshed as soon as its corrections contract too slowly.

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
                jacobians += 1
                factors, info = _factorise(jacobian(x), rows, matrix)
                fresh = True
                if info != 0:
                    message = "singular Newton matrix" if info > 0 else "invalid Newton matrix"
                    return _failed(x, iteration, r, np.inf, message, jacobians)
        except ArithmeticError as error:
            return NewtonResult(x, Convergence.FAILED, iteration, np.inf, np.inf, f"state left the domain: {error}",
                                jacobians)
        if x.size < SMALL_SOLVE and isinstance(factors, tuple):
            dx, step = rhs, _correction(*factors, r, rows, targets, x, rhs)
        else:
            _right_hand_side(r, rows, targets, x, rhs)
            dx = solve_factored(factors, rhs)
            step = _scaled_size(dx, x)
        if not math.isfinite(step):
            return _failed(x, iteration, r, np.inf, "non-finite Newton step", jacobians)
        ratio = step / previous if math.isfinite(previous) and previous > 0 else None
        if ratio is not None and ratio > refresh_ratio and not fresh:
            factors = None  # a stale Jacobian contracts too slowly: drop its step, redo it with a fresh one here
            continue
        if rounding_limit > 0 and fresh and ratio is not None and ratio >= 1.0 and step > tol:
            if isinstance(factors, SparseFactors):
                raise ValueError("newton: rounding_limit > 0 reads dgetrf's factors (a dense Jacobian), not sparse ones")
            floor = rounding_floor(factors[0], x)
            if step <= floor < math.inf:  # a singular A (floor inf) attains nothing
                outcome = Convergence.AT_ROUNDING if step <= rounding_limit else Convergence.ILL_CONDITIONED
                return NewtonResult(x, outcome, iteration, max_abs(r), step,
                                    f"at the rounding floor: corrections stopped contracting at {step:.2g} (tol "
                                    f"{tol:g}, limit {rounding_limit:g}, ε·κ∞(A D) = {floor:.2g})", jacobians,
                                    factors)
        fresh = False
        x = x + dx
        r = None
        error = step if ratio is None else max(step, step * min(ratio, 0.99) / (1.0 - min(ratio, 0.99)))
        if error <= tol:
            try:
                final = max_abs(residual(x))
            except ArithmeticError as failure:
                return NewtonResult(x, Convergence.FAILED, iteration, np.inf, step,
                                    f"state left the domain: {failure}", jacobians)
            if not math.isfinite(final):
                return NewtonResult(x, Convergence.FAILED, iteration, final, step,
                                    "non-finite residual at the solution", jacobians)
            return NewtonResult(x, Convergence.CONVERGED, iteration, final, step, "converged", jacobians, factors)
        growth = growth + 1 if step > previous else 0
        if growth >= 3:
            return NewtonResult(x, Convergence.FAILED, iteration, np.inf, step, "Newton corrections grow", jacobians)
        previous = step
    return NewtonResult(x, Convergence.FAILED, max_iter, np.inf, step, f"no convergence in {max_iter} iterations",
                        jacobians)


class SparseFactors:
    """SuperLU's factors (scipy.sparse.linalg.splu, partial pivoting, minimum-degree ordering on AᵀA's pattern) of
    [∂R/∂x; rows] where the Jacobian is a scipy.sparse matrix (spectral elements: galerkin/interval_elements.py):
    fill O(nnz) for a banded Jacobian with a few dense rows and columns, where dgetrf costs O(n³) (25 elements of
    order 16, 802 unknowns: 8 ms against 100–600 ms)."""

    def __init__(self, jacobian, rows):
        from scipy import sparse  # here: a sphere's run never imports scipy.sparse
        from scipy.sparse.linalg import splu
        self.lu = splu(_with_rows(sparse.csc_matrix(jacobian), np.atleast_2d(rows)), permc_spec="MMD_AT_PLUS_A")

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        return self.lu.solve(rhs)


def _with_rows(jacobian, rows: np.ndarray):
    """[jacobian; rows] in CSC (``jacobian`` CSC n × m, ``rows`` dense k × m): each column's entries followed by the
    k rows' (their row indices n..n + k − 1, after the Jacobian's)."""
    from scipy import sparse
    n, m = jacobian.shape
    k = rows.shape[0]
    counts = np.diff(jacobian.indptr)
    moved = np.arange(jacobian.nnz) + k * np.repeat(np.arange(m), counts)
    border = (jacobian.indptr[1:] + k * np.arange(m))[:, None] + np.arange(k)[None, :]
    data, indices = np.empty(jacobian.nnz + k * m), np.empty(jacobian.nnz + k * m, dtype=np.int32)
    data[moved], indices[moved] = jacobian.data, jacobian.indices
    data[border], indices[border] = rows.T, n + np.arange(k)[None, :]
    return sparse.csc_matrix((data, indices, jacobian.indptr + k * np.arange(m + 1)), shape=(n + k, m))


def _factorise(jacobian, rows, matrix: np.ndarray) -> tuple:
    """(factors of [jacobian; rows], LAPACK's info: 0, > 0 singular): dgetrf's (lu, pivots) in ``matrix`` (n + k
    square, column order) for a dense Jacobian, ``SparseFactors`` for a sparse one (it has ``tocsc``)."""
    if hasattr(jacobian, "tocsc"):
        try:
            return SparseFactors(jacobian, rows), 0
        except RuntimeError:  # SuperLU: "Factor is exactly singular"
            return None, 1
    n = matrix.shape[0] - rows.shape[0]
    matrix[:n] = jacobian
    matrix[n:] = rows
    lu, pivots, info = dgetrf(matrix, overwrite_a=True)
    return (lu, pivots), info


def solve_factored(factors, rhs: np.ndarray) -> np.ndarray:
    """A⁻¹ rhs from a NewtonResult's ``factors`` (dgetrf's (lu, pivots) or ``SparseFactors``)."""
    return factors.solve(rhs) if isinstance(factors, SparseFactors) else dgetrs(*factors, rhs)[0]


def rounding_floor(lu, x) -> float:
    """ε·κ∞(A D), D = diag(1 + |x_i|), from dgetrf's ``lu`` of A (P A = L U; inf if singular): the largest scaled
    correction max_i |dx_i|/(1 + |x_i|) that rounding of the residual (δR ~ ε|A||x|) causes at the solution (module
    docstring). P A D = L (U D): ‖A D‖∞ from the product (P permutes rows: the same norm), ‖(A D)⁻¹‖∞ by dgecon."""
    scale = 1.0 + np.abs(x)
    upper = np.triu(lu) * scale
    norm = np.abs((np.tril(lu, -1) + np.eye(x.size)) @ upper).sum(axis=1).max()
    rcond, info = dgecon(np.tril(lu, -1) + upper, norm, norm="I")
    return EPSILON / rcond if info == 0 and rcond > 0 else math.inf


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
    return NewtonResult(x, Convergence.FAILED, iteration, float(np.abs(r).max()), step, message, jacobians)
