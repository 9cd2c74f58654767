"""The equations of a tube's non-axisymmetric branch in P: the gauged equilibrium of the tube over (S, φ).

At X = (c_f, τ, P) (c_f the free coefficients of the basis, τ the multiplier of the gauge, P last: numerics/
continuation.py's parameter)

    R(X) = (∇E(c; P) + τ G t,  tᵀ G c_1) = 0,

t the sideways translation (R = 1, T = −1, Z = 0 in order 1: tube/azimuthal.translation), a zero mode of E on
sliding ends without a field, gauged by its held centroid tᵀ G c_1 = 0, τ the reaction (0 at an equilibrium: E is
invariant under t). Plugged ends hold the rims, and a coil's field (M ≠ 0: tube/azimuthal.in_field) makes the
translation no symmetry, the tube free to move sideways in it (tube/azimuthal.py's free reading): no gauge,
X = (c_f, P). The Jacobian is exact (the surface Hessian bordered by G t and ∂R/∂P).
"""
import numpy as np

from .basis import TubeSurfaceBasis
from .equilibrium import MeridianSurfaceEquilibrium
from .. import azimuthal
from ...galerkin.equilibrium import Parameters
from ...scene.tables import Ends


def gauge_row(basis: TubeSurfaceBasis, field: bool = False) -> np.ndarray:
    """G t in c (order 1 on sliding ends), zero where nothing is gauged (plugged ends, no order 1, or in a coil's
    ``field``)."""
    row = np.zeros(basis.size)
    if 1 in basis.orders and basis.disc.ends == Ends.SLIDING and not field:
        row[basis.block(1)] = azimuthal.operators(basis.disc)[1] @ azimuthal.translation(basis.disc)
    return row


class TubeSurfaceSystem:
    """R(X) and its Jacobian (module docstring) of ``surface`` at ``params`` (P replaced by X[-1]); ``template``:
    the coefficients the held unknowns (λ̄ of ends held apart) are read from."""

    def __init__(self, surface: MeridianSurfaceEquilibrium, params: Parameters, template: np.ndarray):
        self.surface, self.params = surface, params
        self.basis = surface.basis
        self.free = self.basis.free
        self.template = np.array(template, dtype=float)
        self.gauge = gauge_row(self.basis, azimuthal.in_field(surface, params))[self.free]
        self.gauged = bool(self.gauge.any())

    @property
    def size(self) -> int:
        """The number of equations (X has one more entry)."""
        return self.free.size + self.gauged

    def point(self, c: np.ndarray, P: float) -> np.ndarray:
        """X of the coefficients c at the pressure P (τ = 0)."""
        return np.concatenate([c[self.free], [0.0] * self.gauged, [P]])

    def coefficients(self, X: np.ndarray) -> np.ndarray:
        c = self.template.copy()
        c[self.free] = X[:self.free.size]
        return c

    def raised(self, X: np.ndarray, to: "TubeSurfaceSystem", direction: bool = False) -> np.ndarray:
        """X on the finer basis of ``to`` (TubeSurfaceBasis.raised: the coefficients zero-padded, τ and P as they
        are), or with ``direction`` a vector of X's space (a tangent: the held unknowns 0)."""
        c = np.zeros(self.basis.size) if direction else self.template.copy()
        c[self.free] = X[:self.free.size]
        out = to.point(self.basis.raised(c, to.basis), X[-1])
        out[to.free.size:] = X[self.free.size:]
        return out

    def params_at(self, X: np.ndarray) -> Parameters:
        return self.params.with_value("P", X[-1])

    def reaction(self, X: np.ndarray) -> float:
        """τ, the gauge's reaction (0 without a gauge)."""
        return float(X[self.free.size]) if self.gauged else 0.0

    def residual(self, X: np.ndarray) -> np.ndarray:
        c, at = self.coefficients(X), self.params_at(X)
        R = self.surface.residual(c, at)[self.free]
        if not self.gauged:
            return R
        return np.append(R + X[self.free.size] * self.gauge, self.gauge @ X[:self.free.size])

    def jacobian(self, X: np.ndarray) -> np.ndarray:
        c, at = self.coefficients(X), self.params_at(X)
        n = self.free.size
        J = np.zeros((self.size, self.size + 1))
        J[:n, :n] = self.surface.hessian(c, at)[np.ix_(self.free, self.free)]
        J[:n, -1] = self.surface.parameter_derivative(c, at)[self.free]
        if self.gauged:
            J[:n, n] = self.gauge
            J[n, :n] = self.gauge
        return J
