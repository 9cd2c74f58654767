"""Branch points of the equator-symmetric branch as regular solutions of extended systems.

Both systems live on a plain (unmapped) equator-symmetric discretisation of degree N, and the perturbation
basis of the second variation (``stability.SecondVariation``, Legendre in x) has the same degree N, so that
its even block *is* the Jacobian J_u of the symmetric layout and its odd block that of the pear directions
of the general layout: a singular block is a branch point of the discrete problem itself.

The parameter p is the branch's continuation parameter: the pressure P, or the voltage Φ̄ of a voltage
continuation at fixed P (``parameter`` = "voltage"; R_p = ∂R/∂Φ̄ is the generated ``voltage_gradient``).

Pear (odd_held block; a symmetry-breaking pitchfork), Werner–Spence:

    unknowns  (u, p, φ)           u: symmetric-layout coefficients, φ: the odd block (a_odd, b_even without
                                   b_0) of the perturbation basis
    equations R(u; p)       = 0   (n)    equilibrium
              H_odd(u; p) φ = 0   (m)    the pear block is singular, φ its null vector
              ℓ·φ − 1       = 0   (1)    normalisation

J_u is regular at a symmetry-breaking pitchfork (the singular direction is not in the symmetric space), and
the system is regular there when the pear eigenvalue crosses zero transversally along the branch. The same
system with the odd_free block (the pear block and the axial translation b_0: a free balloon in a field) locates
the free balloon's pitchfork: b_0 is odd under z → −z, and the symmetric state's net axial force vanishes.

Even block (a branch point inside the symmetric space), Moore's system for a simple bifurcation point of
F(x) = R(u; p), x = (u, p) (n equations, n + 1 unknowns), F_x = [J_u, R_p]:

    unknowns  (x, ψ, β)
    equations F(x) + β ψ   = 0    (n)
              F_x(x)ᵀ ψ    = 0    (n + 1)   i.e. J_u ψ = 0 (J_u is symmetric) and R_p·ψ = 0
              ℓ·ψ − 1      = 0    (1)

regular at a simple (transcritical or pitchfork) bifurcation point, where β = 0 (a solution with β ≠ 0 is a
point of the perturbed problem F + βψ, not a branch point: ``MooreSystem.beta`` is checked to vanish).
Jacobian rows of F_xᵀψ: ∂(J_u ψ)/∂u = D_u J_u[ψ] (the third derivative of E is symmetric), a central
difference of the generated Hessian along ψ; ∂(J_u ψ)/∂p = ∂(R_p·ψ)/∂u = D_u R_p[ψ] (R_p = ∂²E/∂u∂p is a
gradient: its Jacobian is symmetric), a central difference of R_p along ψ (exact for P: R_P is quadratic in u);
∂(R_p·ψ)/∂p, a central difference of R_p in p (exact: R is linear in P and quadratic in Φ̄, so R_p is at most
linear in p; zero for P).
Difference steps are ``H_STEP`` (relative): the Jacobian is accurate to ~1e-9, which affects only Newton's
rate, not the converged point (the residuals are exact).
"""
import numpy as np

from ...galerkin.equilibrium import Equilibrium
from ..stability.axisymmetric import SecondVariation, block_indices, held_transform

H_STEP = 1e-6


def _step(c, direction) -> float:
    """Central-difference step along ``direction`` at the coefficients c (relative, ``H_STEP``)."""
    return H_STEP * max(1.0, np.abs(c).max()) / max(np.abs(direction).max(), 1e-300)


def _parameter_step(p: float) -> float:
    return H_STEP * max(1.0, abs(p))


