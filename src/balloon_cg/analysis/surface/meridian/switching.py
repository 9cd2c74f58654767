"""One point of the non-axisymmetric branch born at a located m ≥ 1 zero of a surface over a meridian, the start of its
trace (trace.py; docs/tubes.md "The tube over (S, φ)"): a tube's (tube/surface/switching.py), a capsule's (capsule.py).

At the zero (the axisymmetric state u, the pressure P_0, the critical mode φ of the m-th block, G-unit) the branch
leaves along φ. With the orders (0, m, 2m) of the branch's dihedral symmetry
(MODEL.md §8: for m ≥ 2 also the rotation by 2π/m) the point of amplitude ε solves, for (c, P) and a multiplier τ,

    ∇E(c; P) + τ G t = 0,      tᵀ G c_1 = 0,      φᵀ G c_m = ε,

from the predictor (u + ε φ, P_0), by Newton with the exact Jacobian (numerics/newton.py, the two conditions its
bordering row; system.py: t the sideways translation on sliding ends, its centroid held, τ its
reaction, 0 at an equilibrium). The condition on the amplitude fixes the point on the branch:
a pitchfork (the rotation by π/m maps c_m to −c_m), P − P_0 = O(ε²).
"""
from dataclasses import dataclass

import numpy as np

from .basis import MeridianSurfaceBasis
from .equilibrium import MeridianSurfaceEquilibrium
from .system import MeridianSurfaceSystem
from ....galerkin.equilibrium import Parameters
from ....numerics.newton import newton


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


def point_at_amplitude(scene, basis: MeridianSurfaceBasis, start: np.ndarray, pressure: float, row: np.ndarray,
                       amplitude: float, m: int, params: Parameters, tol: float = 1e-12,
                       max_iter: int = 30) -> SwitchedPoint:
    """The equilibrium on ``basis`` with row · c = ``amplitude`` (``mode_row``: the amplitude of order m's critical
    mode) by Newton from (``start``, ``pressure``); the held unknowns (λ̄ of ends held apart) read from ``start``."""
    system = MeridianSurfaceSystem(MeridianSurfaceEquilibrium(scene, basis), params, start)
    result = newton(system.residual, system.jacobian, system.point(start, pressure),
                    np.append(row[system.free], [0.0] * (1 + system.gauged)), amplitude, tol, max_iter)
    c = system.coefficients(result.x)
    return SwitchedPoint(basis, c, float(result.x[-1]), float(amplitude), m, system.reaction(result.x),
                         bool(result.converged), int(result.iterations), float(result.residual), result.message)
