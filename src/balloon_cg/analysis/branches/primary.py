"""The primary (axisymmetric) branch: start at the inflated M = 0 sphere, switch the field on, trace in P (or Φ̄).

1. Start: the exact sphere (``model.sphere``) at the scene's start stretch, where the membrane is taut (the
   first-order system is singular at the undeformed state, MODEL.md §4): its pressure at the scene's voltage,
   or, for continuation.parameter = "voltage", its voltage at the scene's fixed pressure. Another reference
   shape (scene.Geometry: the spheroid, the capsule) has no closed form: its start is solved from the unstressed
   reference (λ2 = 1, η = Z(θ), P = 0, an exact equilibrium) by natural continuation in the north pole stretch up
   to the start stretch, P an unknown (``inflated_reference``); for a voltage continuation the voltage holding
   that stretch at the scene's pressure is then solved for (``held_by_voltage``).
2. Field on: natural continuation in M at that pressure (and voltage) from 0 to the scene's M.
3. Continuation: pseudo-arclength in (u, P) (or (u, Φ̄) at fixed P) downwards to ``min_stretch`` and upwards to
   ``stop_stretch`` (landing exactly on it), ``stop_pressure`` (``stop_voltage``), ``continuation.stop_volume`` (any
   control), ``loading.stop_amount``, a wire gap or ``max_points``; folds in the parameter (LP), in the north pole
   stretch (TP) and in the control parameter V or n (LV, LN) are located and recorded; the degree and basis map adapt
   (``tracer``).

The equator-symmetric subspace is used whenever the field allows it; without a field (no coils, or M = 0) the
axial translation is removed from the unknowns; with a field that is not equator-symmetric the balloon is held at
the centre (the translation coefficient b_0 is constrained to zero, a reaction force balances the net magnetic
pull).
"""
import time

import numpy as np

from ...galerkin.discretisation import Discretisation, held_surface
from ...galerkin.equilibrium import Parameters
from ...galerkin.profiles import meridional_stretch
from ...model import meridian
from ...model.sphere import sphere_pressure, sphere_voltage
from ...model.stresses import dielectric_stress, elastic_stresses
from ...numerics import continuation
from ...numerics.continuation import Stop
from ...numerics.newton import newton
from .assembly import PARAMETER, assemble
from .control import control_value, landing, scene_stops
from .events import with_events
from .problem import ParameterSystem
from ..results import Branch, StopCode
from .tracer import ContinuationError, Tracer, scene_parameter, unit
from .wires import wire_gap
from ...scene import Shape
from ...numerics.threads import limited_blas


def start(tracer: Tracer) -> tuple[continuation.Point, Parameters, int]:
    """The inflated M = 0 sphere, then the field switched on by natural continuation in M (bounded halving), on
    a degree that resolves it: (the start point, its parameters, its degree). Raises ContinuationError when the
    field cannot be switched on or the start is not resolved up to solver.max_degree (never a guess). A free
    balloon in a field without equator symmetry (``Tracer.free_off_equator``) is switched on held, then released
    (``released``)."""
    scene = tracer.scene
    if tracer.free_off_equator:
        return released(tracer, *start(Tracer(scene, tracer.symmetric, held=True)))
    degree = scene.solver.degree
    eq = tracer.system(degree, Parameters(0.0)).eq
    disc = eq.disc
    lam = scene.continuation.start_stretch
    if scene.geometry.shape == Shape.SPHERE:
        params = start_parameters(scene, tracer.parameter)
        a, b = np.zeros(disc.degree + 1), np.zeros(disc.degree + 1)
        a[0], b[1] = lam, lam
        u = disc.join(a, b)
    elif tracer.parameter == "voltage":
        params = Parameters(scene.continuation.pressure, 0.0, scene.field.chi, 0.0)
        u, voltage = held_by_voltage(tracer, degree, lam, params)
        params = params.with_value("voltage", voltage)
    else:
        params = start_parameters(scene, tracer.parameter)
        u, P = inflated_reference(tracer, degree, lam, params)
        params = params.with_value("P", P)
    if scene.electric is not None and not _taut(disc, u, scene.material, params.voltage, scene.geometry):
        raise ContinuationError(f"the sphere at continuation.start_stretch = {lam:g} is compressed at the voltage "
                                f"{params.voltage:.6g} (its dielectric stress exceeds the elastic tension); "
                                "start at another continuation.start_stretch")
    target, M, dM = scene.field.M, 0.0, scene.field.M
    system = ParameterSystem(eq, params, "M")
    while M < target:
        trial = min(M + dM, target)
        result = newton(system.residual, system.jacobian, np.append(u, trial), unit(u.size + 1, -1), trial,
                        scene.solver.tol, scene.solver.max_newton)
        if result.converged and _taut(disc, result.x[:-1], scene.material, params.voltage, scene.geometry):
            u, M = result.x[:-1], trial
            dM *= 2
        elif result.converged:
            raise ContinuationError(_wrinkling_limit(system, u, M, trial, scene))
        else:
            dM *= 0.5
            if dM < 1e-6 * target:
                raise ContinuationError(
                    f"could not switch the field on at continuation.start_stretch = {lam:g} beyond M = {M:.6g} "
                    f"(Newton failed at M = {trial:.6g}: {result.message}; at fixed pressure the equilibrium may "
                    "turn back in M there); try another continuation.start_stretch or a smaller field.M"
                )
    params = params.with_value("M", target)
    X, degree = _resolved_start(tracer, np.append(u, getattr(params, tracer.parameter)), degree, params)
    residual = float(np.abs(tracer.system(degree, params).residual(X)).max())
    return continuation.Point(X, np.zeros_like(X), 0, residual), params, degree


