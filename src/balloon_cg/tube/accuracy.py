"""How well a tube's state solves the continuous problem: its spectral error estimate and its first integral.

Two measures per point, both cheap (one pass over the coefficients, one over the nodes):

- the Legendre tail (galerkin/interval.IntervalDiscretisation.tail), the estimate the resolution policy reads
  (analysis/branches/resolution.Resolution: a point is resolved where it is at most solver.max_error);
- the spread of the first integral of axial translation, H = λ1Φ_1 − Φ (ρ'∂π/∂ρ' + η'∂π/∂η' − π with the
  pressure's term, linear in η', dropping out: model/tube.py), constant along S on an exact equilibrium of a tube
  without a field. Stored as (max H − min H)/max |H| over the Gauss nodes (0 where H vanishes at every node: the
  unstressed tube); Φ the effective energy under a voltage (model/membrane.Charged). In a coil field H is not
  conserved (the field varies along the tube): NaN.
"""
import numpy as np

from .primary import in_field
from ..galerkin.equilibrium import Equilibrium
from ..model.membrane import scene_energy, stretch_derivatives


def first_integral(eq: Equilibrium, u: np.ndarray) -> np.ndarray:
    """H = λ1Φ_1 − Φ at the Gauss nodes of the state u (λ1 = |(ρ', η')|, λ2 = ρ on the tube's meridian)."""
    hoop, rate, _, slope = eq.disc.node_state(u)
    axial = np.hypot(rate, slope)
    d = stretch_derivatives(scene_energy(eq.scene), axial, hoop)
    return axial * d["phi_1"] - d["phi"]


def first_integral_spread(eq: Equilibrium, u: np.ndarray) -> float:
    """(max H − min H)/max |H| over the nodes (module docstring); NaN in a coil field."""
    if in_field(eq.scene):
        return np.nan
    H = first_integral(eq, u)
    size = np.abs(H).max()
    return float(np.ptp(H) / size) if size > 0 else 0.0


def accuracy(eq: Equilibrium, states) -> tuple:
    """(tail, first-integral spread) arrays of the states u (rows)."""
    return (np.array([eq.disc.tail(u) for u in states]), np.array([first_integral_spread(eq, u) for u in states]))
