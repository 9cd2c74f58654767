"""The whole-sphere problem in its gauge as a continuation system: R(a; p) = Zᵀ ∇E(Z a; p) of X = (a, p), for
the balloon-free Newton solver and continuation driver (numerics/)."""
import numpy as np

from .equilibrium import SurfaceEquilibrium
from .gauge import Gauge
from ..galerkin.equilibrium import Parameters
from ..numerics.newton import NewtonResult, newton


class SurfaceSystem:
    """R(a; p) for one continuation parameter ``name`` ∈ {P, M, voltage}."""

    def __init__(self, equilibrium: SurfaceEquilibrium, gauge: Gauge, params: Parameters, name: str = "P"):
        self.eq, self.gauge, self.params, self.name = equilibrium, gauge, params, name

    def params_at(self, X) -> Parameters:
        return self.params.with_value(self.name, X[-1])

    def coefficients(self, X) -> np.ndarray:
        """c = Z a of the point X = (a, p)."""
        return self.gauge.expand(X[:-1])

    def point(self, c: np.ndarray, value: float) -> np.ndarray:
        """X = (Zᵀ c, p) of coefficients meeting the gauge's constraints."""
        return np.append(self.gauge.reduce(c), value)

    def residual(self, X):
        return self.gauge.reduce(self.eq.residual(self.coefficients(X), self.params_at(X)))

    def jacobian(self, X):
        c, params = self.coefficients(X), self.params_at(X)
        J = np.empty((self.gauge.size, self.gauge.size + 1))
        self.gauge.reduce_matrix(self.eq.hessian(c, params), out=J[:, :-1])
        J[:, -1] = self.gauge.reduce(self.eq.parameter_derivative(c, params, self.name))
        return J

    def jacobian_vector(self, X, v):
        """J(X) v = Zᵀ(∇²E(c) Z v_a + ∂∇E/∂p v_p) without assembling J (``SurfaceEquilibrium.hessian_product``)."""
        c, params = self.coefficients(X), self.params_at(X)
        return self.gauge.reduce(self.eq.hessian_product(c, params, self.gauge.expand(v[:-1]))
                                 + v[-1] * self.eq.parameter_derivative(c, params, self.name))

    def solve(self, X0, tol: float = 1e-12, max_iter: int = 25) -> NewtonResult:
        """Newton at the fixed parameter X0[-1]."""
        row = np.zeros(X0.size)
        row[-1] = 1.0
        return newton(self.residual, self.jacobian, X0, row, X0[-1], tol, max_iter)