def released(tracer: Tracer, held: continuation.Point, params: Parameters,
             degree: int) -> tuple[continuation.Point, Parameters, int]:
    """The free balloon's start from the held one at the same P and M (MODEL.md §8: a free balloon centres where
    the net force vanishes): the held state (b_0 = 0) with its axial translation b_0 an unknown, solved by Newton
    at fixed P, where the b_0 row of the residual is the net axial force (its ∂E/∂b_0); then resolved
    (``_resolved_start``). ContinuationError when Newton does not reach a free equilibrium."""
    scene = tracer.scene
    system = tracer.system(degree, params)
    pinned = Discretisation(degree, tracer.symmetric, True, joins=system.eq.disc.joins,
                            held=held_surface(scene.geometry, tracer.symmetric, True))
    X = np.append(system.eq.disc.join(*pinned.split(held.X[:-1])), held.X[-1])
    result = newton(system.residual, system.jacobian, X, unit(X.size, -1), X[-1], scene.solver.tol,
                    scene.solver.max_newton)
    if not result.converged:
        raise ContinuationError(f"the free balloon's start (the held start at P = {X[-1]:.6g}, M = {params.M:g} "
                                f"released along the axis) did not converge: {result.message}")
    X, degree = _resolved_start(tracer, result.x, degree, params)
    residual = float(np.abs(tracer.system(degree, params).residual(X)).max())
    return continuation.Point(X, np.zeros_like(X), 0, residual), params, degree


