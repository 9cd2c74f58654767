"""The adaptive tracer: pseudo-arclength legs on discretisations of growing degree and, near wires, mapped bases.

A leg follows a branch from a point along its tangent (``numerics.continuation.trace``), locating the folds
in P (LP), in the north pole stretch (TP) and in the loading's control parameter (LV, LN: ``control``). When a
point's spectral error estimate exceeds the resolution policy's max_error (``resolution.Resolution``), the leg stops
with RESOLUTION and the last point is recomputed on a finer basis: with coils, first the wire map re-centred
at the same degree (kept if the estimate leaves the policy's headroom, at most max_recentres times per degree);
otherwise the degree grows and the current map is kept unless the re-centred one's estimate is clearly lower
(``Resolution.clearly_lower``). Past max_degree the leg stops with RESOLUTION_LIMIT, or FLATTENING where it is on
its way to the balloon folded flat about a wire at P = 0, which no degree reaches (``flattening``).

The tracer is the same for the primary branch (``primary``) and the bifurcating ones (``switching``): they
differ in the layout (equator-symmetric or general, held or free) and the stop rule.
"""
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from ...galerkin.discretisation import Discretisation, held_surface
from ...galerkin.equilibrium import Equilibrium, Parameters
from ...numerics import continuation, interrupt
from ...numerics.continuation import Stop
from ...numerics.newton import newton
from .control import fold_monitors
from .flattening import flattening_stop
from .graded import graded_point
from ...scene import ContinuationParameter
from ...scene.tables import GRADED
from .problem import ParameterSystem, continuation_settings
from .resolution import Resolution
from ..results import Kind, StopCode
from .wires import wire_map


class ContinuationError(RuntimeError):
    """The branch could not be started or continued; the message says what to change."""


@dataclass
class LegTrace:
    """A traced leg: the (discretisation, continuation.Path) of each basis used, in order, and its stop."""

    segments: list
    stop: Stop


def unit(size: int, index: int) -> np.ndarray:
    e = np.zeros(size)
    e[index] = 1.0
    return e


def scene_parameter(scene) -> str:
    """The Parameters field a scene's branches are continued in: P, or Φ̄ for continuation.parameter = "voltage"."""
    return "voltage" if scene.continuation.parameter == ContinuationParameter.VOLTAGE else "P"


TOP_TURNING = MappingProxyType({Kind.TP: "lam2_top"})  # the pole stretch folds a leg locates by default


