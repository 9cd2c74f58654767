"""The primary (axisymmetric) branch: start at the inflated M = 0 sphere, switch the field on, trace in P.

1. Start: the exact sphere (``sphere``) at the scene's start stretch, where the membrane is taut (the
   first-order system is singular at the undeformed state, MODEL.md §4).
2. Field on: natural continuation in M at that pressure from 0 to the scene's M.
3. Pressure: pseudo-arclength in (u, P) downwards to ``min_stretch`` and upwards to ``stop_stretch`` (landing
   exactly on it), ``stop_pressure``, a wire gap or ``max_points``; folds in P (LP) and in the north pole
   stretch (TP) are located and recorded.

The equator-symmetric subspace is used whenever the field allows it; without a field the axial translation is
removed from the unknowns; with a field that is not equator-symmetric the balloon is held at the centre
(the translation coefficient b_0 is constrained to zero, a reaction force balances the net magnetic pull).
"""
import time
from dataclasses import dataclass, field

import numpy as np

from . import continuation
from .discretisation import Discretisation
from .equilibrium import Equilibrium, Parameters
from .newton import newton
from .sphere import sphere_pressure


class ContinuationError(RuntimeError):
    """The branch could not be started or continued; the message says what to change."""


class ParameterSystem:
    """R(u; p) as a map of X = (u, p) for one continuation parameter p ∈ {P, M}."""

    def __init__(self, equilibrium: Equilibrium, params: Parameters, name: str):
        self.eq, self.params, self.name = equilibrium, params, name

    def _params(self, X):
        return self.params.with_value(self.name, X[-1])

    def residual(self, X):
        return self.eq.residual(X[:-1], self._params(X))

    def jacobian(self, X):
        p = self._params(X)
        return np.hstack([self.eq.jacobian(X[:-1], p), self.eq.parameter_derivative(X[:-1], p, self.name)[:, None]])


@dataclass
class SpecialPoint:
    kind: str  # 'LP' fold in P, 'TP' turning point of the north pole stretch, 'EP' end point
    index: int  # position in the branch (the special point lies between index and index + 1 for folds)
    X: np.ndarray
    note: str = ""


@dataclass
class Branch:
    """A traced branch: unknowns u and pressure P per point, solver records, special points."""

    name: str
    equilibrium: Equilibrium
    disc: Discretisation
    params: Parameters
    X: np.ndarray  # (n_points, n + 1): (u, P)
    iterations: np.ndarray
    residual: np.ndarray
    error_estimate: np.ndarray
    special: list = field(default_factory=list)
    stop_reason: str = ""
    wall_time: float = 0.0

    @property
    def pressure(self):
        return self.X[:, -1]

    def pole_values(self, X=None):
        """dict of λ2 and η at both poles for every point (or for one X)."""
        rows = self.disc.pole_rows()
        U = (self.X if X is None else np.atleast_2d(X))[:, :-1]
        return {name: U @ row for name, row in rows.items()}


def settings_from(scene) -> continuation.Settings:
    c, s = scene.continuation, scene.solver
    return continuation.Settings(c.step, c.step_min, c.step_max, c.max_points, s.tol, s.max_newton)


def make_discretisation(scene, symmetric: bool) -> Discretisation:
    held = bool(scene.field.coils) and not scene.field.is_equator_symmetric
    return Discretisation(scene.solver.degree, symmetric, pin_translation=(not scene.field.coils) or held,
                          quadrature=scene.solver.quadrature)


def wire_gap(disc: Discretisation, u, coils, n_theta: int = 361) -> tuple[float, int]:
    """Smallest distance from the membrane profile to a coil wire, and the coil index."""
    if not len(coils):
        return np.inf, -1
    theta = np.linspace(0.0, np.pi, n_theta)
    lam2, _, eta, _ = disc.evaluate(u, theta)
    rho = lam2 * np.sin(theta)
    gaps = [np.hypot(rho - c.radius, eta - c.height).min() for c in coils]
    return float(min(gaps)), int(np.argmin(gaps))


