"""Pseudo-arclength continuation of R(X) = 0, R: R^{n+1} -> R^n, with adaptive steps and fold location.

Knows nothing about balloons: a *system* has ``residual(X)`` and ``jacobian(X)`` (n × (n+1)). From a point X
with unit tangent τ (J τ = 0), the predictor is X + σ τ and the corrector solves R = 0 with τ·(X − X_pred) = 0
(Keller). Steps grow after easy corrections and shrink on failure, on a sharp turn (τ_i·τ_{i+1} small) or
on a slow correction (linear Newton convergence means a nearly singular Jacobian: landing close to a branch
point, where the corrector may pick the crossing branch). With ``Settings.rounding_limit`` > 0 (opt-in; 0, the
default, turns both off) a corrector that stagnates at its rounding floor is accepted up to that limit (newton's
AT_ROUNDING), and one that stagnates above it (ILL_CONDITIONED: the system is nearly singular there, e.g. at a
codim-2 point of an extended system) doubles the step instead of halving it, on every failure until a point is
accepted or the step would move the state more than step_max: shorter steps would land nearer the singular point,
a longer one lands past it.
``step_max`` bounds the change of the state X[:-1] in one step, not of the parameter X[-1]: where the branch
is steep in the parameter (a stiff material's pressure grows like λ^(α−1)) the arclength may grow until the
state moves step_max, instead of crawling at a fixed arclength that the parameter alone uses up.
*Fold monitors* are vectors c whose sign change in c·τ marks a fold of the quantity c·X (the parameter itself
for a limit point), or callables X ↦ ∇q(X) for a fold of a nonlinear quantity q (dq/ds = ∇q·τ); folds are then
located by Brent's method in the arclength (``locate_root``, to 1e-13 in s).
"""
import enum
from dataclasses import dataclass, field

import numpy as np
from .newton import Convergence, SparseFactors, newton, solve_factored
from .roots import brent


TANGENT_REFINEMENTS = 10  # refinement steps of a tangent from the corrector's factors before the dense solve
TANGENT_TOL = 1e-14  # the last refinement step, relative to |t|, that ends it (rounding: ~ε·cond of the bordered J)


@dataclass
class Settings:
    step: float
    step_min: float
    step_max: float
    max_points: int
    tol: float
    max_newton: int
    max_turn: float = 0.3  # radians between successive tangents
    slow_newton: int = 6  # a correction needing more iterations is rejected (near-singular: e.g. a branch point)
    rounding_limit: float = 0.0  # > 0: accept a corrector at its rounding floor up to this, step across above it
    easy_newton: int = 3  # a correction of at most this many iterations grows the next step (``next_step``)


class TraceStop(enum.StrEnum):
    """Why ``trace`` itself stopped (the caller's stop rule has its own codes)."""

    MAX_POINTS = "max_points"  # settings.max_points reached
    STEP_MIN = "step_min"  # the corrector failed at the minimum step


@dataclass(frozen=True)
class Stop:
    """A stop: ``code`` (a member of an enum: TraceStop or the caller's) decides, ``message`` explains."""

    code: enum.Enum
    message: str

    def __str__(self):
        return self.message


@dataclass
class Point:
    X: np.ndarray
    tangent: np.ndarray
    iterations: int
    residual: float


@dataclass
class Fold:
    label: str
    point: Point
    index: int  # the fold lies between points[index] and points[index + 1]
    status: "RootStatus"
    bracket: tuple | None = None  # NEAREST: the two evaluated Points of the narrowest sign change, if any


@dataclass
class Path:
    points: list = field(default_factory=list)
    folds: list = field(default_factory=list)
    stop: Stop | None = None
    overshoot: Point | None = None  # the first point past a stop condition (not part of the branch)
    step: float | None = None  # the step σ from the overshoot had it been accepted (``next_step``)

    def bracket(self, fold: Fold) -> tuple[np.ndarray, np.ndarray]:
        """X of the two points a fold lies between: the narrowest sign change its root search evaluated, else
        points[index] and the next one (the overshoot, for a fold found on the step that ended the trace)."""
        if fold.bracket is not None:
            return fold.bracket[0].X, fold.bracket[1].X
        after = self.points[fold.index + 1] if fold.index + 1 < len(self.points) else self.overshoot
        return self.points[fold.index].X, after.X


