"""numerics.roots.brent against scipy.optimize.brentq: the same iterates, so the same float, on functions that
take each of its steps (secant, inverse quadratic, bisection, the minimal step δ), and the same refusals."""
import math

import pytest
from scipy.optimize import brentq

from balloon_cg.numerics.roots import NoConvergence, brent

CASES = [
    (lambda x: x**3 - 2 * x - 5, 2.0, 3.0),  # Wallis' cubic
    (lambda x: math.cos(x) - x, 0.0, 1.0),
    (lambda x: math.exp(x) - 1e4, 0.0, 20.0),
    (lambda x: (x - 1.0) ** 5, 0.0, 3.5),  # a flat root: slow, many bisections
    (lambda x: math.atan(1e6 * (x - 0.3)), -1.0, 1.0),  # a near step: interpolation rejected
    (lambda x: x - 1e-300, 0.0, 1.0),  # the root below δ: minimal steps
    (lambda x: math.tanh(x - 2.0) + 0.5 * math.sin(7 * x), 0.0, 3.0),
    (lambda x: 1.0 / (x - 0.5) if x != 0.5 else math.inf, 0.0, 1.0),  # a pole, no root: ends at the sign change
]


@pytest.mark.parametrize("case", range(len(CASES)))
@pytest.mark.parametrize("xtol", [2e-12, 1e-13, 1e-6])
def test_brent_returns_brentqs_float(case, xtol):
    f, a, b = CASES[case]
    calls, scipy_calls = [], []
    try:
        theirs = brentq(lambda x: scipy_calls.append(x) or f(x), a, b, xtol=xtol)
    except RuntimeError:  # the flat root at a small xtol: 100 steps are not enough for either
        with pytest.raises(NoConvergence):
            brent(lambda x: calls.append(x) or f(x), a, b, xtol=xtol)
    else:
        assert brent(lambda x: calls.append(x) or f(x), a, b, xtol=xtol) == theirs
    assert calls == scipy_calls  # the same iterates, not only the same end


def test_brent_roots_at_the_ends_and_reversed_brackets():
    assert brent(lambda x: x - 1.0, 1.0, 2.0) == 1.0
    assert brent(lambda x: x - 2.0, 1.0, 2.0) == 2.0
    f = lambda x: x**3 - 2 * x - 5  # noqa: E731
    assert brent(f, 3.0, 2.0) == brentq(f, 3.0, 2.0)


def test_brent_refuses_what_brentq_refuses():
    with pytest.raises(ValueError, match="same sign"):
        brent(lambda x: x * x + 1.0, -1.0, 1.0)
    with pytest.raises(ValueError, match="NaN"):
        brent(lambda x: math.nan if x > 0.7 else x - 0.9, 0.0, 1.0)
    with pytest.raises(ValueError, match="xtol"):
        brent(lambda x: x, -1.0, 1.0, xtol=0.0)
    with pytest.raises(ValueError, match="rtol"):
        brent(lambda x: x, -1.0, 1.0, rtol=1e-17)
    f = lambda x: (x - 1.0) ** 5  # noqa: E731
    with pytest.raises(NoConvergence):
        brent(f, 0.0, 3.5, maxiter=3)
    with pytest.raises(RuntimeError):
        brentq(f, 0.0, 3.5, maxiter=3)
