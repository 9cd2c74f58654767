"""The non-axisymmetric branch born at a located m ≥ 1 zero of a tube, traced in P (docs/tubes.md "The tube over
(S, φ)"; ``[surface] branches``).

Point 0 is the zero itself (c = u, P_0: amplitude 0); point 1 the switched point at ε = START_AMPLITUDE along the
critical mode φ (switching.switched_point, on the orders (0, m, 2m) and the parent's degree, then re-solved at the
same ε on the bases tube/surface/resolution.refined asks for until its error estimate is below solver.max_error);
from there pseudo-arclength continuation (numerics/continuation.py) of tube/surface/system.py's R(X) = 0,
X = (c, τ, P), the tangent oriented along +φ, folds in P located (LP). It stops where the amplitude a = φᵀ G c_m
changes sign (REJOINED: back through the axisymmetric states), the largest hoop stretch |a_φ| over the nodes passes
continuation.stop_stretch (HOOP_STRETCH), a signal (INTERRUPTED), the corrector fails at step_min or after
``max_points`` ([surface] max_points). ``direction`` −1 traces the other half of the pitchfork (for odd m the image
of the first under the rotation by π: P the same at opposite amplitudes).

Refinement, as the sphere's surface branches (analysis/surface/branches.py): a point whose error estimate
(resolution.error_estimate: the Legendre tail over every order, or the highest order's largest coefficient relative
to the mean radius) exceeds solver.max_error is rejected, the basis refined from its coefficients' fitted decay (the
degree and the orders separately), the last kept point solved again on it on the hyperplane through it normal to
its tangent, and the trace goes on (REFINE_FAILED where that Newton fails). Where the basis would pass
resolution.MAX_DEGREE or MAX_HARMONICS the trace goes on at the cap, every point's estimate stored, and the branch is
flagged ``limited``: never silently. The points are stored on the final basis (the earlier ones zero-padded:
TubeSurfaceBasis.raised), each with the estimate and the stability read on the basis it was solved on.
"""
from dataclasses import dataclass

import numpy as np

from .basis import TubeSurfaceBasis
from .equilibrium import MeridianSurfaceEquilibrium
from . import capsule_resolution, resolution
from .stability import SectorStability
from .switching import SwitchedPoint, mode_row, point_at_amplitude, switched_point
from .system import TubeSurfaceSystem
from ..results import IntervalStop, signalled
from ...analysis.branches.problem import continuation_settings
from ...analysis.results import StopCode
from ...galerkin.equilibrium import Parameters
from ...numerics import continuation, interrupt
from ...numerics.continuation import Stop, TraceStop
from ...numerics.newton import newton
from ...scene.loading import Control
from ...scene.tables import Shape

START_AMPLITUDE = 0.05  # ε of the switched point the trace starts from (G-unit mode: ~5 % of the tube's radius)
POLICIES = {Shape.TUBE: resolution, Shape.CAPSULE: capsule_resolution}  # a basis' error estimate and refinement


def policy(basis):
    """The resolution module of the basis' shape (``error_estimate``, ``refined``, MAX_DEGREE, MAX_HARMONICS)."""
    return POLICIES[basis.shape]


class SurfaceBranchStartError(ArithmeticError):
    """The switched point (the trace's first step off the axisymmetric branch) did not converge."""


@dataclass(frozen=True)
class TubeSurfaceBranch:
    """Per point the ``coefficients`` c on ``basis`` (the final one: module docstring), ``pressure``, ``volume``
    (V/V0), ``amplitude`` φᵀ G c_m, ``reaction`` τ, ``error_estimate`` (on the basis the point was solved on), the
    ``lowest`` COUNT eigenvalues of the mirror sector's pencil under pressure control and the ``unstable`` counts
    under each control (tube/surface/stability.py); ``folds``: (index, pressure) of each located LP (between points
    index and index + 1); ``m``; ``parent``: (branch name, label) of the zero it was born at; ``stop``; ``limited``:
    the basis reached its cap with an estimate above solver.max_error (module docstring)."""

    basis: TubeSurfaceBasis
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


def largest_hoop_stretch(basis: TubeSurfaceBasis, c: np.ndarray) -> float:
    """max |a_φ| over the nodes (R = 1: the stretch of the φ-lines)."""
    return float(np.max(np.linalg.norm(basis.node_state(c)[6:9], axis=0)))


class _Leg:
    """The points traced on one basis: its ``system`` (R(X) of tube/surface/system.py) and ``row``, the amplitude
    φᵀ G c_m as a row on X (φ raised to the basis)."""

    def __init__(self, scene, basis: TubeSurfaceBasis, params: Parameters, template: np.ndarray, m: int,
                 mode: np.ndarray):
        self.system = TubeSurfaceSystem(MeridianSurfaceEquilibrium(scene, basis), params, template)
        self.basis, self.points = basis, []
        self.row = np.append(mode_row(basis, m, mode[basis.block(m)])[self.system.free],
                             [0.0] * (1 + self.system.gauged))

    def amplitude(self, c: np.ndarray) -> float:
        """φᵀ G c_m of the coefficients c of the basis."""
        return float(self.row[:self.system.free.size] @ c[self.system.free])


def resolved_start(scene, point: SwitchedPoint, mode: np.ndarray, params: Parameters) -> tuple:
    """(the switched ``point`` solved again at its amplitude on the bases resolution.refined asks for until its
    estimate is below solver.max_error, whether the cap stopped that: ``limited``); ``mode`` φ as c on
    ``point.basis``. SurfaceBranchStartError where Newton fails on a refined basis."""
    solver = scene.solver
    while True:
        finer = policy(point.basis).refined(point.basis, point.c, point.m, solver.max_error)
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