def inflated_reference(tracer: Tracer, degree: int, stretch: float, params: Parameters) -> tuple[np.ndarray, float]:
    """(u, P) of the M = 0 equilibrium whose north pole stretch is ``stretch``, on the scene's reference shape:
    from the unstressed reference (a_0 = 1, b_1 = aspect: λ2 = 1, η = aspect cos θ, P = 0; a capsule's η = Z(θ)
    projected on the basis and solved at P = 0, its meridian being no polynomial in cos θ) by natural
    continuation in the pole stretch (steps doubled after a success, halved after a failure), each point solved
    by Newton on R(u; P) = 0 with the pole row λ2(0) = r_n·u prescribed (galerkin.point_solve's system); under a
    voltage (a capsule with [electric]) the reference is inflated without it, then the voltage is switched on at
    that pole stretch by natural continuation in Φ̄ (P still the unknown). ContinuationError when the step falls
    below 1e-6 of the way."""
    scene = tracer.scene
    uncharged = params.with_value("P", 0.0).with_value("voltage", 0.0)
    system = ParameterSystem(tracer.system(degree, uncharged).eq, uncharged, "P")  # P the unknown, whatever the trace's
    disc = system.eq.disc
    a, b = np.zeros(disc.degree + 1), np.zeros(disc.degree + 1)
    a[0], b[1] = 1.0, scene.geometry.aspect
    if scene.geometry.shape == Shape.CAPSULE:
        b = disc.projection @ meridian.reference_height(scene.geometry, np.arccos(disc.x))
    X = np.append(disc.join(a, b), 0.0)
    row = np.append(disc.pole_rows()["lam2_top"], 0.0)

    def solve(X, value):
        return newton(system.residual, system.jacobian, X, row, value, scene.solver.tol, scene.solver.max_newton)

    if scene.geometry.shape == Shape.CAPSULE:  # its projected reference: the discrete unstressed state at P = 0
        reference = solve(X, 1.0)
        if not reference.converged:
            raise ContinuationError(f"the unstressed {scene.geometry.describe()} did not converge at P = 0 "
                                    f"({reference.message}); try a higher solver.degree")
        X = reference.x
    X, reached, message = continuation.natural(solve, X, 1.0, stretch)
    if reached < stretch:
        raise ContinuationError(f"could not inflate the {scene.geometry.shape.value} to continuation.start_stretch "
                                f"= {stretch:g} beyond the north pole stretch {reached:.6g} ({message}); "
                                "try a smaller continuation.start_stretch")
    if params.voltage:
        def charged(X, voltage):
            charging = ParameterSystem(system.eq, params.with_value("P", X[-1]).with_value("voltage", voltage), "P")
            return newton(charging.residual, charging.jacobian, X, row, stretch, scene.solver.tol,
                          scene.solver.max_newton)

        X, reached, message = continuation.natural(charged, X, 0.0, params.voltage)
        if reached < params.voltage:
            raise ContinuationError(f"could not switch the voltage on at continuation.start_stretch = {stretch:g} "
                                    f"beyond {reached:.6g} ({message}); try a larger continuation.start_stretch")
    return X[:-1], float(X[-1])


def held_by_voltage(tracer: Tracer, degree: int, stretch: float, params: Parameters) -> tuple[np.ndarray, float]:
    """(u, Φ̄) of the M = 0 equilibrium whose north pole stretch is ``stretch`` at the pressure params.P, on any
    reference shape (the sphere's closed form is ``model.sphere.sphere_voltage``): the voltage-free state at that
    stretch (``inflated_reference``, its pressure P0), then natural continuation in P from P0 to params.P at that
    pole stretch with (u, s = Φ̄²) the unknowns. The residual is linear in s (the dielectric term −Φ̄²λ1²λ2²):
    R(u; P, s) = R(u; P, 0) + s D(u), D = ½ ∂R/∂Φ̄ at Φ̄ = 1, so its Jacobian is regular at s = 0, where the one in Φ̄
    is singular (∂R/∂Φ̄ = 2Φ̄ D). ContinuationError where no voltage holds that stretch at P: a voltage moves its
    pressure away from P (ds/dP at s = 0, from the bordered system [∂R/∂u, D; pole row, 0], has the sign of P0 − P),
    or the continuation does not get there or ends at s < 0."""
    scene = tracer.scene
    u, free = inflated_reference(tracer, degree, stretch, params.with_value("voltage", 0.0))
    eq = tracer.system(degree, params).eq
    row = np.append(eq.disc.pole_rows()["lam2_top"], 0.0)

    def solve(Y, t):
        at = params.with_value("P", free + t * (params.P - free))

        def residual(Y):
            return eq.residual(Y[:-1], at.with_value("voltage", 0.0)) + Y[-1] * charge(Y[:-1])

        def jacobian(Y):
            return np.column_stack([eq.jacobian(Y[:-1], at.with_value("voltage", np.sqrt(max(Y[-1], 0.0)))),
                                    charge(Y[:-1])])

        return newton(residual, jacobian, Y, row, stretch, scene.solver.tol, scene.solver.max_newton)

    def charge(u):
        return 0.5 * eq.parameter_derivative(u, params.with_value("voltage", 1.0), "voltage")

    def refused(why):
        return ContinuationError(f"cannot start the voltage continuation at continuation.start_stretch = {stretch:g}, "
                                 f"continuation.pressure = {params.P:g}: no voltage holds the "
                                 f"{scene.geometry.shape.value} there ({why}); lower continuation.pressure or choose "
                                 "another start_stretch")

    free_params = params.with_value("P", free).with_value("voltage", 0.0)
    bordered = np.vstack([np.column_stack([eq.jacobian(u, free_params), charge(u)]), row])
    rate = np.linalg.solve(bordered, np.append(-eq.parameter_derivative(u, free_params, "P"), 0.0))[-1]  # ds/dP
    if rate * (params.P - free) <= 0:
        raise refused(f"its voltage-free pressure there is {free:.6g}, and a voltage moves it by dP/dΦ̄² = "
                      f"{1 / rate:.4g}: away from P")
    Y, reached, message = continuation.natural(solve, np.append(u, 0.0), 0.0, 1.0)
    if reached < 1.0:
        raise refused(f"the continuation from its voltage-free pressure {free:.6g} stopped at P = "
                      f"{free + reached * (params.P - free):.6g}: {message}")
    if Y[-1] < 0:
        raise refused(f"Φ̄² = {Y[-1]:.3g} < 0 at P")
    return Y[:-1], float(np.sqrt(Y[-1]))


