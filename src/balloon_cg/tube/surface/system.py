"""The equations of a non-axisymmetric branch in P: the gauged equilibrium of a surface over (t, φ)
(tube/surface/meridian.py).

At X = (c_f, τ, P) (c_f the free coefficients of the basis, τ the multipliers of the gauge rows, P last:
numerics/continuation.py's parameter)

    R(X) = (∇E(c; P) + Σ_i τ_i g_i,  g_i · c) = 0,

g_i = G f_i the rows of the basis' zero modes f_i held (``gauge_rows``: a tube's sideways translation on sliding ends
without a field; a capsule's translation and rotation about a horizontal axis, tube/surface/capsule.py), τ_i their
reactions (0 at an equilibrium: E is invariant under them). Plugged ends hold the rims, and a coil's field
(M ≠ 0: tube/azimuthal.in_field) makes the translation no symmetry, a tube free to move sideways in it: no gauge,
X = (c_f, P). The Jacobian is exact (the surface Hessian bordered by the g_i and ∂R/∂P).
"""
import numpy as np

from .equilibrium import MeridianSurfaceEquilibrium
from .. import azimuthal
from ...galerkin.equilibrium import Parameters


class TubeSurfaceSystem:
    """R(X) and its Jacobian (module docstring) of ``surface`` at ``params`` (P replaced by X[-1]); ``template``:
    the coefficients the held unknowns (λ̄ of ends held apart) are read from."""

    def __init__(self, surface: MeridianSurfaceEquilibrium, params: Parameters, template: np.ndarray):
        self.surface, self.params = surface, params
        self.basis = surface.basis
        self.free = self.basis.free
        self.template = np.array(template, dtype=float)
        self.gauges = self.basis.gauge_rows(azimuthal.in_field(surface, params))[:, self.free]
        self.gauged = self.gauges.shape[0]

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
        """τ_1, the first gauge row's reaction (0 without a gauge)."""
        return float(X[self.free.size]) if self.gauged else 0.0

    def residual(self, X: np.ndarray) -> np.ndarray:
        c, at = self.coefficients(X), self.params_at(X)
        R = self.surface.residual(c, at)[self.free]
        if not self.gauged:
            return R
        n = self.free.size
        return np.concatenate([R + X[n:n + self.gauged] @ self.gauges, self.gauges @ X[:n]])

    def jacobian(self, X: np.ndarray) -> np.ndarray:
        c, at = self.coefficients(X), self.params_at(X)
        n = self.free.size
        J = np.zeros((self.size, self.size + 1))
        J[:n, :n] = self.surface.hessian(c, at)[np.ix_(self.free, self.free)]
        J[:n, -1] = self.surface.parameter_derivative(c, at)[self.free]
        J[:n, n:n + self.gauged] = self.gauges.T
        J[n:, :n] = self.gauges
        return J
