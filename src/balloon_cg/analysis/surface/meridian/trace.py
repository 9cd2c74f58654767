"""The non-axisymmetric branch born at a located m ≥ 1 zero of a surface over a meridian (basis.py: a tube's,
tube/surface/branch.py; a capsule's, capsule.py), traced in P (docs/tubes.md "The tube over (S, φ)"; ``[surface]
branches``).

Point 0 is the zero itself (c = u, P_0: amplitude 0); point 1 the switched point at ε = START_AMPLITUDE along the
critical mode φ (switching.point_at_amplitude, on the orders (0, m, 2m) and the parent's degree, then re-solved at the
same ε on the bases the shape's resolution policy asks for until its error estimate is below solver.max_error);
from there pseudo-arclength continuation (numerics/continuation.py) of system.py's R(X) = 0,
X = (c, τ, P), the tangent oriented along +φ, folds in P located (LP). It stops where the amplitude a = φᵀ G c_m
changes sign (REJOINED: back through the axisymmetric states), the largest hoop stretch |a_φ| over the nodes passes
continuation.stop_stretch (HOOP_STRETCH), a signal (INTERRUPTED), the corrector fails at step_min or after
``max_points`` ([surface] max_points). ``direction`` −1 traces the other half of the pitchfork (the image of the
first under the rotation by π/m, which rotation.py gives without a trace: P the same at opposite amplitudes).

Refinement, as the sphere's surface branches (analysis/surface/branches.py): a point whose error estimate (the
policy's ``error_estimate``: tube/surface/resolution.py, capsule_resolution.py) exceeds solver.max_error is rejected,
the basis refined (the policy's ``refined``: the degree and the orders separately), the last kept point solved again
on it on the hyperplane through it normal to its tangent, and the trace goes on (REFINE_FAILED where that Newton
fails). Where the basis would pass the policy's MAX_DEGREE or MAX_HARMONICS the trace goes on at the cap, every
point's estimate stored, and the branch is flagged ``limited``: never silently. The points are stored on the final
basis (the earlier ones raised: the basis' ``raised``), each with the estimate and the stability read on the basis it
was solved on.
"""
from dataclasses import dataclass

import numpy as np

from .basis import MeridianSurfaceBasis
from .equilibrium import MeridianSurfaceEquilibrium
from .stability import SectorStability
from .switching import SwitchedPoint, mode_row, point_at_amplitude
from .system import MeridianSurfaceSystem
from ...branches.problem import continuation_settings
from ...results import IntervalStop, StopCode, signalled
from ....galerkin.equilibrium import Parameters
from ....numerics import continuation, interrupt
from ....numerics.continuation import Stop, TraceStop
from ....numerics.newton import newton
from ....scene.loading import Control

START_AMPLITUDE = 0.05  # ε of the switched point the trace starts from (G-unit mode: ~5 % of the tube's radius)


class SurfaceBranchStartError(ArithmeticError):
    """The switched point (the trace's first step off the axisymmetric branch) did not converge."""


@dataclass(frozen=True)
class MeridianSurfaceBranch:
    """Per point the ``coefficients`` c on ``basis`` (the final one: module docstring), ``pressure``, ``volume``
    (V/V0), ``amplitude`` φᵀ G c_m, ``reaction`` τ, ``error_estimate`` (on the basis the point was solved on), the
    ``lowest`` COUNT eigenvalues of the mirror sector's pencil under pressure control and the ``unstable`` counts
    under each control (stability.py); ``folds``: (index, pressure) of each located LP (between points
    index and index + 1); ``m``; ``parent``: (branch name, label) of the zero it was born at; ``stop``; ``limited``:
    the basis reached its cap with an estimate above solver.max_error (module docstring); ``image_of``: the name of
    the branch this one is the image of under the rotation by π/m about the axis (rotation.py), "" where traced;
    ``events``: its UZ points (events.MeridianEvent: ``[[events]]``, events.py)."""

    basis: MeridianSurfaceBasis
    m: int
    coefficients: np.ndarray
    pressure: np.ndarray
    volume: np.ndarray
    amplitude: np.ndarray
    reaction: np.ndarray
    error_estimate: np.ndarray
    lowest: np.ndarray
    unstable: dict
    folds: tuple
    stop: Stop
    parent: tuple | None = None
    limited: bool = False
    image_of: str = ""
    events: tuple = ()


def largest_hoop_stretch(basis: MeridianSurfaceBasis, c: np.ndarray) -> float:
    """max |a_φ| over the nodes (a_φ = ∂x/∂φ / R: the stretch of the φ-lines)."""
    return float(np.max(np.linalg.norm(basis.node_state(c)[6:9], axis=0)))


