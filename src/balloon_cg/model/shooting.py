"""Shooting: equilibria from the first-order Euler–Lagrange system, independent of the Galerkin solver.

y = (λ2, v, η, w) with v = λ2' sin θ, w = η' obeys y' = f(θ, y; P, M) (generated ``rhs``, MODEL.md §4). Each
half of the meridian is integrated in the distance t from its pole (θ = t north, θ = π − t south; σ = ±1):

    dy/dt = σ f(θ(t), y),      cos θ = σ cos t,  sin θ = sin t  (no cancellation near the south pole).

Start (generated ``pole_series``): the smooth solution is λ2 = λ_p + c2 t² + O(t⁴), η = η_p + e2 t² + O(t⁴),
so either the Taylor start at t = ε

    y(ε) = (λ_p + c2 ε², 2σ c2 ε sin ε, η_p + e2 ε², 2σ e2 ε),

or t = 0 exactly with y(0) = (λ_p, 0, η_p, 0) and the pole limit dy/dt(0) = σ (0, 0, 0, 2 e2). With a field,
(c2, e2) depend on H²_z and H²_ρρ on the axis at the pole height η_p.

Newton's matrix comes from the variational equations along the same integration: for the pole data
p = (P, η_p, λ_p), Z = ∂y/∂p obeys dZ/dt = σ (∂f/∂y Z + ∂f/∂P e_P) (generated ``rhs_jacobian`` and
``rhs_pressure``), starting from the p-derivative of y(ε), or from Z(0) = ∂(λ_p, 0, η_p, 0)/∂p with
dZ/dt(0) = σ (0, 0, 0, 2 ∂e2/∂p). ∂(c2, e2)/∂p is a central difference of ``pole_series`` (step 1e-6
relative); it only enters Newton's matrix (through the O(ε) start terms), never the residual, so it changes
the convergence rate, not the solution.

Problems (the north pole stretch λ0 is the branch parameter, as in the paper):
- ``shoot_symmetric``: equator-symmetric equilibria (λ2 even, η odd about θ = π/2; needs H² even in z).
  Unknowns (P, η0), conditions v(π/2) = 0, η(π/2) = 0. At M = 0 the last one fixes the translation.
- ``shoot_general``: both poles shot to the equator, the four components of y_N(π/2) − y_S(π/2) matched;
  unknowns (P, η0, λ2(π), η(π)). At M = 0 η0 is pinned (translation invariance) and the w-matching dropped: the
  axial first integral Π_w = Φ_w sin θ + ½ P λ2² sin² θ = 0 holds on each half (d/dθ Π_w = Π_η = 0, Π_w = 0 at
  the poles) and fixes w from (λ2, v) wherever Π_ww > 0 (a taut membrane), so w matches once λ2, v and η do.
"""
import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from .field import coaxial_table, field_squared
from .kernels import KernelSet
from ..generated import FIELD_ROWS

NORTH, SOUTH = 1.0, -1.0
EQUATOR = 0.5 * np.pi
_DIFF_STEP = 1e-6


@dataclass
class ShootingResult:
    """A shooting solve at prescribed north pole stretch.

    ``residual``: max-norm of the equator conditions at the returned unknowns; ``iterations``: Newton steps;
    ``lam2_bottom``/``eta_bottom`` are the bottom (south) pole values (by symmetry for ``shoot_symmetric``).
    """

    P: float
    eta_top: float
    lam2_equator: float
    residual: float
    converged: bool
    message: str
    iterations: int = 0
    lam2_bottom: float = np.nan
    eta_bottom: float = np.nan
    wall_time: float = 0.0


@dataclass
class Half:
    """One integrated half: y and Z = ∂y/∂(P, η_p, λ_p) at the equator (Z is 4 × 3)."""

    y: np.ndarray
    Z: np.ndarray


