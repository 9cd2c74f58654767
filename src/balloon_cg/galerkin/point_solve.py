"""One equilibrium at a prescribed north pole stretch λ*, the pressure being an unknown.

Unknowns X = (u, P), u the Ritz coefficients on a Discretisation of the given degree. Equations (n + 1):

    R(u; P) = ∂E/∂u (u; P) = 0      (n equations: equilibrium.Equilibrium.residual at the other parameters)
    λ2(0) = r_n·u = λ*              (the pole row r_n = Discretisation.pole_rows()["lam2_top"])

solved by numerics.newton with the Jacobian [∂R/∂u  ∂R/∂P] (n × (n + 1)) bordered by (r_n, 0). The start X0 may
live on another discretisation ``source`` (same symmetry and translation hold): its Legendre coefficients
a_k, b_k are copied for k ≤ min(N, N_source) and the rest set to zero (exact when the degree is raised on an
unmapped basis; otherwise only a start), P is copied. Used to solve a branch point again at a higher degree
(a refinement check) and to reach points that continuation starts from.
"""
import numpy as np

from .discretisation import Discretisation
from .equilibrium import Equilibrium
from ..numerics.newton import newton


def constrained_newton(scene, degree, X0, source, stretch, params, tol=1e-12, max_iter=25):
    """Solve R(u; P) = 0 with λ2(0) = ``stretch`` on ``degree`` from X0 = (u0, P0) given on ``source``
    (coefficients padded or truncated), the other parameters from ``params``.

    Returns (numerics.newton.NewtonResult with x = (u, P), the Equilibrium of the new discretisation).
    """
    eq = Equilibrium(scene, Discretisation(degree, source.symmetric, source.pin_translation, joins=source.joins,
                                           held=source.held))
    a, b = source.split(X0[:-1])
    n = min(degree, source.degree) + 1
    a2, b2 = np.zeros(degree + 1), np.zeros(degree + 1)
    a2[:n], b2[:n] = a[:n], b[:n]
    X = np.append(eq.disc.join(a2, b2), X0[-1])

    def residual(X):
        return eq.residual(X[:-1], params.with_value("P", X[-1]))

    def jacobian(X):
        return eq.bordered_jacobian(X[:-1], params.with_value("P", X[-1]), "P")

    row = np.append(eq.disc.pole_rows()["lam2_top"], 0.0)
    return newton(residual, jacobian, X, row, stretch, tol, max_iter), eq
