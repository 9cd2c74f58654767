"""How well a tube's state solves the continuous problem: its spectral error estimate and its first integral.

Two measures per point, both cheap (one pass over the coefficients, one over the nodes):

- the Legendre tail (galerkin/interval.IntervalDiscretisation.tail), the estimate the resolution policy reads
  (analysis/branches/resolution.Resolution: a point is resolved where it is at most solver.max_error);
- the spread of the first integral of axial translation, H = λ1Φ_1 − Φ (ρ'∂π/∂ρ' + η'∂π/∂η' − π with the
  pressure's term, linear in η', dropping out: model/tube.py), constant along S on an exact equilibrium of a tube
  without a field. Stored as (max H − min H)/max |H| over the Gauss nodes (0 where H vanishes at every node: the
  unstressed tube); Φ the effective energy under a voltage (model/membrane.Charged; on a voltage continuation at
  each point's Φ̄, tube/voltage.py). In a coil field H is not conserved (the field varies along the tube): NaN.
"""
import numpy as np

from .primary import in_field
from ..galerkin.equilibrium import Equilibrium
from ..model.membrane import Charged, scene_energy, stretch_derivatives


def first_integral(eq: Equilibrium, u: np.ndarray, voltage: float | None = None) -> np.ndarray:
    """H = λ1Φ_1 − Φ at the Gauss nodes of the state u (λ1 = |(ρ', η')|, λ2 = ρ on the tube's meridian); under
    ``voltage`` Φ̄ (None: the scene's) Φ is Φ_eff."""
    hoop, rate, _, slope = eq.disc.node_state(u)
    axial = np.hypot(rate, slope)
    energy = scene_energy(eq.scene) if voltage is None else Charged(eq.scene.material, voltage)
    d = stretch_derivatives(energy, axial, hoop)
    return axial * d["phi_1"] - d["phi"]


def first_integral_spread(eq: Equilibrium, u: np.ndarray, voltage: float | None = None) -> float:
    """(max H − min H)/max |H| over the nodes (module docstring; ``voltage``: ``first_integral``'s); NaN in a coil
    field."""
    if in_field(eq.scene):
        return np.nan
    H = first_integral(eq, u, voltage)
    size = np.abs(H).max()
    return float(np.ptp(H) / size) if size > 0 else 0.0


def accuracy(eq: Equilibrium, states, voltage=None) -> tuple:
    """(tail, first-integral spread) arrays of the states u (rows); ``voltage``: each state's Φ̄ on a voltage
    continuation (None: the scene's)."""
    charges = [None] * len(states) if voltage is None else voltage
    return (np.array([eq.disc.tail(u) for u in states]),
            np.array([first_integral_spread(eq, u, v) for u, v in zip(states, charges)]))
