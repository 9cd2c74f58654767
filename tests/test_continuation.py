"""The generic engine (balloon_cg.numerics.continuation) on scalar toy systems with closed-form answers.

S-curve R(u, λ) = u³ − u − (λ − 1): λ = 1 + u³ − u has limit points where dλ/du = 3u² − 1 = 0,
    u = ±1/√3,  λ = 1 ∓ 2/(3√3),
found by the fold monitor c = e_λ (sign change of c·τ = dλ/ds) and located by Brent in the arclength.
Pitchfork normal form R(u, λ) = λu − u³: on the trivial branch u = 0 the test function ∂R/∂u = λ − 3u²
changes sign at λ = 0, where the branches u = ±√λ cross; the engine locates that root with ``locate_root``
(it has no branch-point detection or classification of its own: those are balloon-specific, in
analysis/points/branch_points.py).
"""
import enum
import math

import numpy as np
import pytest

from balloon_cg.numerics import continuation
from balloon_cg.numerics.continuation import RootStatus, Stop

SETTINGS = continuation.Settings(step=0.05, step_min=1e-8, step_max=0.2, max_points=500, tol=1e-13, max_newton=20)
LAMBDA = np.array([0.0, 1.0])  # c with c·X = λ: the fold monitor of limit points
STATE = np.array([1.0, 0.0])  # c·X = u: u is monotonic on the S-curve, so this monitor never fires


class Scalar:
    """R(X), X = (u, λ), with its Jacobian [∂R/∂u, ∂R/∂λ] (1 × 2), as the engine expects."""

    def __init__(self, residual, r_u, r_lambda):
        self.f, self.r_u, self.r_lambda = residual, r_u, r_lambda

    def residual(self, X):
        return np.array([self.f(*X)])

    def jacobian(self, X):
        return np.array([[self.r_u(*X), self.r_lambda(*X)]])


class Done(enum.Enum):
    """The caller's stop codes (the engine takes any enum)."""

    REACHED = "reached"


S_CURVE = Scalar(lambda u, lam: u**3 - u - (lam - 1), lambda u, lam: 3 * u**2 - 1, lambda u, lam: -1.0)
PITCHFORK = Scalar(lambda u, lam: lam * u - u**3, lambda u, lam: lam - 3 * u**2, lambda u, lam: u)


def start(system, X, reference):
    X = np.asarray(X, dtype=float)
    return continuation.Point(X, continuation.tangent(system, X, np.asarray(reference, dtype=float)), 0, 0.0)


def test_s_curve_folds_located_by_the_fold_monitor():
    u0 = -2.0
    path = continuation.trace(S_CURVE, start(S_CURVE, [u0, 1 + u0**3 - u0], [1.0, 0.0]), SETTINGS,
                              lambda p: Stop(Done.REACHED, "u > 2") if p.X[0] > 2 else None,
                              {"lambda": LAMBDA, "u": STATE})
    assert path.stop.code == Done.REACHED
    assert [f.label for f in path.folds] == ["lambda", "lambda"]
    expected = [(-1 / math.sqrt(3), 1 + 2 / (3 * math.sqrt(3))), (1 / math.sqrt(3), 1 - 2 / (3 * math.sqrt(3)))]
    for fold, (u, lam) in zip(path.folds, expected):
        assert abs(fold.point.X[0] - u) < 1e-10 and abs(fold.point.X[1] - lam) < 1e-12
        assert abs(fold.point.tangent @ LAMBDA) < 1e-10  # dλ/ds = 0 there
        assert abs(S_CURVE.residual(fold.point.X)[0]) < 1e-13
        before, after = path.points[fold.index], path.points[fold.index + 1]
        assert before.X[0] < fold.point.X[0] < after.X[0]  # between the points it is reported between
    assert np.all(np.diff([p.X[0] for p in path.points]) > 0)
    assert all(abs(S_CURVE.residual(p.X)[0]) < 1e-12 for p in path.points)