class _Leg:
    """The points traced on one basis: its ``system`` (R(X) of system.py) and ``row``, the amplitude
    φᵀ G c_m as a row on X (φ raised to the basis)."""

    def __init__(self, scene, basis: MeridianSurfaceBasis, params: Parameters, template: np.ndarray, m: int,
                 mode: np.ndarray):
        self.system = MeridianSurfaceSystem(MeridianSurfaceEquilibrium(scene, basis), params, template)
        self.basis, self.points = basis, []
        self.row = np.append(mode_row(basis, m, mode[basis.block(m)])[self.system.free],
                             [0.0] * (1 + self.system.gauged))

    def amplitude(self, c: np.ndarray) -> float:
        """φᵀ G c_m of the coefficients c of the basis."""
        return float(self.row[:self.system.free.size] @ c[self.system.free])


def resolved_start(scene, point: SwitchedPoint, mode: np.ndarray, params: Parameters, policy) -> tuple:
    """(the switched ``point`` solved again at its amplitude on the bases ``policy.refined`` asks for until its
    estimate is below solver.max_error, whether the cap stopped that: ``limited``); ``mode`` φ as c on
    ``point.basis``. SurfaceBranchStartError where Newton fails on a refined basis."""
    solver = scene.solver
    while True:
        finer = policy.refined(point.basis, point.c, point.m, solver.max_error)
        if finer is None or finer is point.basis:
            return point, finer is None
        phi = point.basis.raised(mode, finer)
        again = point_at_amplitude(scene, finer, point.basis.raised(point.c, finer), point.pressure,
                                   mode_row(finer, point.m, phi[finer.block(point.m)]), point.amplitude, point.m,
                                   params, solver.tol, solver.max_newton)
        if not again.converged:
            raise SurfaceBranchStartError(f"the switched point at ε = {point.amplitude:g} did not converge on the "
                                          f"refined basis (degree {finer.disc.degree}, orders {finer.orders}): "
                                          f"{again.message}")
        point, mode = again, phi


def _stop_rule(scene, leg: _Leg, direction: float, resolving: bool, policy):
    """stop(point) -> Stop or None (module docstring); ``policy``'s estimate checked while ``resolving`` (below the
    cap)."""
    upper, max_error = scene.continuation.stop_stretch, scene.solver.max_error

    def stop(point):
        if leg.row @ point.X * direction <= 0:
            return Stop(IntervalStop.REJOINED, "rejoined the axisymmetric states (the amplitude changed sign)")
        c = leg.system.coefficients(point.X)
        stretch = largest_hoop_stretch(leg.basis, c)
        if stretch >= upper:
            return Stop(IntervalStop.HOOP_STRETCH, f"largest hoop stretch {stretch:.4g} passed stop_stretch "
                                                   f"{upper:g}")
        error = policy.error_estimate(leg.basis, c) if resolving else 0.0
        if error > max_error:
            return Stop(StopCode.RESOLUTION, f"error estimate {error:.2g} above solver.max_error {max_error:g} at "
                                             f"degree {leg.basis.disc.degree}, orders up to {leg.basis.orders[-1]}")
        return signalled()

    return stop


