"""Stability of a state of the tube over (S, φ) in its mirror sector (y → −y: every order's cos/sin pattern of
tube/surface/basis.py), as tube/stability.py reads the axisymmetric states. The second variation is the Hessian H of
E/(2π) on the free coefficients, in the pencil with the block-diagonal metric M = diag(1 on order 0
(tube/stability.py's), G on each m ≥ 1 order (tube/azimuthal.py's Gram matrix)), the sideways translation removed on
sliding ends (its centroid held, tᵀ G c_1 = 0: a zero mode without a field, so the held and free readings are one).
Under pressure control: the lowest COUNT eigenvalues and the number of negative ones (from the eigenvalues); under
volume control on δṼ = g·δc = 0 (g = ∇Ṽ = −∂R/∂P); under gas control of H + (P/Ṽ) g gᵀ (numerics/eigen.restricted: the
inertia, which M does not change, is the stability; the eigenvalues' sizes are on M).
"""
import numpy as np
from scipy import linalg

from ...numerics.eigen import GramFactor, restricted
from ...scene.loading import Control

COUNT = 3  # the lowest eigenvalues stored per point (pressure control)


def metric(basis) -> np.ndarray:
    """M on the free coefficients (module docstring)."""
    blocks = [np.eye(basis.axis_size)] + [basis.gram(m) for m in basis.orders[1:]]
    return linalg.block_diag(*blocks)[np.ix_(basis.free, basis.free)]


class SectorStability:
    """The readings (module docstring) of the states of ``system`` (tube/surface/system.TubeSurfaceSystem: its
    equilibrium, free unknowns and gauge), M factored once."""

    def __init__(self, system):
        self.system = system
        self.factor = GramFactor(metric(system.basis))
        self.gauge = system.gauges

    def pressure_matrix(self, c: np.ndarray, params) -> np.ndarray:
        """The standard symmetric matrix of the pencil (H, M) on tᵀ G c_1 = 0 (pressure control)."""
        free = self.system.free
        return restricted(self.system.surface.hessian(c, params)[np.ix_(free, free)], self.factor, self.gauge)

    def __call__(self, c: np.ndarray, params) -> tuple:
        """(the lowest COUNT eigenvalues under pressure control, {Control: the number of negative ones}) at c."""
        free, surface = self.system.free, self.system.surface
        H = surface.hessian(c, params)[np.ix_(free, free)]
        g = -surface.parameter_derivative(c, params)[free]
        gas = H + params.P / surface.volume(c) * np.outer(g, g)
        spectra = {Control.PRESSURE: np.linalg.eigvalsh(restricted(H, self.factor, self.gauge)),
                   Control.VOLUME: np.linalg.eigvalsh(restricted(H, self.factor, np.vstack([self.gauge, g]))),
                   Control.GAS: np.linalg.eigvalsh(restricted(gas, self.factor, self.gauge))}
        return spectra[Control.PRESSURE][:COUNT], {k: int(np.sum(v < 0)) for k, v in spectra.items()}