class Shooter:
    """The first-order system of one scene (material, M, χ, coils) with its pole starts and half-integrations."""

    def __init__(self, scene, rtol: float = 1e-13, atol: float = 1e-13):
        f = scene.field
        self.coils = coaxial_table(f.coils)
        self.kernels = KernelSet.of_scene(scene)
        self.M, self.chi = (f.M, f.chi) if self.coils.shape[0] else (0.0, f.chi)
        self.voltage = scene.voltage
        self.equator_symmetric = f.is_equator_symmetric
        self.rtol, self.atol = rtol, atol

    def params(self, P) -> dict:
        """The branch parameters as the kernels' named values (the material's μ, α)."""
        return {"P": P, "M": self.M, "chi": self.chi, "voltage": self.voltage}

    def field(self, rho, z):
        """H² and its derivatives at (ρ, z) in the generated FIELD_ROWS (zeros without coils)."""
        if not self.coils.shape[0]:
            return np.zeros(len(FIELD_ROWS))
        return field_squared(rho, z, self.coils)

    def pole_coefficients(self, pole, lam, eta, P):
        """(c2, e2) of the Taylor series at the pole (σ = NORTH or SOUTH) with stretch λ_p and height η_p (the
        field on the axis at η_p)."""
        q = self.field(0.0, eta)
        values = {"lam0": lam, **self.params(P), "field_north": q, "field_south": q}
        c2n, e2n, c2s, e2s = self.kernels.call("pole_series", values)
        return (c2n, e2n) if pole == NORTH else (c2s, e2s)

    def pole_derivatives(self, pole, lam, eta, P):
        """∂(c2, e2)/∂(P, η_p, λ_p), 2 × 3, by central differences."""
        out = np.empty((2, 3))
        base = np.array([P, eta, lam])
        for k in range(3):
            h = _DIFF_STEP * max(1.0, abs(base[k]))
            up, down = base.copy(), base.copy()
            up[k] += h
            down[k] -= h
            out[:, k] = (np.subtract(self.pole_coefficients(pole, up[2], up[1], up[0]),
                                     self.pole_coefficients(pole, down[2], down[1], down[0]))) / (2 * h)
        return out

    def half(self, pole, lam, eta, P, start="taylor", eps=1e-4) -> Half:
        """Integrate y and Z = ∂y/∂(P, η_p, λ_p) from the pole to the equator (see the module docstring)."""
        sigma = pole
        c2, e2 = self.pole_coefficients(pole, lam, eta, P)
        dc2, de2 = self.pole_derivatives(pole, lam, eta, P)
        Z0 = np.zeros((4, 3))
        if start == "taylor":
            t0 = eps
            y0 = np.array([lam + c2 * eps**2, 2 * sigma * c2 * eps * np.sin(eps),
                           eta + e2 * eps**2, 2 * sigma * e2 * eps])
            Z0[0], Z0[1] = dc2 * eps**2, 2 * sigma * dc2 * eps * np.sin(eps)
            Z0[2], Z0[3] = de2 * eps**2, 2 * sigma * de2 * eps
        elif start == "pole":
            t0, y0 = 0.0, np.array([lam, 0.0, eta, 0.0])
        else:
            raise ValueError(f"start = {start!r}: expected 'taylor' or 'pole'")
        Z0[2, 1] += 1.0
        Z0[0, 2] += 1.0
        pole_limit = np.zeros(16)
        pole_limit[3], pole_limit[4 + 9:4 + 12] = 2 * sigma * e2, 2 * sigma * de2
        kernels, params = self.kernels, self.params(P)

        def rhs(t, Y):
            if t == 0.0:
                return pole_limit
            y = Y[:4]
            c, s = sigma * np.cos(t), np.sin(t)
            theta = t if sigma > 0 else np.pi - t
            values = {"theta": theta, "cos_theta": c, "sin_theta": s, **kernels.state(y), **params,
                      "field": self.field(y[0] * s, y[2])}
            J = np.array(kernels.call("rhs_jacobian", values)).reshape(4, 4)
            dZ = J @ Y[4:].reshape(4, 3)
            dZ[:, 0] += kernels.call("rhs_pressure", values)
            return sigma * np.concatenate([kernels.call("rhs", values), dZ.ravel()])

        solution = solve_ivp(rhs, (t0, EQUATOR), np.concatenate([y0, Z0.ravel()]), method="DOP853",
                             rtol=self.rtol, atol=self.atol)
        if not solution.success or not np.all(np.isfinite(solution.y[:, -1])):
            raise FloatingPointError(f"integration from the {'north' if sigma > 0 else 'south'} pole failed at "
                                     f"θ-distance {solution.t[-1]:.6g}: {solution.message}")
        end = solution.y[:, -1]
        return Half(end[:4], end[4:].reshape(4, 3))


