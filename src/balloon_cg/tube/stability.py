"""Stability of a tube's states (m = 0): the spectra of the mirror blocks of ∂R/∂u and the number of unstable
directions under pressure control (all of u's unknowns: a held λ̄ is not one) and under volume control (on
δV = ∇V·δu = 0, ∇V = −∂R/∂P), by the inertia of a Bunch–Kaufman factorisation (numerics/eigen.py: ``restricted``
removes the constraint)."""
import numpy as np

from ..galerkin.equilibrium import Equilibrium, Parameters
from ..numerics.eigen import GramFactor, negative_count, restricted
from ..scene.loading import Control


def unstable_counts(eq: Equilibrium, points) -> dict:
    """{Control.PRESSURE, Control.VOLUME: the number of negative eigenvalues of ∂R/∂u at each Y = (u, P) of
    ``points``, without and with δV = 0} (module docstring)."""
    counts = {Control.PRESSURE: [], Control.VOLUME: []}
    free = eq.disc.free
    unit = GramFactor(np.ones(free.size), orthogonal=True)
    for Y in points:
        params = Parameters(Y[-1])
        H = eq.jacobian(Y[:-1], params)[np.ix_(free, free)]
        counts[Control.PRESSURE].append(negative_count(H))
        gradient = -eq.parameter_derivative(Y[:-1], params, "P")[free]
        counts[Control.VOLUME].append(negative_count(restricted(H, unit, gradient[None, :])))
    return {control: np.array(values, dtype=int) for control, values in counts.items()}


def spectrum(eq: Equilibrium, Y: np.ndarray, index: np.ndarray) -> np.ndarray:
    """The eigenvalues (ascending) of the Hessian ∂R/∂u at Y = (u, P) restricted to the unknowns ``index``."""
    H = eq.jacobian(Y[:-1], Parameters(Y[-1]))
    return np.linalg.eigvalsh(H[np.ix_(index, index)])