def start_parameters(scene, parameter: str) -> Parameters:
    """The start sphere's parameters at M = 0: its pressure at electric.voltage (parameter "P"), or its voltage
    at continuation.pressure (parameter "voltage"; ContinuationError where no voltage holds it)."""
    lam, chi = scene.continuation.start_stretch, scene.field.chi
    if parameter == "P":
        return Parameters(sphere_pressure(scene.material, lam, scene.voltage), 0.0, chi, scene.voltage)
    P = scene.continuation.pressure
    try:
        return Parameters(P, 0.0, chi, sphere_voltage(scene.material, lam, P))
    except ValueError as e:
        raise ContinuationError(f"cannot start the voltage continuation at continuation.start_stretch = {lam:g}: "
                                f"{e}; lower continuation.pressure or choose another start_stretch") from None


SLACK_TOLERANCE = 1e-8  # compression beyond rounding, relative to the elastic stress; zero stress (P = 0) is traced
_STRESS_GRID = np.linspace(0.0, np.pi, 361)  # θ where a start's stresses are checked


def _smallest_stress(material, lam1, lam2, voltage: float) -> tuple[float, float]:
    """(smallest principal stress, elastic plus dielectric; smallest elastic one) over the given stretches."""
    elastic = np.minimum(*elastic_stresses(material, lam1, lam2))
    return float(np.min(elastic + dielectric_stress(voltage, lam1, lam2))), float(np.min(elastic))


def _taut(disc, u, material, voltage: float, geometry) -> bool:
    """Both elastic principal stresses positive on a fine θ grid (MODEL.md §6: tension-field theory) and the
    dielectric stress not above them (within SLACK_TOLERANCE), on the scene's reference ``geometry``."""
    lam2, dlam2, _, deta = disc.evaluate(u, _STRESS_GRID)
    lam1 = meridional_stretch(_STRESS_GRID, lam2, dlam2, deta, geometry)
    total, elastic = _smallest_stress(material, lam1, lam2, voltage)
    return elastic > 0.0 and total >= -SLACK_TOLERANCE * elastic


def compressed(disc, u, material, voltage: float, geometry) -> bool:
    """At a quadrature node a principal stress (elastic + dielectric) below −SLACK_TOLERANCE × the smallest elastic
    one: the membrane would carry compression, which it cannot (the voltage's Maxwell stress exceeds the elastic
    tension). Checked at every point of a dielectric branch, so on the nodes the solver has (no new grid)."""
    lam2, v, _, w = disc.node_state(u)
    lam1 = meridian.meridional_stretch(geometry, disc.cos_theta, disc.sin_theta, lam2, v, w)
    total, elastic = _smallest_stress(material, lam1, lam2, voltage)
    return total < -SLACK_TOLERANCE * abs(elastic)


def _wrinkling_limit(system: ParameterSystem, u, taut_M: float, wrinkled_M: float, scene, rtol: float = 1e-8) -> str:
    """The message for a start that wrinkles while the field is switched on: the field intensity where the
    smallest elastic principal stress reaches zero, located by bisection between a taut and a wrinkled M."""
    disc, solver = system.eq.disc, scene.solver
    while wrinkled_M - taut_M > rtol * wrinkled_M:
        middle = 0.5 * (taut_M + wrinkled_M)
        result = newton(system.residual, system.jacobian, np.append(u, middle), unit(u.size + 1, -1), middle,
                        solver.tol, solver.max_newton)
        if not result.converged:
            break
        if _taut(disc, result.x[:-1], scene.material, system.params.voltage, scene.geometry):
            u, taut_M = result.x[:-1], middle
        else:
            wrinkled_M = middle
    return (f"cannot start at field.M = {scene.field.M:g}: switched on at continuation.start_stretch = "
            f"{scene.continuation.start_stretch:g}, the membrane wrinkles (its smallest elastic principal stress "
            f"reaches 0) at M = {taut_M:.8g} (tension-field theory is not modelled); start at a larger "
            "continuation.start_stretch, where the inflation keeps it taut")