def test_pitchfork_located_by_the_test_function_on_the_trivial_branch():
    path = continuation.trace(PITCHFORK, start(PITCHFORK, [0.0, -1.0], [0.0, 1.0]), SETTINGS,
                              lambda p: Stop(Done.REACHED, "λ > 1") if p.X[1] > 1 else None, {"lambda": LAMBDA})
    assert path.stop.code == Done.REACHED and path.folds == []
    assert all(p.X[0] == 0.0 for p in path.points)  # the corrector stays on u = 0 across the branch point

    def test_function(X):
        return PITCHFORK.r_u(*X)

    values = [test_function(p.X) for p in path.points]
    crossings = [i for i in range(len(values) - 1) if values[i] * values[i + 1] < 0]
    assert len(crossings) == 1
    first = path.points[crossings[0]]
    length = float(np.linalg.norm(path.points[crossings[0] + 1].X - first.X))

    def value_at(s):
        result = continuation.correct(PITCHFORK, first.X + s * first.tangent, first.tangent, SETTINGS)
        return test_function(result.x), result.x

    root = continuation.locate_root(value_at, length)
    assert root.status == RootStatus.LOCATED and abs(root.payload[1]) < 1e-13 and root.payload[0] == 0.0


def test_locate_root_falls_back_to_the_best_evaluated_point():
    """No sign change (brentq refuses) or a failed evaluation: the evaluated point of smallest |value|, with
    status NEAREST (a root it is not)."""
    root = continuation.locate_root(lambda s: (s - 0.3, s), 1.0)
    assert root.status == RootStatus.LOCATED and root.payload == pytest.approx(0.3, abs=1e-13)
    root = continuation.locate_root(lambda s: (s + 1.0, s), 1.0)
    assert root.status == RootStatus.NEAREST and root.payload == 0.0 and root.value == 1.0

    def failing(s):
        if s > 0.9:
            raise ArithmeticError("singular")
        return s - 0.3, s

    root = continuation.locate_root(failing, 1.0)
    assert root.status == RootStatus.NEAREST and root.payload == 0.0  # brentq's first evaluations are the ends


def test_a_failed_evaluation_near_the_root_keeps_the_narrowest_bracket():
    """An evaluation that fails close to the root (Newton at a singular point): the root is known to lie between
    the two evaluated neighbours of opposite sign that are closest together (``bracket``), and the end of it
    with the smaller |value| is returned, not the whole interval's best guess."""
    root_at, evaluated = 0.3, {}

    def value_at(s):
        if 0 < abs(s - root_at) < 1e-10:
            raise ArithmeticError("singular")
        evaluated[s] = (s - root_at) ** 3 + 0.1 * (s - root_at)
        return evaluated[s], s

    root = continuation.locate_root(value_at, 1.0)
    assert root.status == RootStatus.NEAREST and root.bracket is not None
    low, high = sorted(root.bracket)
    assert low < root_at < high and evaluated[low] * evaluated[high] < 0
    ordered = sorted(evaluated)
    widths = [b - a for a, b in zip(ordered, ordered[1:]) if evaluated[a] * evaluated[b] <= 0]
    assert high - low == min(widths) < 1.0  # Brent's own bracket (its steps here all fall on one side)
    assert root.payload == min((low, high), key=lambda x: abs(evaluated[x]))


def test_known_values_spare_evaluations_and_change_nothing():
    """``known`` (the bracket end the caller has computed) is used when Brent asks for it: the same root and
    payload, one evaluation fewer; a failed first evaluation still gives None (the known end is never offered
    as the fallback before Brent asked for it)."""
    calls = []

    def value_at(s):
        calls.append(s)
        return (s - 0.3) ** 3 + 0.1 * (s - 0.3), s

    plain = continuation.locate_root(value_at, 1.0)
    evaluations, end = len(calls), value_at(1.0)
    calls.clear()
    seeded = continuation.locate_root(value_at, 1.0, known={1.0: end})
    assert 1.0 not in calls and len(calls) == evaluations - 1
    assert (seeded.status, seeded.payload, seeded.value) == (plain.status, plain.payload, plain.value)

    def failing_at_zero(s):
        if s == 0.0:
            raise ArithmeticError("singular")
        return s - 0.3, s

    assert continuation.locate_root(failing_at_zero, 1.0, known={1.0: (0.7, 1.0)}) is None


