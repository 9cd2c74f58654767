"""Newton's method for square systems assembled from n equations plus bordering rows.

Solves R(X) = 0 (n equations, X of size n + k) together with k linear rows C X = d, which fix what the
equations leave free: a pseudo-arclength condition, a prescribed pole stretch or a fixed parameter.
Every loop is bounded; the result says whether it converged and why not.

The Jacobian is evaluated and LU-factored only when it is needed (simplified Newton, Hairer & Wanner, *Solving
ODEs II*, §IV.8): it is reused while the corrections contract by at least ``REFRESH_RATIO`` per iteration, and
refreshed at the current iterate as soon as they do not (the slow step is dropped, so every accepted step is
a Newton step or a chord step that contracted fast, and the observed ratios estimate the contraction). With a fresh Jacobian every iteration this is plain
Newton; from a good start (a continuation predictor, a neighbouring solution) one factorisation usually serves
the whole solve, and the remaining iterations cost one residual each. Converged when both the last correction
and the error estimate ρ/(1 − ρ)·|dx| (observed contraction ρ = |dx_k|/|dx_{k−1}|, Hairer & Wanner IV.8.10)
are below the tolerance.
"""
from dataclasses import dataclass

import numpy as np
import scipy.linalg

REFRESH_RATIO = 0.1  # a stale Jacobian is kept while |dx_k| ≤ REFRESH_RATIO |dx_{k−1}|


@dataclass
class NewtonResult:
    x: np.ndarray
    converged: bool
    iterations: int  # corrections computed (a dropped stale-Jacobian correction counts too)
    residual: float  # max-norm of R at the returned x
    step: float  # max-norm of the last correction
    message: str
    jacobians: int = 0  # Jacobian evaluations and factorisations


def newton(residual, jacobian, x0, rows, targets, tol: float, max_iter: int) -> NewtonResult:
    """Solve R(x) = 0, rows @ x = targets; converged when |dx| and the estimated error are below tol·max(1, |x|∞).

    Near a singular point Newton converges only linearly (ratio ρ) even with a fresh Jacobian, and the
    remaining error ρ/(1 − ρ)|dx| may exceed |dx|: the estimate accounts for that.

    ``residual(x)`` returns R (n), ``jacobian(x)`` returns ∂R/∂x (n × (n + k)); rows is (k, n + k).
    """
    x = np.array(x0, dtype=float)
    rows = np.atleast_2d(rows)
    targets = np.atleast_1d(np.asarray(targets, dtype=float))
    previous = np.inf
    factors, fresh, jacobians, growth = None, False, 0, 0
    r, step = None, np.inf
    for iteration in range(1, max_iter + 1):
        try:
            if r is None:
                r = residual(x)
            if factors is None:
                factors = scipy.linalg.lu_factor(np.vstack([jacobian(x), rows]), check_finite=False)
                fresh, jacobians = True, jacobians + 1
        except ArithmeticError as error:
            return NewtonResult(x, False, iteration, np.inf, np.inf, f"state left the domain: {error}", jacobians)
        except (ValueError, np.linalg.LinAlgError):
            return _failed(x, iteration, r, np.inf, "non-finite Newton matrix", jacobians)
        if np.any(np.diag(factors[0]) == 0.0):
            return _failed(x, iteration, r, np.inf, "singular Newton matrix", jacobians)
        dx = scipy.linalg.lu_solve(factors, -np.concatenate([r, rows @ x - targets]), check_finite=False)
        if not np.all(np.isfinite(dx)):
            return _failed(x, iteration, r, np.inf, "non-finite Newton step", jacobians)
        step = float(np.abs(dx).max())
        ratio = step / previous if np.isfinite(previous) and previous > 0 else None
        if ratio is not None and ratio > REFRESH_RATIO and not fresh:
            factors = None  # a stale Jacobian contracts too slowly: drop its step, redo it with a fresh one here
            continue
        fresh = False
        x = x + dx
        r = None
        error = step if ratio is None else max(step, step * min(ratio, 0.99) / (1.0 - min(ratio, 0.99)))
        if error <= tol * max(1.0, float(np.abs(x).max())):
            try:
                final = float(np.abs(residual(x)).max())
            except ArithmeticError as failure:
                return NewtonResult(x, False, iteration, np.inf, step, f"state left the domain: {failure}",
                                    jacobians)
            return NewtonResult(x, True, iteration, final, step, "converged", jacobians)
        growth = growth + 1 if step > previous else 0
        if growth >= 3:
            return NewtonResult(x, False, iteration, np.inf, step, "Newton corrections grow", jacobians)
        previous = step
    return NewtonResult(x, False, max_iter, np.inf, step, f"no convergence in {max_iter} iterations", jacobians)


def _failed(x, iteration, r, step, message, jacobians) -> NewtonResult:
    return NewtonResult(x, False, iteration, float(np.abs(r).max()), step, message, jacobians)
