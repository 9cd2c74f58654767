"""The energy landscape near a pear pitchfork at a pressure off the branch point (the paper's Fig. 13).

At a fixed pressure P where both the symmetric state u_s and a pear-shaped state u_p exist (on the pear
branch's general discretisation), the amplitude is measured along the unit vector from one to the other,

    φ = (u_p − u_s) / |u_p − u_s|   (Euclidean norm of the Legendre coefficients),   Λ = φ·(u − u_s),

and the reduced energy is ΔΠ(Λ) = min {E(u) : φ·(u − u_s) = Λ} − E(u_s) (the other modes relax: constrained
minimisations, ``bifurcation.constrained_minimum``, continued from Λ = 0 outward). Its stationary points Λ* are
the equilibria at P on that line: 0 (u_s), |u_p − u_s| (u_p) and, by the equator reflection, the mirror
image; they are where the multiplier μ = −dΔΠ/dΛ changes sign (located by the cubic through the samples around).
At the branch point itself φ tends to the critical eigenvector (``bifurcation.classify``'s normalisation).
"""
from dataclasses import dataclass

import numpy as np

from ...galerkin.equilibrium import Equilibrium, Parameters
from ...numerics.newton import newton
from ..points.branch_points import constrained_minimum
from ..branches.problem import ParameterSystem


class LandscapeError(RuntimeError):
    """A state or a constrained minimisation of the landscape did not converge."""


@dataclass(frozen=True)
class Landscape:
    """ΔΠ(Λ) at ``pressure``: ``amplitude`` Λ (ascending), ``energy`` ΔΠ, ``multiplier`` μ = −dΔΠ/dΛ, and the
    stationary points ``equilibria`` (sign changes of μ, with 0 and ±``pear_amplitude`` among them)."""

    pressure: float
    amplitude: np.ndarray
    energy: np.ndarray
    multiplier: np.ndarray
    pear_amplitude: float

    @property
    def equilibria(self) -> np.ndarray:
        """Λ where μ changes sign between samples (the root in that interval of the cubic through the four
        samples around it: it interpolates them, so it has one there) and the samples where μ vanishes (below
        ZERO_MULTIPLIER of its largest magnitude: Λ = 0 on the symmetric state)."""
        L, mu = self.amplitude, self.multiplier
        zero = np.abs(mu) <= ZERO_MULTIPLIER * np.abs(mu).max()
        found = list(L[zero])
        for i in np.flatnonzero((mu[:-1] * mu[1:] < 0) & ~zero[:-1] & ~zero[1:]):
            near = slice(max(0, min(i - 1, L.size - 4)), max(0, min(i - 1, L.size - 4)) + 4)
            roots = np.polynomial.Polynomial.fit(L[near], mu[near], 3).roots()
            inside = roots[(np.abs(roots.imag) < 1e-12) & (roots.real >= L[i]) & (roots.real <= L[i + 1])].real
            found.append(inside[0])
        return np.sort(np.array(found))


ZERO_MULTIPLIER = 1e-8


def state_at(eq: Equilibrium, params: Parameters, guess: np.ndarray, pressure: float, solver) -> np.ndarray:
    """The equilibrium u of ``eq`` at ``pressure`` from ``guess`` (Newton in (u, P) with P fixed)."""
    system = ParameterSystem(eq, params, "P")
    row = np.zeros(guess.size + 1)
    row[-1] = 1.0
    result = newton(system.residual, system.jacobian, np.append(guess, pressure), row, pressure, solver.tol,
                    solver.max_newton)
    if not result.converged:
        raise LandscapeError(f"no equilibrium at P = {pressure:.6g} from the guess")
    return result.x[:-1]


def landscape(eq: Equilibrium, params: Parameters, symmetric: np.ndarray, pear: np.ndarray, solver,
              samples: int = 41, reach: float = 1.4) -> Landscape:
    """ΔΠ(Λ) at ``params.P`` on the line through the equilibria ``symmetric`` and ``pear`` (module docstring),
    Λ ∈ [−reach, reach]·|pear − symmetric|, ``samples`` values (odd: Λ = 0 is one)."""
    difference = pear - symmetric
    distance = float(np.linalg.norm(difference))
    phi = difference / distance
    E0 = eq.energy(symmetric, params)
    amplitudes = np.linspace(-reach, reach, samples) * distance
    middle = samples // 2
    energy, multiplier = np.empty(samples), np.empty(samples)
    for direction in (range(middle, samples), range(middle, -1, -1)):  # from Λ = 0 outward, each side
        guess = symmetric
        for i in direction:
            result = constrained_minimum(eq, params, phi, phi @ symmetric + amplitudes[i],
                                         guess + (amplitudes[i] - phi @ (guess - symmetric)) * phi, solver)
            if not result.converged:
                raise LandscapeError(f"constrained minimisation at Λ = {amplitudes[i]:.4g} (P = {params.P:.6g}) "
                                     "did not converge")
            guess = result.x[:-1]
            energy[i], multiplier[i] = eq.energy(guess, params) - E0, result.x[-1]
    return Landscape(float(params.P), amplitudes, energy, multiplier, distance)