def tangent(system, X, reference, factors=None, row: np.ndarray | None = None) -> np.ndarray:
    """Unit null vector of J(X) oriented along ``reference``: t of A t = e_{n+1}, A = [J(X); referenceᵀ], normalised.
    Given ``factors`` (dgetrf's LU or newton.SparseFactors of M = [J(X_k); rowᵀ], a corrector's at an iterate X_k
    near X; ``row`` its bordering row, default ``reference``) and a system that applies J(X) without assembling it
    (``jacobian_vector(X, v)``), by iterative refinement of [J(X); rowᵀ] t = e_{n+1} (the same null vector, scaled),
    t ← t + M⁻¹(e_{n+1} − [J(X); rowᵀ] t), which contracts as ‖I − M⁻¹[J(X); rowᵀ]‖ = O(|X − X_k|): a few
    matrix-free products instead of an assembly and a factorisation; the direct solve where it does not reach
    TANGENT_TOL in TANGENT_REFINEMENTS steps."""
    if factors is not None and hasattr(system, "jacobian_vector"):
        t = _refined_tangent(system, X, reference if row is None else row, factors)
        if t is not None:
            return t if t @ reference > 0 else -t
    J = system.jacobian(X)
    rhs = np.zeros(J.shape[0] + 1)
    rhs[-1] = 1.0
    if hasattr(J, "tocsc"):  # a sparse Jacobian (spectral elements)
        t = SparseFactors(J, reference).solve(rhs)
    else:
        t = np.linalg.solve(np.vstack([J, reference]), rhs)
    return t / np.linalg.norm(t)


def _refined_tangent(system, X, row, factors) -> np.ndarray | None:
    """The unit solution of [J(X); rowᵀ] t = e_{n+1} by iterative refinement on ``factors`` (``tangent``), or None
    when a step is not below TANGENT_TOL·|t| within TANGENT_REFINEMENTS steps."""
    rhs = np.zeros(X.size)
    rhs[-1] = 1.0
    t = solve_factored(factors, rhs)
    for _ in range(TANGENT_REFINEMENTS):
        step = solve_factored(factors, rhs - np.append(system.jacobian_vector(X, t), row @ t))
        t = t + step
        if np.linalg.norm(step) <= TANGENT_TOL * np.linalg.norm(t):
            return t / np.linalg.norm(t)
    return None


def correct(system, predictor, direction, settings: Settings):
    """Keller's corrector: R(X) = 0 on the hyperplane through the predictor normal to ``direction``."""
    return newton(system.residual, system.jacobian, predictor, direction, direction @ predictor,
                  settings.tol, settings.max_newton, rounding_limit=settings.rounding_limit)


class RootStatus(enum.StrEnum):
    """How ``locate_root`` found its point."""

    LOCATED = "located"  # Brent's method converged to xtol
    NEAREST = "nearest"  # an evaluation failed: the evaluated point with the smallest |value| (not a root)


@dataclass(frozen=True)
class Root:
    payload: object
    status: RootStatus
    value: float  # the function's value there
    bracket: tuple | None = None  # NEAREST: the payloads at the ends of the narrowest evaluated sign change


def locate_root(value_at, length: float, xtol: float = 1e-13, known: dict | None = None) -> Root | None:
    """Root in (0, length) of s ↦ value_at(s)[0] (value_at returns (value, payload)) by Brent's method, and the
    payload there. If an evaluation fails (ArithmeticError: e.g. Newton at a singular point), the search stops
    with status NEAREST: the root lies in the narrowest interval between evaluated neighbours whose values differ in
    sign (``bracket``: their payloads), and the end of it with the smaller |value| is returned (without such an
    interval: the evaluated point with the smallest |value|); None if nothing was evaluated. ``known``:
    s -> value_at(s) already computed by the caller (e.g. the bracket's end), used when Brent asks for that s."""
    cache, known = {}, known or {}

    def f(s):
        cache[s] = known[s] if s in known else value_at(s)
        return cache[s][0]

    try:
        s = brent(f, 0.0, length, xtol=xtol * max(1.0, length), maxiter=100)
        value, payload = cache[s] if s in cache else value_at(s)
        return Root(payload, RootStatus.LOCATED, float(value))
    except (ArithmeticError, ValueError):
        if not cache:
            return None
        evaluated = sorted(cache.items(), key=lambda item: item[0])
        changes = [(b[0] - a[0], a[1], b[1]) for a, b in zip(evaluated, evaluated[1:]) if a[1][0] * b[1][0] <= 0]
        if not changes:
            value, payload = min(cache.values(), key=lambda item: abs(item[0]))
            return Root(payload, RootStatus.NEAREST, float(value))
        _, low, high = min(changes, key=lambda change: change[0])
        value, payload = min((low, high), key=lambda item: abs(item[0]))
        return Root(payload, RootStatus.NEAREST, float(value), (low[1], high[1]))


def natural(solve, X: np.ndarray, start: float, target: float) -> tuple:
    """Natural continuation in a prescribed value from ``X`` (solved at ``start``) to ``target``: ``solve(X, value)``
    returns a NewtonResult from the last solution; steps of a quarter of the way, doubled after a success, halved
    after a failure. (X, value reached, the last failure's message): the value reached is ``target``, or where the
    step fell below 1e-6 of the way."""
    reached, step, message = start, (target - start) / 4, ""
    while reached < target:
        trial = min(reached + step, target)
        result = solve(X, trial)
        if result.converged:
            X, reached = result.x, trial
            step *= 2
            continue
        step, message = step * 0.5, result.message
        if step < 1e-6 * (target - start):
            break
    return X, reached, message