def _resolved_start(tracer: Tracer, X, degree: int, params: Parameters) -> tuple[np.ndarray, int]:
    """X = (u, P) of the start recomputed (at fixed P and M) on degrees grown by the resolution policy until its
    spectral error estimate is within max_error; ContinuationError past max_degree or when Newton fails."""
    policy, scene = tracer.resolution, tracer.scene
    disc = tracer.system(degree, params).eq.disc
    while not policy.resolved(disc, X[:-1]):
        if degree >= policy.max_degree:
            raise ContinuationError(
                f"the start at continuation.start_stretch = {scene.continuation.start_stretch:g}, field.M = "
                f"{params.M:g} is not resolved: spectral error estimate {disc.tail(X[:-1]):.2g} above "
                f"solver.max_error = {policy.max_error:g} at solver.max_degree = {policy.max_degree}"
                f"{_compression(disc, X)}; try a larger continuation.start_stretch or a smaller field.M")
        degree = policy.grow(degree)
        system = tracer.system(degree, params)
        guess = disc.transfer(X, system.eq.disc)
        result = newton(system.residual, system.jacobian, guess, unit(guess.size, -1), guess[-1],
                        scene.solver.tol, scene.solver.max_newton)
        if not result.converged:
            raise ContinuationError(
                f"the start at field.M = {params.M:g} is not resolved at degree {disc.degree} (error estimate "
                f"{disc.tail(X[:-1]):.2g}) and could not be refined to degree {degree} ({result.message})"
                f"{_compression(disc, X)}; try a larger continuation.start_stretch or a smaller field.M")
        X, disc = result.x, system.eq.disc
    return X, degree


def _compression(disc, X) -> str:
    """'; the membrane is compressed …' when the hoop stretch λ2 falls below 1 somewhere, else ''."""
    lam2 = disc.evaluate(X[:-1], np.linspace(0.0, np.pi, 181))[0]
    if lam2.min() >= 1:
        return ""
    return f"; the membrane is compressed (smallest λ2 = {lam2.min():.4g} < 1: a membrane carries no compression)"


def initial_point(tracer: Tracer, start: continuation.Point, direction: float, params: Parameters,
                  degree: int) -> continuation.Point:
    """The start with its unit tangent oriented so that the north pole stretch moves in ``direction``."""
    system = tracer.system(degree, params)
    north = np.append(system.eq.disc.pole_rows()["lam2_top"], 0.0)
    tangent = direction * continuation.tangent(system, start.X, north)
    return continuation.Point(start.X, tangent, start.iterations, start.residual)


def top_stop_stretch(upper: float) -> Stop:
    """The stop of a branch whose north pole stretch reached ``upper`` (continuation.stop_stretch)."""
    return Stop(StopCode.STOP_STRETCH, f"reached stop_stretch {upper:g}")


