"""The non-axisymmetric branch born at a located m ≥ 1 zero of a tube, traced in P (docs/tubes.md "The tube over
(S, φ)"; ``[surface] branches``): its switched point (switching.py) on the orders (0, m, 2m) and the parent's degree,
traced by analysis/surface/meridian/trace.py with the tube's error estimate and refinement (resolution.py).
"""
import numpy as np

from . import resolution
from .switching import switched_point
from ...analysis.surface.meridian.trace import START_AMPLITUDE, MeridianSurfaceBranch, trace_from
from ...galerkin.equilibrium import Parameters


def traced_branch(scene, disc, crossing, params: Parameters, direction: float = 1.0, max_points: int | None = None,
                  orders: tuple | None = None, n_phi: int = 0, parent: tuple | None = None) -> MeridianSurfaceBranch:
    """The branch born at ``crossing`` (tube/azimuthal_crossings.AzimuthalCrossing on ``disc``; ``params`` its
    branch's), starting on the orders (0, m, 2m) unless ``orders`` (module docstring); SurfaceBranchStartError where
    the switched point does not converge."""
    solver, m = scene.solver, crossing.m
    first = switched_point(scene, disc, crossing, direction * START_AMPLITUDE, params, orders, n_phi, solver.tol,
                           solver.max_newton)
    mode = first.basis.with_mode(np.zeros(first.basis.size), m, crossing.mode)
    return trace_from(scene, first, mode, first.basis.axisymmetric(crossing.u), crossing.pressure, params, resolution,
                      direction, max_points, parent)
