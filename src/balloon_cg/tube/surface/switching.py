"""One point of the non-axisymmetric branch born at a located m ≥ 1 zero of a tube (opt-in: not called by ``run``;
the branch is not traced, docs/tubes.md "The tube over (S, φ)").

At the zero (tube/azimuthal_crossings.AzimuthalCrossing: the axisymmetric state u, the pressure P_0, the critical mode
φ of the m-th block, G-unit) the branch leaves along φ. With the orders (0, m, 2m) of the branch's dihedral symmetry
(MODEL.md §8: for m ≥ 2 also the rotation by 2π/m) the point of amplitude ε solves, for (c, P) and a multiplier τ,

    ∇E(c; P) + τ G t = 0,      tᵀ G c_1 = 0,      φᵀ G c_m = ε,

from the predictor (u + ε φ, P_0), by Newton with the exact Jacobian (numerics/newton.py, the two conditions its
bordering rows). t is the sideways translation (R = 1, T = −1, Z = 0 in order 1, sliding ends), a zero mode of E
without a field: its gauge is the centroid held (tube/azimuthal.py's removed mode), its multiplier the reaction, zero
at an equilibrium since E is invariant under t. The condition on the amplitude fixes the point on the branch:
a pitchfork (the rotation by π/m maps c_m to −c_m), P − P_0 = O(ε²).
"""
from dataclasses import dataclass

import numpy as np

from .basis import TubeSurfaceBasis
from .equilibrium import TubeSurfaceEquilibrium
from .. import azimuthal
from ...galerkin.equilibrium import Parameters
from ...galerkin.interval import IntervalDiscretisation
from ...numerics.newton import newton
from ...scene.tables import Ends


@dataclass(frozen=True)
class SwitchedPoint:
    """The state c (``basis``'s coefficients) and ``pressure`` at ``amplitude`` ε along the m-th critical mode;
    ``reaction`` τ; Newton's ``converged``, ``iterations``, ``residual`` (max-norm) and ``message``."""

    basis: TubeSurfaceBasis
    c: np.ndarray
    pressure: float
    amplitude: float
    m: int
    reaction: float
    converged: bool
    iterations: int
    residual: float
    message: str


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
    surface = TubeSurfaceEquilibrium(scene, basis)
    gram = azimuthal.operators(disc)[1]
    free = basis.free
    mode_row = np.zeros(basis.size)
    mode_row[basis.block(m)] = gram @ crossing.mode
    gauge = np.zeros(basis.size)
    if 1 in basis.orders and disc.ends == Ends.SLIDING:
        gauge[basis.block(1)] = gram @ azimuthal.translation(disc)
    n, gauged = free.size, bool(gauge.any())
    width = n + 1 + gauged

    def state(X):
        c = basis.axisymmetric(crossing.u)
        c[free] = X[:n]
        return c, params.with_value("P", X[n])

    def residual(X):
        c, at = state(X)
        R = surface.residual(c, at)[free]
        return R + X[n + 1] * gauge[free] if gauged else R

    def jacobian(X):
        c, at = state(X)
        J = np.empty((n, width))
        J[:, :n] = surface.hessian(c, at)[np.ix_(free, free)]
        J[:, n] = surface.parameter_derivative(c, at)[free]
        if gauged:
            J[:, n + 1] = gauge[free]
        return J

    bordering = np.zeros((1 + gauged, width))
    bordering[0, :n] = mode_row[free]
    if gauged:
        bordering[1, :n] = gauge[free]
    start = basis.with_mode(basis.axisymmetric(crossing.u), m, amplitude * crossing.mode)
    X0 = np.concatenate([start[free], [crossing.pressure], [0.0] * gauged])
    targets = np.array([amplitude] + [0.0] * gauged)
    result = newton(residual, jacobian, X0, bordering, targets, tol, max_iter)
    c, at = state(result.x)
    return SwitchedPoint(basis, c, float(at.P), float(amplitude), m, float(result.x[n + 1]) if gauged else 0.0,
                         bool(result.converged), int(result.iterations), float(result.residual), result.message)