def range_limits(scene, upper: float, parameter: str | None = None, params: Parameters | None = None):
    """limits(disc, point) -> Stop or None: a dielectric membrane is compressed, the north pole stretch leaves
    [min_stretch, upper], P reaches stop_pressure (Φ̄ reaches stop_voltage or falls below 0 in a voltage
    continuation; M reaches stop_field or falls below 0 in a continuation in M), or the control parameter reaches
    continuation.stop_volume or loading.stop_amount: the range the scene asks for, and the model's. ``parameter``: the
    continuation parameter (default the scene's, ``tracer.scene_parameter``), ``params`` the fixed ones (default:
    the scene's voltage)."""
    cont, stops = scene.continuation, scene_stops(scene)
    parameter = parameter or scene_parameter(scene)
    in_voltage = parameter == "voltage"
    fixed_voltage = params.voltage if params is not None else getattr(scene.electric, "voltage", 0.0)

    def limits(disc, point):
        if scene.electric is not None:  # first: a compressed point is not landed on, whatever its stretch
            voltage = point.X[-1] if in_voltage else fixed_voltage
            if compressed(disc, point.X[:-1], scene.material, voltage, scene.geometry):
                return Stop(StopCode.COMPRESSED, "the membrane is compressed (dielectric stress above the elastic "
                                                 "tension: tension-field theory is not modelled)")
        stretch = float(disc.pole_rows()["lam2_top"] @ point.X[:-1])
        if stretch >= upper:
            return top_stop_stretch(upper)
        if stretch <= cont.min_stretch:
            return Stop(StopCode.MIN_STRETCH, f"reached min_stretch {cont.min_stretch:g}")
        if cont.stop_pressure is not None and point.X[-1] >= cont.stop_pressure and parameter == "P":
            return Stop(StopCode.STOP_PRESSURE, f"reached stop_pressure {cont.stop_pressure:g}")
        for key, code, control, limit in stops:
            if control_value(disc, point.X, control, scene.geometry) >= limit:
                return Stop(code, f"reached {key} {limit:g}")
        if in_voltage and cont.stop_voltage is not None and point.X[-1] >= cont.stop_voltage:
            return Stop(StopCode.STOP_VOLTAGE, f"reached stop_voltage {cont.stop_voltage:g}")
        if in_voltage and point.X[-1] < 0:  # Φ̄ → −Φ̄ is the same balloon: the branch ends at the voltage-free sphere
            return Stop(StopCode.ZERO_VOLTAGE, "reached voltage 0 (the sphere without voltage)")
        if parameter == "M" and cont.stop_field is not None and point.X[-1] >= cont.stop_field:
            return Stop(StopCode.STOP_FIELD, f"reached stop_field {cont.stop_field:g}")
        if parameter == "M" and point.X[-1] < 0:  # M = I²/(16π²R0²μ) ≥ 0
            return Stop(StopCode.ZERO_FIELD, "reached M = 0 (the balloon without field)")
        return None

    return limits


def stop_rule(scene, upper: float, parameter: str | None = None, params: Parameters | None = None):
    """stop(disc, point) -> Stop or None: ``range_limits``, or the membrane comes within wire_gap of a coil."""
    cont = scene.continuation
    limits = range_limits(scene, upper, parameter, params)

    def stop(disc, point):
        beyond = limits(disc, point)
        if beyond is not None:
            return beyond
        gap, coil = wire_gap(disc, point.X[:-1], scene.field.coils, scene.geometry)
        if gap < cont.wire_gap:
            return Stop(StopCode.WIRE_GAP, f"membrane within wire_gap {cont.wire_gap:g} of coil {coil} (gap {gap:.3g})")
        return None

    return stop


@limited_blas
def trace_primary(scene, symmetric: bool | None = None, stop_stretch: float | None = None, down: bool = True,
                  progress=None, held: bool | None = None, name: str = "primary") -> Branch:
    """Trace the primary branch of a scene (module docstring). ``down=False`` skips the leg below the start;
    ``held=False``: the free balloon's (b_0 an unknown, the net axial force zero; ``Tracer``), named ``name``."""
    t0 = time.perf_counter()
    tracer = Tracer(scene, symmetric, held)
    first, params, degree = start(tracer)
    upper = scene.continuation.stop_stretch if stop_stretch is None else stop_stretch
    stop, limits = stop_rule(scene, upper), range_limits(scene, upper)
    up = tracer.leg(initial_point(tracer, first, 1.0, params, degree), params, stop, progress, degree=degree,
                    limits=limits)
    below = (tracer.leg(initial_point(tracer, first, -1.0, params, degree), params, stop, progress, degree=degree,
                        limits=limits) if down else None)
    return with_events(assemble(tracer, params, name, up, below, t0, land_on=landing_targets(scene, upper),
                                labels=("up", "down")))


def landing_targets(scene, upper: float) -> dict:
    """``assembly.assemble``'s land_on of a primary branch: the north pole stretch at ``upper`` and at
    min_stretch, the control stop (``control.landing``), and a continuation in M's ends (M = 0, stop_field)."""
    field_ends = {StopCode.ZERO_FIELD: (PARAMETER, 0.0)}
    if scene.continuation.stop_field is not None:
        field_ends[StopCode.STOP_FIELD] = (PARAMETER, scene.continuation.stop_field)
    return {StopCode.STOP_STRETCH: ("lam2_top", upper),
            StopCode.MIN_STRETCH: ("lam2_top", scene.continuation.min_stretch)} | landing(scene) | field_ends