def _newton(equations, x0, tol, max_iter):
    """Newton on equations(x) -> (r, ∂r/∂x, halves); converged when |Δx|∞ ≤ tol·max(1, |x|∞).

    Returns (x, r, halves, iterations, converged, message), r and halves evaluated at the returned x.
    """
    x = np.array(x0, dtype=float)
    iteration = 0
    try:
        r, A, halves = equations(x)
        for iteration in range(1, max_iter + 1):
            dx = np.linalg.solve(A, -r)
            x = x + dx
            r, A, halves = equations(x)
            if np.abs(dx).max() <= tol * max(1.0, np.abs(x).max()):
                return x, r, halves, iteration, True, "converged"
    except (FloatingPointError, np.linalg.LinAlgError) as error:
        return x, np.full(len(x), np.inf), None, iteration, False, f"{type(error).__name__}: {error}"
    return x, r, halves, max_iter, False, f"no convergence in {max_iter} Newton iterations"


def _result(P, eta_top, halves, r, iterations, converged, message, lam2_bottom, eta_bottom, t_start):
    return ShootingResult(
        P=float(P), eta_top=float(eta_top), lam2_equator=float(halves[0].y[0]) if halves else np.nan,
        residual=float(np.abs(r).max()), converged=converged, message=message, iterations=iterations,
        lam2_bottom=float(lam2_bottom), eta_bottom=float(eta_bottom), wall_time=time.perf_counter() - t_start,
    )


def shoot_symmetric(scene, pole_stretch, P_guess, eta0_guess, start="taylor", eps=1e-4, tol=1e-12,
                    max_iter=20) -> ShootingResult:
    """Equator-symmetric equilibrium with λ2(0) = ``pole_stretch``: (P, η0) with v(π/2) = η(π/2) = 0.

    ``start``: "taylor" (integrate from θ = ``eps``) or "pole" (from θ = 0 with the pole limit of f).
    """
    t_start = time.perf_counter()
    shooter = Shooter(scene)
    if not shooter.equator_symmetric:
        raise ValueError(f"scene {scene.name!r}: the coils are not mirror-symmetric about z = 0, so there are "
                         "no equator-symmetric equilibria; use shoot_general")

    def equations(x):
        north = shooter.half(NORTH, pole_stretch, x[1], x[0], start, eps)
        return north.y[[1, 2]], north.Z[[1, 2]][:, :2], (north,)

    x, r, halves, iterations, converged, message = _newton(equations, (P_guess, eta0_guess), tol, max_iter)
    return _result(x[0], x[1], halves, r, iterations, converged, message, pole_stretch, -x[1], t_start)


def shoot_general(scene, pole_stretch, P_guess, eta0_guess, lam2_bottom_guess, eta_bottom_guess, start="taylor",
                  eps=1e-4, tol=1e-12, max_iter=20) -> ShootingResult:
    """Any axisymmetric equilibrium with λ2(0) = ``pole_stretch``: both halves shot to θ = π/2 and matched.

    Unknowns (P, η0, λ2(π), η(π)), conditions y_N(π/2) = y_S(π/2). Without a field (no coils or M = 0) η0 stays
    at ``eta0_guess`` and w is not matched (the axial first integral, module docstring).
    """
    t_start = time.perf_counter()
    shooter = Shooter(scene)
    free_translation = shooter.M != 0.0

    def unpack(x):
        return (x[0], x[1], x[2], x[3]) if free_translation else (x[0], eta0_guess, x[1], x[2])

    def equations(x):
        P, eta0, lam2_bottom, eta_bottom = unpack(x)
        north = shooter.half(NORTH, pole_stretch, eta0, P, start, eps)
        south = shooter.half(SOUTH, lam2_bottom, eta_bottom, P, start, eps)
        mismatch = north.y - south.y
        # columns ∂/∂(P, η0, λ2(π), η(π))
        A = np.column_stack([north.Z[:, 0] - south.Z[:, 0], north.Z[:, 1], -south.Z[:, 2], -south.Z[:, 1]])
        if free_translation:
            return mismatch, A, (north, south)
        return mismatch[:3], A[:3][:, [0, 2, 3]], (north, south)

    x0 = (P_guess, eta0_guess, lam2_bottom_guess, eta_bottom_guess)
    x0 = x0 if free_translation else (x0[0],) + x0[2:]
    x, r, halves, iterations, converged, message = _newton(equations, x0, tol, max_iter)
    P, eta0, lam2_bottom, eta_bottom = unpack(x)
    return _result(P, eta0, halves, r, iterations, converged, message, lam2_bottom, eta_bottom, t_start)