def rate(monitor, X: np.ndarray, t: np.ndarray) -> float:
    """dq/ds = ∇q(X)·τ of a fold monitor: a vector c (q = c·X) or a callable X ↦ ∇q(X)."""
    return float((monitor(X) if callable(monitor) else monitor) @ t)


def locate_fold(system, start: Point, sigma: float, c, settings: Settings, end: Point | None = None):
    """The Root where the monitor's rate (``rate``) vanishes between start and start + σ along the arclength
    (Brent), or None; ``end`` (if given) is the point the step from start reached (``value_at(σ)``: the same
    corrector and tangent, not recomputed)."""

    def value_at(s):
        result = correct(system, start.X + s * start.tangent, start.tangent, settings)
        if not result.converged:
            raise ArithmeticError(result.message)
        t = tangent(system, result.x, start.tangent, result.factors)
        return rate(c, result.x, t), Point(result.x, t, result.iterations, result.residual)

    if end is None:
        return locate_root(value_at, sigma)
    reached = Point(end.X.copy(), end.tangent.copy(), end.iterations, end.residual)  # a fold's own arrays
    return locate_root(value_at, sigma, known={sigma: (rate(c, end.X, end.tangent), reached)})


def next_step(sigma: float, point: Point, settings: Settings) -> float:
    """The step after ``point``, reached by the step σ: 1.5σ after an easy correction (at most settings.easy_newton
    iterations, 3 unless a caller says otherwise), at most what moves the state by step_max along the point's
    tangent; 0.7σ, at least step_min, after a slow one (≥ 6)."""
    if point.iterations <= settings.easy_newton:
        state_share = max(float(np.linalg.norm(point.tangent[:-1])), 1e-6)  # σ moves the state by σ·share
        return min(sigma * 1.5, settings.step_max / state_share)
    if point.iterations >= 6:
        return max(sigma * 0.7, settings.step_min)
    return sigma


def trace(system, start: Point, settings: Settings, stop, monitors: dict, progress=None) -> Path:
    """Follow the branch from ``start`` along its tangent until ``stop(point)`` returns a ``Stop``.

    The point that triggers the stop is not appended (it is kept as ``path.overshoot``, for the caller to
    land exactly on the limit).

    ``monitors``: label -> vector c or callable X ↦ ∇q(X) for fold detection (``rate``). ``progress``: optional
    callable(point).
    """
    path = Path(points=[start])
    sigma, across = settings.step, None  # across: the step that met ILL_CONDITIONED, while doubling
    current = start
    rates = {label: rate(c, start.X, start.tangent) for label, c in monitors.items()}  # at ``current``
    while len(path.points) < settings.max_points:
        predictor = current.X + sigma * current.tangent
        result = correct(system, predictor, current.tangent, settings)
        new_tangent = None
        if result.converged and result.iterations <= settings.slow_newton:
            try:
                new_tangent = tangent(system, result.x, current.tangent, result.factors)
            except np.linalg.LinAlgError:
                new_tangent = None
        failed = new_tangent is None or float(new_tangent @ current.tangent) < np.cos(settings.max_turn)
        if failed and across is None and result.outcome == Convergence.ILL_CONDITIONED:
            across = sigma  # a singular point ahead: shorter steps land nearer to it, longer ones past it
        if failed and across is not None:
            cap = settings.step_max / max(float(np.linalg.norm(current.tangent[:-1])), 1e-6)
            if sigma * 2.0 <= cap:
                sigma *= 2.0
                continue
            sigma, across = across, None  # no step across within step_max: back to halving
        if failed:
            sigma *= 0.5
            if sigma < settings.step_min:
                path.stop = Stop(TraceStop.STEP_MIN,
                                 f"corrector failed at the minimum step {settings.step_min:g}: {result.message}")
                return path
            continue
        point = Point(result.x, new_tangent, result.iterations, result.residual)
        new_rates = {label: rate(c, point.X, point.tangent) for label, c in monitors.items()}
        for label, c in monitors.items():
            if rates[label] * new_rates[label] < 0:
                fold = locate_fold(system, current, sigma, c, settings, point)
                if fold is None:  # no evaluation converged: the fold is known to lie in the step, no better
                    path.folds.append(Fold(label, current, len(path.points) - 1, RootStatus.NEAREST))
                else:
                    path.folds.append(Fold(label, fold.payload, len(path.points) - 1, fold.status, fold.bracket))
        reason = stop(point)
        if reason is not None:
            path.stop, path.overshoot, path.step = reason, point, next_step(sigma, point, settings)
            return path
        path.points.append(point)
        if progress is not None:
            progress(point)
        current, rates, across = point, new_rates, None
        sigma = next_step(sigma, point, settings)
    path.stop = Stop(TraceStop.MAX_POINTS, f"maximum number of points ({settings.max_points}) reached")
    return path