def trace_from(scene, first: SwitchedPoint, mode: np.ndarray, zero: np.ndarray, pressure: float,
               params: Parameters, policy, direction: float = 1.0, max_points: int | None = None,
               parent: tuple | None = None, progress=None) -> MeridianSurfaceBranch:
    """The branch through the switched point ``first`` (any MeridianSurfaceBasis), born at the axisymmetric state
    ``zero`` (c on ``first.basis``) at ``pressure`` along the critical ``mode`` (c on ``first.basis``), traced
    (module docstring) with the error estimate and refinement of ``policy`` (the resolution module of the basis'
    shape: ``error_estimate``, ``refined``, MAX_DEGREE, MAX_HARMONICS; tube/surface/resolution.py,
    capsule_resolution.py); ``progress``: callable(point), told of every traced point; SurfaceBranchStartError where
    ``first`` did not converge, or where the zero's largest hoop stretch already passes continuation.stop_stretch
    (a capsule's primary stops at its pole stretch, which is below its cylinder's hoop stretch: the branch would
    end at its first point)."""
    solver, m = scene.solver, first.m
    if not first.converged:
        raise SurfaceBranchStartError(f"the switched point at ε = {first.amplitude:g} did not converge: "
                                      f"{first.message}")
    if (stretch := largest_hoop_stretch(first.basis, zero)) >= scene.continuation.stop_stretch:
        raise SurfaceBranchStartError(f"the zero's largest hoop stretch {stretch:.4g} already passes "
                                      f"continuation.stop_stretch {scene.continuation.stop_stretch:g}, where the "
                                      f"branch would stop: raise continuation.stop_stretch above it")
    origin_basis = first.basis
    origin = _Leg(scene, origin_basis, params, first.c, m, mode)
    first, limited = resolved_start(scene, first, mode, params, policy)
    leg = _Leg(scene, first.basis, params, first.c, m, origin_basis.raised(mode, first.basis))
    X = leg.system.point(first.c, first.pressure)
    start = continuation.Point(X, continuation.tangent(leg.system, X, direction * leg.row), first.iterations,
                               first.residual)
    max_points = max_points or scene.surface.max_points
    legs, folds, done = [leg], [], 1  # done: the points kept so far (point 0, the zero, is not the tracer's)
    while True:
        path = continuation.trace(leg.system, start, continuation_settings(scene, max(max_points - done, 1)),
                                  _stop_rule(scene, leg, direction, not limited, policy),
                                  {"LP": np.eye(start.X.size)[-1]}, progress)
        stop = path.stop
        # a fold in the step to a point the estimate rejects is found again from the re-solved last point
        folds += [(f.index + done, float(f.point.X[-1])) for f in path.folds
                  if stop.code != StopCode.RESOLUTION or f.index < len(path.points) - 1]
        leg.points += path.points  # after the cap the run goes on from the leg's last point
        done += len(path.points)
        if stop.code != StopCode.RESOLUTION:
            break
        finer = policy.refined(leg.basis, leg.system.coefficients(path.overshoot.X), m, solver.max_error)
        last = leg.points.pop()  # the start of the next run: on the finer basis, or here at the cap
        done -= 1
        if finer is None:
            limited, start = True, last
            continue
        new = _Leg(scene, finer, params, leg.basis.raised(leg.system.coefficients(last.X), finer), m,
                   origin_basis.raised(mode, finer))
        moved, reference = leg.system.raised(last.X, new.system), leg.system.raised(last.tangent, new.system, True)
        across = reference / np.linalg.norm(reference)  # the hyperplane through it normal to the branch
        result = newton(new.system.residual, new.system.jacobian, moved, across, across @ moved, solver.tol,
                        solver.max_newton)
        if not result.converged:
            leg.points.append(last)
            stop = Stop(StopCode.REFINE_FAILED, f"Newton failed on the refined basis (degree {finer.disc.degree}, "
                                                f"orders up to {finer.orders[-1]}): {result.message}")
            break
        start = continuation.Point(result.x, continuation.tangent(new.system, result.x, reference),
                                   result.iterations, result.residual)
        leg = new
        legs.append(leg)
    if stop.code == TraceStop.MAX_POINTS:
        stop = Stop(TraceStop.MAX_POINTS, f"maximum number of points ({max_points}) reached")
    if limited:
        stop = Stop(stop.code, f"{stop.message}; limited: the basis at its cap (degree ≤ {policy.MAX_DEGREE}, orders "
                               f"up to {policy.MAX_HARMONICS} m) with error estimates above solver.max_error "
                               f"{solver.max_error:g}")
    return _branch(origin, legs, (m, zero, pressure), params, tuple(folds), stop, parent, limited, policy)


def _branch(origin: _Leg, legs: list, born: tuple, params: Parameters, folds: tuple, stop: Stop, parent: tuple | None,
            limited: bool, policy) -> MeridianSurfaceBranch:
    """The MeridianSurfaceBranch of the traced ``legs``, point 0 the zero on ``origin`` (the switched point's first
    basis): every point's values, estimate and stability on its own basis, its coefficients raised to the last."""
    final = legs[-1].basis
    m, zero, pressure = born  # the order, the zero's c on the origin's basis and its P
    points = [(origin, zero, pressure, 0.0)]
    points += [(leg, leg.system.coefficients(p.X), p.X[-1], leg.system.reaction(p.X)) for leg in legs
               for p in leg.points]
    readers = {id(leg): SectorStability(leg.system) for leg in (origin, *legs)}
    readings, traced_whole = [], not interrupt.requested()  # a signal in the trace: its points are all read
    for leg, c, P, _ in points:
        if readings and traced_whole and interrupt.requested():  # readings of minutes: the points read are kept
            stop = Stop(StopCode.INTERRUPTED, f"interrupted (SIGINT or SIGTERM) while reading the stability: the "
                                              f"{len(readings)} points read are kept")
            points, folds = points[:len(readings)], tuple(f for f in folds if f[0] < len(readings) - 1)
            break
        readings.append(readers[id(leg)](c, params.with_value("P", P)))
    return MeridianSurfaceBranch(
        final, m, np.array([leg.basis.raised(c, final) for leg, c, _, _ in points]),
        np.array([P for _, _, P, _ in points]),
        np.array([leg.basis.volume_ratio(leg.system.surface.volume(c)) for leg, c, _, _ in points]),
        np.array([leg.amplitude(c) for leg, c, _, _ in points]), np.array([tau for *_, tau in points]),
        np.array([policy.error_estimate(leg.basis, c) for leg, c, _, _ in points]),
        np.array([lowest for lowest, _ in readings]),
        {control: np.array([counts[control] for _, counts in readings], dtype=int) for control in Control},
        folds, stop, parent, limited)