def start_point(scene, equilibrium: Equilibrium) -> tuple[np.ndarray, Parameters]:
    """The inflated M = 0 sphere, then the field switched on by natural continuation in M (bounded halving)."""
    disc, material = equilibrium.disc, scene.material
    lam = scene.continuation.start_stretch
    a = np.zeros(disc.degree + 1)
    b = np.zeros(disc.degree + 1)
    a[0], b[1] = lam, lam
    u = disc.join(a, b)
    params = Parameters(sphere_pressure(material, lam), 0.0, scene.field.chi)
    target_M, M, dM = scene.field.M, 0.0, scene.field.M
    tol, max_newton = scene.solver.tol, scene.solver.max_newton
    while M < target_M:
        trial = min(M + dM, target_M)
        system = ParameterSystem(equilibrium, params, "M")
        result = newton(system.residual, system.jacobian, np.append(u, trial), _unit(u.size + 1, -1), trial,
                        tol, max_newton)
        if result.converged:
            u, M = result.x[:-1], trial
            dM *= 2
        else:
            dM *= 0.5
            if dM < 1e-6 * max(target_M, 1e-12):
                raise ContinuationError(
                    f"could not switch the field on at start stretch {lam}: Newton failed at M = {trial:.6g} "
                    f"({result.message}); try a smaller [continuation].start_stretch or a smaller M"
                )
    return u, params.with_value("M", target_M)


def _unit(size, index):
    e = np.zeros(size)
    e[index] = 1.0
    return e


def trace_primary(scene, symmetric: bool | None = None, stop_stretch: float | None = None, progress=None) -> Branch:
    """Trace the primary branch of a scene; see the module docstring for the stages and stop rules."""
    t0 = time.perf_counter()
    if symmetric is None:
        symmetric = scene.continuation.symmetry != "none" and scene.field.is_equator_symmetric
    disc = make_discretisation(scene, symmetric)
    eq = Equilibrium(scene, disc)
    u, params = start_point(scene, eq)
    settings = settings_from(scene)
    system = ParameterSystem(eq, params, "P")
    X0 = np.append(u, params.P)
    north = np.append(disc.pole_rows()["lam2_north"], 0.0)
    monitors = {"LP": _unit(X0.size, -1), "TP": north}
    cont = scene.continuation
    upper = cont.stop_stretch if stop_stretch is None else stop_stretch

    def stop(point):
        stretch = float(north @ point.X)
        if stretch >= upper:
            return f"reached stop_stretch {upper:g}"
        if stretch <= cont.min_stretch:
            return f"reached min_stretch {cont.min_stretch:g}"
        if cont.stop_pressure is not None and point.X[-1] >= cont.stop_pressure:
            return f"reached stop_pressure {cont.stop_pressure:g}"
        gap, coil = wire_gap(disc, point.X[:-1], scene.field.coils)
        if gap < cont.wire_gap:
            return f"membrane within wire_gap {cont.wire_gap:g} of coil {coil} (gap {gap:.3g})"
        return None

    t_up = continuation.tangent(system, X0, north)
    start = continuation.Point(X0, t_up, 0, float(np.abs(system.residual(X0)).max()))
    legs = {}
    for direction, t in (("down", -t_up), ("up", t_up)):
        legs[direction] = continuation.trace(system, continuation.Point(X0, t, 0, start.residual), settings,
                                             stop, monitors, progress)
    up, down = legs["up"], legs["down"]
    points = down.points[:0:-1] + up.points
    offset = len(down.points) - 1
    special = [SpecialPoint(f.label, offset - f.index - 1, f.point.X) for f in down.folds[::-1]]
    special += [SpecialPoint(f.label, offset + f.index, f.point.X) for f in up.folds]
    if up.stop_reason.startswith("reached stop_stretch") and up.overshoot is not None:
        end = _land(system, up.points[-1], up.overshoot, north, upper, settings)
        if end is not None:
            points.append(end)
            special.append(SpecialPoint("EP", len(points) - 1, end.X, "stop_stretch"))
    X = np.array([p.X for p in points])
    return Branch(
        name="primary",
        equilibrium=eq,
        disc=disc,
        params=params,
        X=X,
        iterations=np.array([p.iterations for p in points]),
        residual=np.array([p.residual for p in points]),
        error_estimate=np.array([disc.tail(x[:-1]) for x in X]),
        special=special,
        stop_reason=f"up: {up.stop_reason}; down: {down.stop_reason}",
        wall_time=time.perf_counter() - t0,
    )


def _land(system, before, after, row, target, settings):
    """The point with row·X = target between two branch points (Newton from the linear interpolant)."""
    f0, f1 = row @ before.X, row @ after.X
    guess = before.X + (target - f0) / (f1 - f0) * (after.X - before.X)
    result = newton(system.residual, system.jacobian, guess, row, target, settings.tol, settings.max_newton)
    if not result.converged:
        return None
    return continuation.Point(result.x, continuation.tangent(system, result.x, before.tangent), result.iterations,
                              result.residual)