def test_traced_folds_equal_brent_from_scratch(monkeypatch):
    """The fold trace() reports (its Brent run takes the step's end point as the bracket end) is bit for bit the
    one of a Brent run that evaluates both ends itself."""
    steps = []
    original = continuation.locate_fold

    def recording(system, start, sigma, c, settings, end):
        steps.append((start, sigma))
        return original(system, start, sigma, c, settings, end)

    monkeypatch.setattr(continuation, "locate_fold", recording)
    u0 = -2.0
    path = continuation.trace(S_CURVE, start(S_CURVE, [u0, 1 + u0**3 - u0], [1.0, 0.0]), SETTINGS,
                              lambda p: Stop(Done.REACHED, "u > 2") if p.X[0] > 2 else None, {"lambda": LAMBDA})
    assert len(path.folds) == len(steps) == 2
    for fold, (before, sigma) in zip(path.folds, steps):
        def value_at(s):
            result = continuation.correct(S_CURVE, before.X + s * before.tangent, before.tangent, SETTINGS)
            t = continuation.tangent(S_CURVE, result.x, before.tangent)
            return float(LAMBDA @ t), (result.x, t)

        root = continuation.locate_root(value_at, sigma)
        assert np.array_equal(root.payload[0], fold.point.X) and np.array_equal(root.payload[1], fold.point.tangent)


def test_a_trace_resumed_from_its_overshoot_with_its_step_takes_the_same_points():
    """``Path.step`` is the step the trace would take from its overshoot had it accepted it: resumed from the
    overshoot with it (as a surface branch goes on from the point a resolution stop rejected, carried to a finer
    basis) the trace takes the points of one never stopped (the S-curve's steps grow from 0.05 by 1.5 a point to
    0.17; the overshoot here, the third point, is reached by 0.075 in 3 iterations: the next step is 0.1125)."""
    from dataclasses import replace

    u0 = -2.0
    first = start(S_CURVE, [u0, 1 + u0**3 - u0], [1.0, 0.0])
    whole = continuation.trace(S_CURVE, first, SETTINGS, lambda p: Stop(Done.REACHED, "u > 2") if p.X[0] > 2 else None,
                               {})
    stopped = continuation.trace(S_CURVE, first, SETTINGS,
                                 lambda p: Stop(Done.REACHED, "u > -1.99") if p.X[0] > -1.99 else None, {})
    assert len(stopped.points) == 2 and stopped.step == pytest.approx(0.1125)
    resumed = continuation.trace(S_CURVE, stopped.overshoot, replace(SETTINGS, step=stopped.step),
                                 lambda p: Stop(Done.REACHED, "u > 2") if p.X[0] > 2 else None, {})
    joined = [p.X for p in stopped.points + resumed.points]
    assert len(joined) == len(whole.points) > len(stopped.points) + 2
    assert max(np.abs(a - b).max() for a, b in zip(joined, (p.X for p in whole.points))) < 1e-12


def test_easy_newton_sets_the_iterations_that_grow_the_step():
    """``next_step`` grows σ by 1.5 after at most ``Settings.easy_newton`` corrector iterations (default 3; the bulge
    branch on spectral elements passes 4: one SuperLU factor and its chord, tube/bulge.EASY_NEWTON_ELEMENTS), keeps
    it up to 5 and shrinks it by 0.7 from 6; growth stops where the state would move step_max along the tangent."""
    from dataclasses import replace

    tangent = np.array([0.6, 0.8])  # the state's share of the unit tangent: 0.6
    at = {k: continuation.Point(np.zeros(2), tangent, k, 0.0) for k in (3, 4, 5, 6)}
    chord = replace(SETTINGS, easy_newton=4)
    assert SETTINGS.easy_newton == 3
    assert [continuation.next_step(0.1, at[k], SETTINGS) for k in (3, 4, 5, 6)] == pytest.approx([0.15, 0.1, 0.1, 0.07])
    assert [continuation.next_step(0.1, at[k], chord) for k in (3, 4, 5, 6)] == pytest.approx([0.15, 0.15, 0.1, 0.07])
    assert continuation.next_step(0.3, at[4], chord) == pytest.approx(SETTINGS.step_max / 0.6)
