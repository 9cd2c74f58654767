"""The non-axisymmetric branch born at a located m ≥ 1 zero of a tube, traced in P (docs/tubes.md "The tube over
(S, φ)"; behind ``[surface] branches``, default "none" on a tube).

Point 0 is the zero itself (c = u, P_0: amplitude 0); point 1 the switched point at ε = START_AMPLITUDE along the
critical mode φ (switching.switched_point); from there pseudo-arclength continuation (numerics/continuation.py) of
tube/surface/system.py's R(X) = 0, X = (c, τ, P), the tangent oriented along +φ, folds in P located (LP). It stops
where the amplitude a = φᵀ G c_m changes sign (REJOINED: back through the axisymmetric states), the largest hoop
stretch |a_φ| over the nodes passes continuation.stop_stretch (HOOP_STRETCH), a signal (INTERRUPTED), the
corrector fails at step_min or after ``max_points`` ([surface] max_points). ``direction`` −1 traces the other half
of the pitchfork (for odd m the image of the first under the rotation by π: P the same at opposite amplitudes).

Every point carries its error estimate (``error_estimate``: the order-0 Legendre tail, IntervalDiscretisation.tail,
or the largest coefficient of the highest order relative to the mean radius, whichever is larger: on the branch
the next order is smaller by about the amplitude) and its stability in the mirror sector (``stability``).
"""
from dataclasses import dataclass

import numpy as np

from .basis import TubeSurfaceBasis
from .equilibrium import TubeSurfaceEquilibrium
from .stability import SectorStability
from .switching import mode_row, switched_point
from .system import TubeSurfaceSystem
from ..results import IntervalStop, signalled
from ...analysis.branches.problem import continuation_settings
from ...galerkin.equilibrium import Parameters
from ...numerics import continuation
from ...numerics.continuation import Stop, TraceStop
from ...scene.loading import Control

START_AMPLITUDE = 0.05  # ε of the switched point the trace starts from (G-unit mode: ~5 % of the tube's radius)


class SurfaceBranchStartError(ArithmeticError):
    """The switched point (the trace's first step off the axisymmetric branch) did not converge."""


@dataclass(frozen=True)
class TubeSurfaceBranch:
    """Per point the ``coefficients`` c on ``basis``, ``pressure``, ``volume`` (V/V0), ``amplitude`` φᵀ G c_m,
    ``reaction`` τ, ``error_estimate`` (module docstring), the ``lowest`` COUNT eigenvalues of the mirror sector's
    pencil under pressure control and the ``unstable`` counts under each control (tube/surface/stability.py);
    ``folds``: (index, pressure) of each located LP (between points index and index + 1); ``m``; ``parent``:
    (branch name, label) of the zero it was born at; ``stop``."""

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


def error_estimate(basis: TubeSurfaceBasis, c: np.ndarray) -> float:
    """The order-0 Legendre tail or the highest order's largest coefficient over the mean radius (module
    docstring)."""
    u = c[basis.block(0)]
    top = np.max(np.abs(c[basis.block(basis.orders[-1])])) if len(basis.orders) > 1 else 0.0
    return max(basis.disc.tail(u), top / abs(basis.disc.series(u)[0][0]))


def largest_hoop_stretch(basis: TubeSurfaceBasis, c: np.ndarray) -> float:
    """max |a_φ| over the nodes (R = 1: the stretch of the φ-lines)."""
    return float(np.max(np.linalg.norm(basis.node_state(c)[6:9], axis=0)))


def traced_branch(scene, disc, crossing, params: Parameters, direction: float = 1.0, max_points: int | None = None,
                  orders: tuple | None = None, n_phi: int = 0, parent: tuple | None = None) -> TubeSurfaceBranch:
    """The branch born at ``crossing`` (tube/azimuthal_crossings.AzimuthalCrossing on ``disc``; ``params`` its
    branch's), on the orders (0, m, 2m) unless ``orders`` (module docstring); SurfaceBranchStartError where the
    switched point does not converge."""
    solver = scene.solver
    first = switched_point(scene, disc, crossing, direction * START_AMPLITUDE, params, orders, n_phi, solver.tol,
                           solver.max_newton)
    if not first.converged:
        raise SurfaceBranchStartError(f"the switched point at ε = {first.amplitude:g} did not converge: "
                                      f"{first.message}")
    basis = first.basis
    surface = TubeSurfaceEquilibrium(scene, basis)
    system = TubeSurfaceSystem(surface, params, first.c)
    row = np.append(mode_row(basis, crossing)[system.free], [0.0] * (1 + system.gauged))
    X = system.point(first.c, first.pressure)
    start = continuation.Point(X, continuation.tangent(system, X, direction * row), first.iterations,
                               first.residual)
    upper = scene.continuation.stop_stretch

    def stop(point):
        if row @ point.X * direction <= 0:
            return Stop(IntervalStop.REJOINED, "rejoined the axisymmetric states (the amplitude changed sign)")
        stretch = largest_hoop_stretch(basis, system.coefficients(point.X))
        if stretch >= upper:
            return Stop(IntervalStop.HOOP_STRETCH, f"largest hoop stretch {stretch:.4g} passed stop_stretch "
                                                   f"{upper:g}")
        return signalled()

    max_points = max_points or scene.surface.max_points
    path = continuation.trace(system, start, continuation_settings(scene, max_points - 1), stop,
                              {"LP": np.eye(X.size)[-1]})
    if path.stop.code == TraceStop.MAX_POINTS:  # point 0, the zero, is not the tracer's
        path.stop = Stop(TraceStop.MAX_POINTS, f"maximum number of points ({max_points}) reached")
    origin = basis.axisymmetric(crossing.u)
    states = [origin] + [system.coefficients(p.X) for p in path.points]
    pressure = np.array([crossing.pressure] + [p.X[-1] for p in path.points])
    read = SectorStability(system)
    readings = [read(c, params.with_value("P", P)) for c, P in zip(states, pressure)]
    return TubeSurfaceBranch(
        basis, crossing.m, np.array(states), pressure,
        np.array([2 * surface.volume(c) / disc.length for c in states]),
        np.array([row[:-1 - system.gauged] @ c[system.free] for c in states]),
        np.array([0.0] + [system.reaction(p.X) for p in path.points]),
        np.array([error_estimate(basis, c) for c in states]),
        np.array([lowest for lowest, _ in readings]),
        {control: np.array([counts[control] for _, counts in readings], dtype=int) for control in Control},
        tuple((f.index + 1, float(f.point.X[-1])) for f in path.folds), path.stop, parent)