class Tracer:
    """Discretisations of growing degree for one scene and one layout, and the legs traced on them."""

    def __init__(self, scene, symmetric: bool | None = None, held: bool | None = None, parameter: str | None = None):
        """``symmetric``: the equator-symmetric layout (default: when the field allows it); ``held``: constrain the
        axial translation b_0 = 0 (default: with coils that are not equator-symmetric); ``parameter``: the
        continuation parameter, a Parameters field (default: the scene's, P or Φ̄; M: a continuation in the field
        at fixed P, ``continue --parameter M``). Without a field acting (no
        coils, or M = 0: the field energy is proportional to M) the energy does not depend on b_0, an exact zero
        mode, and b_0 is always removed."""
        self.scene = scene
        if symmetric is None:
            symmetric = scene.continuation.symmetry != "none" and scene.field.is_equator_symmetric
        self.symmetric = symmetric
        if held is None:
            held = bool(scene.field.coils) and not scene.field.is_equator_symmetric
        self.pin = (not scene.field.coils) or scene.field.M == 0 or held
        # a free balloon in a field without equator symmetry: the net axial force at its start is not zero by
        # symmetry, and b_0 is a zero mode at M = 0 (``primary.start`` switches the field on held, then releases)
        self.free_off_equator = not self.pin and not scene.field.is_equator_symmetric
        # the continuation parameter (Parameters field): P, or Φ̄ for continuation.parameter = "voltage"
        self.parameter = parameter or scene_parameter(scene)
        self.settings = continuation_settings(scene)
        self.resolution = Resolution.of(scene)
        # a capsule's elements each at its own degree (geometry.element_degrees = "graded": ``graded``)
        self.graded = scene.geometry.element_degrees == GRADED
        self._systems = {}

    def system(self, degree: int, params: Parameters, mapping=None) -> ParameterSystem:
        if (degree, mapping) not in self._systems:
            quadrature = self.scene.solver.quadrature if degree == self.scene.solver.degree else 0
            disc = Discretisation(degree, self.symmetric, self.pin, quadrature, mapping,
                                  held=held_surface(self.scene.geometry, self.symmetric, self.pin))
            self._systems[degree, mapping] = Equilibrium(self.scene, disc)
        return ParameterSystem(self._systems[degree, mapping], params, self.parameter)

    def system_on(self, disc: Discretisation, params: Parameters) -> ParameterSystem:
        """The system on a discretisation of this tracer's: one of ``system``'s (by its degree and map), or a graded
        one (``graded``)."""
        if not disc.element_degrees:
            return self.system(disc.degree, params, disc.mapping)
        if disc not in self._systems:
            self._systems[disc] = Equilibrium(self.scene, disc)
        return ParameterSystem(self._systems[disc], params, self.parameter)

    def leg(self, start: continuation.Point, params: Parameters, stop, progress=None, degree=None,
            mapping=None, limits=None, turning=TOP_TURNING) -> LegTrace:
        """Trace from ``start`` (at ``degree``, default the scene's, and ``mapping``) along its tangent, refining
        as needed (module docstring). ``stop(disc, point)`` returns a Stop or None; ``limits(disc, point)`` (the
        requested range of the branch) is asked first, before the resolution check: a point past the range ends
        the leg (it is landed on exactly afterwards), however unresolved it is (past min_stretch = 1.001 a
        predictor lands in compression, λ < 1, which no degree resolves). ``turning``: fold label -> pole row
        (``Discretisation.pole_rows``) whose turning points are located (default: TP, the north pole stretch)."""
        policy = self.resolution
        degree = degree or self.scene.solver.degree
        system = self.system(degree, params, mapping)
        segments, recentres = [], 0
        while True:
            disc = system.eq.disc
            poles = {label: np.append(disc.pole_rows()[row], 0.0) for label, row in turning.items()}
            monitors = {Kind.LP: unit(start.X.size, -1)} | poles | fold_monitors(system, self.scene.loading.control)

            def checked_stop(point, disc=disc):
                if interrupt.requested():
                    return Stop(StopCode.INTERRUPTED, "interrupted (SIGINT or SIGTERM): stopped at this point")
                beyond = limits(disc, point) if limits is not None else None
                if beyond is not None:
                    return beyond
                if not policy.resolved(disc, point.X[:-1]):
                    return Stop(StopCode.RESOLUTION, "spectral error estimate above solver.max_error")
                return stop(disc, point)

            path = continuation.trace(system, start, self.settings, checked_stop, monitors, progress)
            segments.append((disc, path))
            if path.stop.code != StopCode.RESOLUTION:
                return LegTrace(segments, path.stop)
            last = path.points.pop()  # recomputed on the new basis as the next segment's first point
            path.folds = [f for f in path.folds if f.index < len(path.points)]  # later ones are found again
            if self.graded:
                graded = self._graded(disc, last, path.overshoot, params)
                if isinstance(graded, Stop):
                    path.points.append(last)
                    return LegTrace(segments, graded)
                system, start = graded
                continue
            recentred = wire_map(disc, last.X[:-1], self.scene.field.coils, self.symmetric)
            refined = None
            if recentred is not None and not recentred.close_to(disc.mapping) and recentres < policy.max_recentres:
                refined = self._refine(disc, last, degree, [recentred], params, policy.recentre_accept)
                recentres += not isinstance(refined, str)
            if refined is None or isinstance(refined, str):
                if degree >= policy.max_degree:
                    path.points.append(last)
                    flat = flattening_stop(disc, last, policy.max_degree) if self.parameter == "P" else None
                    return LegTrace(segments, flat or Stop(StopCode.RESOLUTION_LIMIT, (
                        f"resolution: spectral error estimate above solver.max_error = {policy.max_error:g} at "
                        f"solver.max_degree = {policy.max_degree}; raise max_degree or shorten the branch")))
                degree, recentres = policy.grow(degree), 0
                candidates = [disc.mapping] + ([recentred] if recentred not in (None, disc.mapping) else [])
                refined = self._refine(disc, last, degree, candidates, params, np.inf)
                if isinstance(refined, str):
                    path.points.append(last)
                    return LegTrace(segments, Stop(StopCode.REFINE_FAILED,
                                                   f"could not refine to degree {degree}: {refined}"))
            system, result, t = refined
            start = continuation.Point(result.x, continuation.tangent(system, result.x, t), result.iterations,
                                       result.residual)

    def _graded(self, disc: Discretisation, last: continuation.Point, ahead: continuation.Point, params: Parameters):
        """``last`` recomputed on the graded basis that the element groups' own tails at the unresolved point
        ``ahead`` want (``graded.graded_point``): (system, continuation start) there, or the Stop when no group can
        grow or Newton fails."""
        point = graded_point(lambda target: self.system_on(target, params), disc, last.X, last.tangent,
                             self.resolution, self.settings.tol, self.settings.max_newton, ahead.X)
        if point.result is None:
            return Stop(StopCode.RESOLUTION_LIMIT, f"resolution: {point.message}; raise max_degree or shorten the "
                                                   "branch")
        if not point.result.converged:
            return Stop(StopCode.REFINE_FAILED, f"could not refine: {point.message}")
        system = self.system_on(point.disc, params)
        return system, continuation.Point(point.X, continuation.tangent(system, point.X, point.row),
                                          point.result.iterations, point.result.residual)

    def _refine(self, disc: Discretisation, last: continuation.Point, degree: int, mappings, params: Parameters,
                accept: float):
        """``last`` recomputed at ``degree`` on each basis map of ``mappings``, the current one first: (system, Newton
        result, tangent reference) of the first with an error estimate ≤ ``accept``, or of a later one whose
        estimate is clearly lower (``Resolution.clearly_lower``); else a message."""
        best, message = None, "no candidate basis"
        for mapping in mappings:
            system = self.system(degree, params, mapping)
            X = disc.transfer(last.X, system.eq.disc)
            t = disc.transfer(last.tangent, system.eq.disc)
            result = newton(system.residual, system.jacobian, X, t, t @ X, self.settings.tol, self.settings.max_newton)
            message = result.message
            if result.converged:
                estimate = system.eq.disc.tail(result.x[:-1])
                if estimate <= accept and (best is None or self.resolution.clearly_lower(estimate, best[0])):
                    best = (estimate, system, result, t)
                message = f"error estimate {estimate:.2g} above {accept:.2g}"
        return message if best is None else best[1:]
