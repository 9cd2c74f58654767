"""The discrete problem of a branch as a continuation system, and the solver objects rebuilt from a result."""
from ...galerkin.equilibrium import Equilibrium, Parameters
from ...numerics import continuation


class ParameterSystem:
    """R(u; p) as a map of X = (u, p) for one continuation parameter p ∈ {P, M, voltage}."""

    def __init__(self, equilibrium: Equilibrium, params: Parameters, name: str):
        self.eq, self.params, self.name = equilibrium, params, name
        self._point = params.with_value(name, getattr(params, name))  # ``_at``'s, refilled in place

    def params_at(self, X) -> Parameters:
        """The parameters of the point X = (u, p)."""
        return self.params.with_value(self.name, X[-1])

    def _at(self, X) -> Parameters:
        """params_at(X) in an object of this system's, refilled in place, for the equilibrium's calls (they do not
        keep it): a copy per call costs ~2 µs, a tenth of a Newton iteration at low degree."""
        setattr(self._point, self.name, float(X[-1]))
        return self._point

    def residual(self, X):
        return self.eq.residual(X[:-1], self._at(X))

    def jacobian(self, X):
        return self.eq.bordered_jacobian(X[:-1], self._at(X), self.name)

    def sparse_jacobian(self, X):
        """``jacobian`` as a scipy.sparse matrix (Equilibrium.sparse_jacobian)."""
        return self.eq.sparse_jacobian(X[:-1], self._at(X), self.name)


def continuation_settings(scene, max_points: int | None = None) -> continuation.Settings:
    """The continuation settings of a scene's [continuation] and [solver] tables (``max_points`` overridden)."""
    c, s = scene.continuation, scene.solver
    return continuation.Settings(c.step, c.step_min, c.step_max, c.max_points if max_points is None else max_points,
                                 s.tol, s.max_newton)


def equilibrium_of(branch) -> Equilibrium:
    """The Ritz–Galerkin problem a branch was stored on (its scene on its discretisation)."""
    return Equilibrium(branch.scene, branch.disc)


def branch_system(branch) -> ParameterSystem:
    """R(u; p) of a branch as a map of X = (u, p), p its continuation parameter (P or Φ̄)."""
    return ParameterSystem(equilibrium_of(branch), branch.params, branch.parameter)
