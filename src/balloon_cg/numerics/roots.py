"""Brent's method for a root of f in a bracket [a, b] with f(a) f(b) < 0: inverse quadratic interpolation (or
the secant) where it stays well inside the bracket, bisection otherwise (R. P. Brent, *Algorithms for
Minimization without Derivatives*, 1973, ch. 4).

The steps, the tolerance 2δ = xtol + rtol |x| and the defaults are those of scipy.optimize.brentq (its C
routine), so both take the same iterates and return the same float (tests/test_roots.py compares them). It is
here because importing scipy.optimize costs ~0.1–0.2 s, about as long as a whole run's start-up otherwise.
"""
import math

RTOL = 4 * 2.220446049250313e-16  # 4 ε, scipy's default and smallest rtol


class NoConvergence(RuntimeError):
    """The bracket did not shrink to the tolerance within the iteration budget."""


def brent(f, a: float, b: float, xtol: float = 2e-12, rtol: float = RTOL, maxiter: int = 100) -> float:
    """A root of ``f`` in [a, b] to |error| ≤ xtol + rtol |root|. ValueError if f(a) and f(b) have the same
    sign or f returns NaN; NoConvergence after ``maxiter`` steps."""
    if xtol <= 0 or rtol < RTOL:
        raise ValueError(f"xtol = {xtol!r}, rtol = {rtol!r}: need xtol > 0 and rtol >= {RTOL!r}")

    def value(x):
        y = float(f(x))
        if math.isnan(y):
            raise ValueError(f"the function is NaN at x = {x!r}")
        return y

    x_prev, x = float(a), float(b)
    f_prev, f_x = value(x_prev), value(x)
    if f_prev == 0:
        return x_prev
    if f_x == 0:
        return x
    if _negative(f_prev) == _negative(f_x):
        raise ValueError(f"f(a) = {f_prev!r} and f(b) = {f_x!r} have the same sign: no bracket")
    x_far = f_far = step_prev = step = 0.0  # x_far: the end of the bracket opposite x
    for _ in range(maxiter):
        if f_prev != 0 and f_x != 0 and _negative(f_prev) != _negative(f_x):
            x_far, f_far = x_prev, f_prev
            step_prev = step = x - x_prev
        if abs(f_far) < abs(f_x):  # x is always the end with the smaller |f|
            x_prev, x, x_far = x, x_far, x
            f_prev, f_x, f_far = f_x, f_far, f_x
        delta = (xtol + rtol * abs(x)) / 2
        half = (x_far - x) / 2
        if f_x == 0 or abs(half) < delta:
            return x
        if abs(step_prev) > delta and abs(f_x) < abs(f_prev):
            if x_prev == x_far:  # secant
                trial = -f_x * (x - x_prev) / (f_x - f_prev)
            else:  # inverse quadratic interpolation through the three points
                d_prev = (f_prev - f_x) / (x_prev - x)
                d_far = (f_far - f_x) / (x_far - x)
                trial = -f_x * (f_far * d_far - f_prev * d_prev) / (d_far * d_prev * (f_far - f_prev))
            if 2 * abs(trial) < min(abs(step_prev), 3 * abs(half) - delta):
                step_prev, step = step, trial
            else:
                step_prev = step = half
        else:
            step_prev = step = half
        x_prev, f_prev = x, f_x
        x += step if abs(step) > delta else (delta if half > 0 else -delta)
        f_x = value(x)
    raise NoConvergence(f"Brent's method did not converge in {maxiter} steps (last x = {x!r})")


def _negative(y: float) -> bool:
    """The sign bit (C signbit): -0.0 counts as negative, as in scipy's brentq."""
    return math.copysign(1.0, y) < 0
