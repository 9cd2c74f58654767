"""One point of the non-axisymmetric branch born at a located m ≥ 1 zero of a tube, the start of its trace
(tube/surface/branch.py; docs/tubes.md "The tube over (S, φ)").

At the zero (tube/azimuthal_crossings.AzimuthalCrossing: the axisymmetric state u, the pressure P_0, the critical mode
φ of the m-th block, G-unit) the branch leaves along φ. With the orders (0, m, 2m) of the branch's dihedral symmetry
(MODEL.md §8: for m ≥ 2 also the rotation by 2π/m) the point of amplitude ε solves, for (c, P) and a multiplier τ,

    ∇E(c; P) + τ G t = 0,      tᵀ G c_1 = 0,      φᵀ G c_m = ε,

from the predictor (u + ε φ, P_0), by Newton with the exact Jacobian (numerics/newton.py, the two conditions its
bordering row; tube/surface/system.py: t the sideways translation on sliding ends, its centroid held, τ its
reaction, 0 at an equilibrium). The condition on the amplitude fixes the point on the branch:
a pitchfork (the rotation by π/m maps c_m to −c_m), P − P_0 = O(ε²).
"""
from dataclasses import dataclass

import numpy as np

from .basis import TubeSurfaceBasis
from .meridian import MeridianSurfaceBasis
from .equilibrium import MeridianSurfaceEquilibrium
from .system import TubeSurfaceSystem
from ...galerkin.equilibrium import Parameters
from ...galerkin.interval import IntervalDiscretisation
from ...numerics.newton import newton


@dataclass(frozen=True)
class SwitchedPoint:
    """The state c (``basis``'s coefficients) and ``pressure`` at ``amplitude`` ε along the m-th critical mode;
    ``reaction`` τ; Newton's ``converged``, ``iterations``, ``residual`` (max-norm) and ``message``."""

    basis: MeridianSurfaceBasis
    c: np.ndarray
    pressure: float
    amplitude: float
    m: int
    reaction: float
    converged: bool
    iterations: int
    residual: float
    message: str


def mode_row(basis: MeridianSurfaceBasis, m: int, mode: np.ndarray) -> np.ndarray:
    """G φ in c (order m; φ the order-m amplitudes ``mode`` on ``basis``, e.g. a crossing's critical mode): its
    product with c is the amplitude φᵀ G c_m, the L² product of the two order-m fields (on any basis holding φ)."""
    row = np.zeros(basis.size)
    row[basis.block(m)] = basis.gram(m) @ mode
    return row


def switched_point(scene, disc: IntervalDiscretisation, crossing, amplitude: float, params: Parameters,
                   orders: tuple | None = None, n_phi: int = 0, tol: float = 1e-12,
                   max_iter: int = 30) -> SwitchedPoint:
    """The point of amplitude ε = ``amplitude`` (≠ 0) on the branch born at ``crossing`` (its state on ``disc``, the
    branch's discretisation; ``params`` the branch's, P replaced), in the orders (0, m, 2m) unless ``orders``."""
    m = crossing.m
    if crossing.mode is None or crossing.held:
        raise ValueError("crossing: held or without its mode; switched_point starts from the free tube's critical "
                         "mode (allowed: a crossing with mode, held False)")
    if amplitude == 0:
        raise ValueError("amplitude: 0 is the axisymmetric state itself (allowed: ε ≠ 0)")
    basis = TubeSurfaceBasis(disc, orders or (0, m, 2 * m), n_phi)
    if m not in basis.orders:
        raise ValueError(f"orders: {basis.orders} lack the crossing's order (allowed: orders holding m = {m})")
    start = basis.with_mode(basis.axisymmetric(crossing.u), m, amplitude * crossing.mode)
    return point_at_amplitude(scene, basis, start, crossing.pressure, mode_row(basis, m, crossing.mode), amplitude, m,
                              params, tol, max_iter)


def point_at_amplitude(scene, basis: MeridianSurfaceBasis, start: np.ndarray, pressure: float, row: np.ndarray,
                       amplitude: float, m: int, params: Parameters, tol: float = 1e-12,
                       max_iter: int = 30) -> SwitchedPoint:
    """The equilibrium on ``basis`` with row · c = ``amplitude`` (``mode_row``: the amplitude of order m's critical
    mode) by Newton from (``start``, ``pressure``); the held unknowns (λ̄ of ends held apart) read from ``start``."""
    system = TubeSurfaceSystem(MeridianSurfaceEquilibrium(scene, basis), params, start)
    result = newton(system.residual, system.jacobian, system.point(start, pressure),
                    np.append(row[system.free], [0.0] * (1 + system.gauged)), amplitude, tol, max_iter)
    c = system.coefficients(result.x)
    return SwitchedPoint(basis, c, float(result.x[-1]), float(amplitude), m, system.reaction(result.x),
                         bool(result.converged), int(result.iterations), float(result.residual), result.message)
