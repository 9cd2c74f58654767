"""The non-axisymmetric branch born at a located m ≥ 1 zero of a tube, traced in P (docs/tubes.md "The tube over
(S, φ)"; ``[surface] branches``): its switched point (switching.py) on the orders (0, m, 2m) and the parent's degree,
traced by analysis/surface/meridian/trace.py with the tube's error estimate and refinement (resolution.py). A zero
whose axisymmetric state is less resolved than the switch's step is refused before its trace (``unresolved``): on
the finer degree the estimate asks for, the zero itself would move by more than the step (docs/tubes.md: the m = 2
zero in a coil's field).
"""
import numpy as np

from . import resolution
from .switching import switched_point
from ...analysis.surface.meridian.switching import SwitchedPoint
from ...analysis.surface.meridian.trace import (START_AMPLITUDE, MeridianSurfaceBranch, SurfaceBranchStartError,
                                                trace_from)
from ...galerkin.equilibrium import Parameters


def traced_branch(scene, disc, crossing, params: Parameters, direction: float = 1.0, max_points: int | None = None,
                  orders: tuple | None = None, n_phi: int = 0, parent: tuple | None = None) -> MeridianSurfaceBranch:
    """The branch born at ``crossing`` (tube/azimuthal_crossings.AzimuthalCrossing on ``disc``; ``params`` its
    branch's), starting on the orders (0, m, 2m) unless ``orders`` (module docstring); SurfaceBranchStartError where
    the switched point does not converge or its zero is not resolved (``unresolved``)."""
    solver, m = scene.solver, crossing.m
    first = switched_point(scene, disc, crossing, direction * START_AMPLITUDE, params, orders, n_phi, solver.tol,
                           solver.max_newton)
    zero = first.basis.axisymmetric(crossing.u)
    if first.converged:  # else trace_from says so
        unresolved(first, zero, solver.max_error)
    mode = first.basis.with_mode(np.zeros(first.basis.size), m, crossing.mode)
    return trace_from(scene, first, mode, zero, crossing.pressure, params, resolution, direction, max_points, parent)


def unresolved(first: SwitchedPoint, zero: np.ndarray, max_error: float) -> None:
    """SurfaceBranchStartError where the zero's axisymmetric state ``zero`` (c on ``first.basis``) has a degree tail
    (tube/surface/resolution.py) above both ``max_error`` and the switch's step, the largest order-m coefficient of
    the switched point ``first`` over the mean radius: on the finer degree its estimate asks for, the zero itself moves
    by more than the step, and the point re-solved there at the same ε is no point of the branch near the start."""
    parent = resolution.tails(first.basis, zero)[0]
    step = resolution.spectra(first.basis, first.c)[1][first.basis.orders.index(first.m)]
    if parent > max(max_error, step):
        raise SurfaceBranchStartError(
            f"the zero's axisymmetric state is not resolved: its degree tail {parent:.2g} at degree "
            f"{first.basis.disc.degree} exceeds solver.max_error {max_error:g} and the switch's step {step:.2g} "
            f"(ε = {first.amplitude:g}): locate the zero at a higher solver.degree")