class WernerSpence:
    """R(u; p) = 0, H_odd(u; p) φ = 0, ℓ·φ = 1 as a map of X = (u, p, φ) (module docstring): square, n + m + 1;
    p the Parameters field ``parameter`` ("P" or "voltage"), H_odd the block ``block`` (odd_held or odd_free)."""

    def __init__(self, equilibrium: Equilibrium, params, ell: np.ndarray, parameter: str = "P",
                 block: str = "odd_held"):
        disc = equilibrium.disc
        if not disc.symmetric or disc.mapping is not None:
            raise ValueError("the pear system needs a plain equator-symmetric discretisation")
        self.eq, self.params, self.continuation_parameter = equilibrium, params, parameter
        self.variation = SecondVariation(equilibrium, disc.degree)
        self.odd = block_indices(self.variation, block, field_on=True)
        self.basis = self.variation.basis
        self.hold = held_transform(self.basis, equilibrium.scene.geometry)  # the blocks' held η functions
        self.embed = symmetric_embedding(disc)
        self.n, self.m = disc.size, self.odd.size
        self.ell = np.asarray(ell, dtype=float)

    def split(self, X):
        n, m = self.n, self.m
        return X[:n], float(X[n]), X[n + 1:n + 1 + m]

    def _hessian(self, c, params):
        """Generated Hessian on the Legendre basis in x at the (general) coefficient vector c."""
        b = self.basis
        nodes = self.eq.at_nodes(("branch_point", b), (b.cos_theta, b.sin_theta))
        b.node_state(c, nodes.state)
        nodes.hold(params)
        return b.hessian(nodes("energy_hessian", params))

    def full_hessian(self, c, params):
        """``_hessian`` on the stability blocks' η functions, Tᵀ H T (``stability.held_transform``: the held
        centroid of a spheroid's reference area; T = I on the sphere)."""
        H = self._hessian(c, params)
        return H if self.hold is None else self.hold.T @ H @ self.hold

    def odd_hessian(self, u, params):
        return self.full_hessian(self.embed @ u, params)[np.ix_(self.odd, self.odd)]

    def equations(self, u, phi, params):
        """(R, H_odd φ, ℓ·φ − 1) at parameters ``params`` (p among them)."""
        return np.concatenate([self.eq.residual(u, params), self.odd_hessian(u, params) @ phi,
                               [self.ell @ phi - 1.0]])

    def derivatives(self, u, p, phi, params):
        """∂(equations)/∂(u, p, φ), (n + m + 1) square (module docstring)."""
        n, m = self.n, self.m
        J = np.zeros((n + m + 1, n + m + 1))
        J[:n, :n] = self.eq.jacobian(u, params)
        J[:n, n] = self.eq.parameter_derivative(u, params, self.continuation_parameter)
        c = self.embed @ u
        J[n:n + m, n + 1:] = self.full_hessian(c, params)[np.ix_(self.odd, self.odd)]
        # ∂(H_odd φ)/∂u = Tᵀ D_c H[T φ_full] restricted (symmetry of the third derivative)
        phi_full = np.zeros(c.size)
        phi_full[self.odd] = phi
        if self.hold is not None:
            phi_full = self.hold @ phi_full
        h = _step(c, phi_full)
        dH = (self._hessian(c + h * phi_full, params) - self._hessian(c - h * phi_full, params)) / (2 * h)
        J[n:n + m, :n] = (dH if self.hold is None else self.hold.T @ dH)[self.odd] @ self.embed
        hp, name = _parameter_step(p), self.continuation_parameter
        J[n:n + m, n] = (self.odd_hessian(u, params.with_value(name, p + hp))
                         - self.odd_hessian(u, params.with_value(name, p - hp))) @ phi / (2 * hp)
        J[-1, n + 1:] = self.ell
        return J

    def residual(self, X):
        u, p, phi = self.split(X)
        return self.equations(u, phi, self.params.with_value(self.continuation_parameter, p))

    def jacobian(self, X):
        u, p, phi = self.split(X)
        return self.derivatives(u, p, phi, self.params.with_value(self.continuation_parameter, p))

    def mode(self, X) -> np.ndarray:
        """φ on the full perturbation basis (a_0..a_N, b_0..b_N)."""
        full = np.zeros(self.embed.shape[0])
        full[self.odd] = self.split(X)[2]
        return full


class MooreSystem:
    """F(x) + βψ = 0, F_x(x)ᵀψ = 0, ℓ·ψ = 1 as a map of X = (u, p, ψ, β) (module docstring): square, 2n + 2;
    p the Parameters field ``parameter`` ("P" or "voltage")."""

    def __init__(self, equilibrium: Equilibrium, params, ell: np.ndarray, parameter: str = "P"):
        disc = equilibrium.disc
        if not disc.symmetric or disc.mapping is not None:
            raise ValueError("Moore's system here needs a plain equator-symmetric discretisation")
        self.eq, self.params, self.n, self.continuation_parameter = equilibrium, params, disc.size, parameter
        self.embed = symmetric_embedding(disc)
        self.ell = np.asarray(ell, dtype=float)

    def split(self, X):
        n = self.n
        return X[:n], float(X[n]), X[n + 1:2 * n + 1], float(X[-1])

    def _gradient(self, u, params):
        """R_p = ∂R/∂p at (u, params)."""
        return self.eq.parameter_derivative(u, params, self.continuation_parameter)

    def residual(self, X):
        u, p, psi, beta = self.split(X)
        params = self.params.with_value(self.continuation_parameter, p)
        R, J, R_p = self.eq.residual(u, params), self.eq.jacobian(u, params), self._gradient(u, params)
        return np.concatenate([R + beta * psi, J @ psi, [R_p @ psi, self.ell @ psi - 1.0]])

    def jacobian(self, X):
        u, p, psi, beta = self.split(X)
        n = self.n
        params = self.params.with_value(self.continuation_parameter, p)
        J, R_p = self.eq.jacobian(u, params), self._gradient(u, params)
        h = _step(u, psi)
        dJ = (self.eq.jacobian(u + h * psi, params) - self.eq.jacobian(u - h * psi, params)) / (2 * h)
        dR_p = (self._gradient(u + h * psi, params) - self._gradient(u - h * psi, params)) / (2 * h)
        hp = _parameter_step(p)
        dR_pp = (self._gradient(u, params.with_value(self.continuation_parameter, p + hp))
                 - self._gradient(u, params.with_value(self.continuation_parameter, p - hp))) / (2 * hp)
        out = np.zeros((2 * n + 2, 2 * n + 2))
        out[:n, :n], out[:n, n], out[:n, n + 1:2 * n + 1], out[:n, -1] = J, R_p, beta * np.eye(n), psi
        out[n:2 * n, :n], out[n:2 * n, n], out[n:2 * n, n + 1:2 * n + 1] = dJ, dR_p, J
        out[2 * n, :n], out[2 * n, n], out[2 * n, n + 1:2 * n + 1] = dR_p, dR_pp @ psi, R_p
        out[-1, n + 1:2 * n + 1] = self.ell
        return out

    def mode(self, X) -> np.ndarray:
        """ψ on the full perturbation basis (a_0..a_N, b_0..b_N)."""
        return self.embed @ self.split(X)[2]

    def beta(self, X) -> float:
        """β: zero at a genuine branch point of F."""
        return self.split(X)[3]


def symmetric_embedding(disc) -> np.ndarray:
    """The matrix taking symmetric-layout coefficients u to the full (a_0..a_N, b_0..b_N) of degree N."""
    N = disc.degree
    embed = np.zeros((2 * (N + 1), disc.size))
    embed[disc.a_index, np.arange(disc.a_index.size)] = 1.0
    embed[N + 1 + disc.b_index, disc.a_index.size + np.arange(disc.b_index.size)] = 1.0
    return embed
