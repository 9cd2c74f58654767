"""The primary (axisymmetric) branch: start at the inflated M = 0 sphere, switch the field on, trace in P.

1. Start: the exact sphere (``model.sphere``) at the scene's start stretch, where the membrane is taut (the
   first-order system is singular at the undeformed state, MODEL.md §4).
2. Field on: natural continuation in M at that pressure from 0 to the scene's M.
3. Pressure: pseudo-arclength in (u, P) downwards to ``min_stretch`` and upwards to ``stop_stretch`` (landing
   exactly on it), ``stop_pressure``, a wire gap or ``max_points``; folds in P (LP) and in the north pole
   stretch (TP) are located and recorded; the degree and basis map adapt (``tracer``).

The equator-symmetric subspace is used whenever the field allows it; without a field the axial translation is
removed from the unknowns; with a field that is not equator-symmetric the balloon is held at the centre
(the translation coefficient b_0 is constrained to zero, a reaction force balances the net magnetic pull).
"""
import time

import numpy as np

from ..galerkin.equilibrium import Parameters
from ..model.sphere import sphere_pressure
from ..numerics import continuation
from ..numerics.continuation import Stop
from ..numerics.newton import newton
from .assembly import assemble
from .problem import ParameterSystem
from .results import Branch, StopCode
from .tracer import ContinuationError, Tracer, unit
from .wires import wire_gap


def start(tracer: Tracer) -> tuple[np.ndarray, Parameters]:
    """The inflated M = 0 sphere, then the field switched on by natural continuation in M (bounded halving)."""
    scene = tracer.scene
    eq = tracer.system(scene.solver.degree, Parameters(0.0)).eq
    disc = eq.disc
    lam = scene.continuation.start_stretch
    a, b = np.zeros(disc.degree + 1), np.zeros(disc.degree + 1)
    a[0], b[1] = lam, lam
    u = disc.join(a, b)
    params = Parameters(sphere_pressure(scene.material, lam), 0.0, scene.field.chi)
    target, M, dM = scene.field.M, 0.0, scene.field.M
    while M < target:
        trial = min(M + dM, target)
        system = ParameterSystem(eq, params, "M")
        result = newton(system.residual, system.jacobian, np.append(u, trial), unit(u.size + 1, -1), trial,
                        scene.solver.tol, scene.solver.max_newton)
        if result.converged:
            u, M = result.x[:-1], trial
            dM *= 2
        else:
            dM *= 0.5
            if dM < 1e-6 * target:
                raise ContinuationError(
                    f"could not switch the field on at start stretch {lam}: Newton failed at M = {trial:.6g} "
                    f"({result.message}); try a smaller continuation.start_stretch or a smaller field.M"
                )
    return np.append(u, params.P), params.with_value("M", target)


def initial_point(tracer: Tracer, X0, direction: float, params: Parameters) -> continuation.Point:
    """X0 with its unit tangent oriented so that the north pole stretch moves in ``direction``."""
    system = tracer.system(tracer.scene.solver.degree, params)
    north = np.append(system.eq.disc.pole_rows()["lam2_north"], 0.0)
    return continuation.Point(X0, direction * continuation.tangent(system, X0, north), 0, 0.0)


def stop_rule(scene, upper: float):
    """stop(disc, point) -> Stop or None: the north pole stretch leaves [min_stretch, upper], P reaches
    stop_pressure, or the membrane comes within wire_gap of a coil."""
    cont = scene.continuation

    def stop(disc, point):
        stretch = float(disc.pole_rows()["lam2_north"] @ point.X[:-1])
        if stretch >= upper:
            return Stop(StopCode.STOP_STRETCH, f"reached stop_stretch {upper:g}")
        if stretch <= cont.min_stretch:
            return Stop(StopCode.MIN_STRETCH, f"reached min_stretch {cont.min_stretch:g}")
        if cont.stop_pressure is not None and point.X[-1] >= cont.stop_pressure:
            return Stop(StopCode.STOP_PRESSURE, f"reached stop_pressure {cont.stop_pressure:g}")
        gap, coil = wire_gap(disc, point.X[:-1], scene.field.coils)
        if gap < cont.wire_gap:
            return Stop(StopCode.WIRE_GAP, f"membrane within wire_gap {cont.wire_gap:g} of coil {coil} (gap {gap:.3g})")
        return None

    return stop


def trace_primary(scene, symmetric: bool | None = None, stop_stretch: float | None = None, down: bool = True,
                  progress=None) -> Branch:
    """Trace the primary branch of a scene (module docstring). ``down=False`` skips the leg below the start."""
    t0 = time.perf_counter()
    tracer = Tracer(scene, symmetric)
    X0, params = start(tracer)
    upper = scene.continuation.stop_stretch if stop_stretch is None else stop_stretch
    stop = stop_rule(scene, upper)
    up = tracer.leg(initial_point(tracer, X0, 1.0, params), params, stop, progress)
    below = tracer.leg(initial_point(tracer, X0, -1.0, params), params, stop, progress) if down else None
    land_on = {StopCode.STOP_STRETCH: upper, StopCode.MIN_STRETCH: scene.continuation.min_stretch}
    return assemble(tracer, params, "primary", up, below, t0, land_on=land_on, labels=("up", "down"))
