"""Newton's method for square systems assembled from n equations plus bordering rows.

Solves R(X) = 0 (n equations, X of size n + k) together with k linear rows C X = d, which fix what the
equations leave free: a pseudo-arclength condition, a prescribed pole stretch or a fixed parameter.
Every loop is bounded; the result says whether it converged and why not.
"""
from dataclasses import dataclass

import numpy as np


@dataclass
class NewtonResult:
    x: np.ndarray
    converged: bool
    iterations: int
    residual: float  # max-norm of R at the returned x
    step: float  # max-norm of the last correction
    message: str


def newton(residual, jacobian, x0, rows, targets, tol: float, max_iter: int) -> NewtonResult:
    """Solve R(x) = 0, rows @ x = targets; converged when the correction is below tol·max(1, |x|∞).

    Near a singular point Newton converges only linearly (ratio ρ = |dx_k|/|dx_{k−1}|) and the remaining
    error is about |dx| ρ/(1 − ρ), which may exceed |dx|: that bound must be below the tolerance too.

    ``residual(x)`` returns R (n), ``jacobian(x)`` returns ∂R/∂x (n × (n + k)); rows is (k, n + k).
    """
    x = np.array(x0, dtype=float)
    rows = np.atleast_2d(rows)
    targets = np.atleast_1d(np.asarray(targets, dtype=float))
    previous = np.inf
    growth = 0
    for iteration in range(1, max_iter + 1):
        try:
            r = residual(x)
            matrix = np.vstack([jacobian(x), rows])
        except ArithmeticError as error:
            return NewtonResult(x, False, iteration, np.inf, np.inf, f"state left the domain: {error}")
        rhs = -np.concatenate([r, rows @ x - targets])
        try:
            dx = np.linalg.solve(matrix, rhs)
        except np.linalg.LinAlgError:
            return NewtonResult(x, False, iteration, float(np.abs(r).max()), np.inf, "singular Newton matrix")
        if not np.all(np.isfinite(dx)):
            return NewtonResult(x, False, iteration, float(np.abs(r).max()), np.inf, "non-finite Newton step")
        x = x + dx
        step = float(np.abs(dx).max())
        ratio = min(step / previous, 0.99) if np.isfinite(previous) and previous > 0 else 0.0
        if max(step, step * ratio / (1.0 - ratio)) <= tol * max(1.0, float(np.abs(x).max())):
            try:
                final = float(np.abs(residual(x)).max())
            except ArithmeticError as error:
                return NewtonResult(x, False, iteration, np.inf, step, f"state left the domain: {error}")
            return NewtonResult(x, True, iteration, final, step, "converged")
        growth = growth + 1 if step > previous else 0
        if growth >= 3:
            return NewtonResult(x, False, iteration, float(np.abs(r).max()), step, "Newton corrections grow")
        previous = step
    return NewtonResult(x, False, max_iter, float(np.abs(r).max()), step, f"no convergence in {max_iter} iterations")