def _stop_rule(scene, leg: _Leg, direction: float, resolving: bool):
    """stop(point) -> Stop or None (module docstring); the estimate checked while ``resolving`` (below the cap)."""
    upper, max_error = scene.continuation.stop_stretch, scene.solver.max_error

    def stop(point):
        if leg.row @ point.X * direction <= 0:
            return Stop(IntervalStop.REJOINED, "rejoined the axisymmetric states (the amplitude changed sign)")
        c = leg.system.coefficients(point.X)
        stretch = largest_hoop_stretch(leg.basis, c)
        if stretch >= upper:
            return Stop(IntervalStop.HOOP_STRETCH, f"largest hoop stretch {stretch:.4g} passed stop_stretch "
                                                   f"{upper:g}")
        error = policy(leg.basis).error_estimate(leg.basis, c) if resolving else 0.0
        if error > max_error:
            return Stop(StopCode.RESOLUTION, f"error estimate {error:.2g} above solver.max_error {max_error:g} at "
                                             f"degree {leg.basis.disc.degree}, orders up to {leg.basis.orders[-1]}")
        return signalled()

    return stop


def traced_branch(scene, disc, crossing, params: Parameters, direction: float = 1.0, max_points: int | None = None,
                  orders: tuple | None = None, n_phi: int = 0, parent: tuple | None = None) -> TubeSurfaceBranch:
    """The branch born at ``crossing`` (tube/azimuthal_crossings.AzimuthalCrossing on ``disc``; ``params`` its
    branch's), starting on the orders (0, m, 2m) unless ``orders`` (module docstring); SurfaceBranchStartError where
    the switched point does not converge."""
    solver, m = scene.solver, crossing.m
    first = switched_point(scene, disc, crossing, direction * START_AMPLITUDE, params, orders, n_phi, solver.tol,
                           solver.max_newton)
    mode = first.basis.with_mode(np.zeros(first.basis.size), m, crossing.mode)
    return trace_from(scene, first, mode, first.basis.axisymmetric(crossing.u), crossing.pressure, params, direction,
                      max_points, parent)


def trace_from(scene, first: SwitchedPoint, mode: np.ndarray, zero: np.ndarray, pressure: float,
               params: Parameters, direction: float = 1.0, max_points: int | None = None,
               parent: tuple | None = None) -> TubeSurfaceBranch:
    """The branch through the switched point ``first`` (any MeridianSurfaceBasis), born at the axisymmetric state
    ``zero`` (c on ``first.basis``) at ``pressure`` along the critical ``mode`` (c on ``first.basis``), traced
    (module docstring); SurfaceBranchStartError where ``first`` did not converge."""
    solver, m = scene.solver, first.m
    if not first.converged:
        raise SurfaceBranchStartError(f"the switched point at ε = {first.amplitude:g} did not converge: "
                                      f"{first.message}")
    origin_basis = first.basis
    origin = _Leg(scene, origin_basis, params, first.c, m, mode)
    first, limited = resolved_start(scene, first, mode, params)
    leg = _Leg(scene, first.basis, params, first.c, m, origin_basis.raised(mode, first.basis))
    X = leg.system.point(first.c, first.pressure)
    start = continuation.Point(X, continuation.tangent(leg.system, X, direction * leg.row), first.iterations,
                               first.residual)
    max_points = max_points or scene.surface.max_points
    legs, folds, done = [leg], [], 1  # done: the points kept so far (point 0, the zero, is not the tracer's)
    while True:
        path = continuation.trace(leg.system, start, continuation_settings(scene, max(max_points - done, 1)),
                                  _stop_rule(scene, leg, direction, not limited), {"LP": np.eye(start.X.size)[-1]})
        stop = path.stop
        # a fold in the step to a point the estimate rejects is found again from the re-solved last point
        folds += [(f.index + done, float(f.point.X[-1])) for f in path.folds
                  if stop.code != StopCode.RESOLUTION or f.index < len(path.points) - 1]
        leg.points += path.points  # after the cap the run goes on from the leg's last point
        done += len(path.points)
        if stop.code != StopCode.RESOLUTION:
            break
        finer = policy(leg.basis).refined(leg.basis, leg.system.coefficients(path.overshoot.X), m, solver.max_error)
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
        caps = policy(leg.basis)
        stop = Stop(stop.code, f"{stop.message}; limited: the basis at its cap (degree ≤ {caps.MAX_DEGREE}, orders up "
                               f"to {caps.MAX_HARMONICS} m) with error estimates above solver.max_error "
                               f"{solver.max_error:g}")
    return _branch(origin, legs, (m, zero, pressure), params, tuple(folds), stop, parent, limited)


def _branch(origin: _Leg, legs: list, born: tuple, params: Parameters, folds: tuple, stop: Stop, parent: tuple | None,
            limited: bool) -> TubeSurfaceBranch:
    """The TubeSurfaceBranch of the traced ``legs``, point 0 the zero on ``origin`` (the switched point's first
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
    return TubeSurfaceBranch(
        final, m, np.array([leg.basis.raised(c, final) for leg, c, _, _ in points]),
        np.array([P for _, _, P, _ in points]),
        np.array([leg.basis.volume_ratio(leg.system.surface.volume(c)) for leg, c, _, _ in points]),
        np.array([leg.amplitude(c) for leg, c, _, _ in points]), np.array([tau for *_, tau in points]),
        np.array([policy(leg.basis).error_estimate(leg.basis, c) for leg, c, _, _ in points]),
        np.array([lowest for lowest, _ in readings]),
        {control: np.array([counts[control] for _, counts in readings], dtype=int) for control in Control},
        folds, stop, parent, limited)
