"""The net force and torque of the applied field on a state (per 2π, as E): the field's part of the energy,
−½ χ M ∫∫ H²(x) dA, changes under a rigid translation δx = e and a rigid rotation δx = ω × x by −e·F and −ω·T with

    F = ½ χ M (1/2π) ∫∫ ∇H²(x) dA,      T = ½ χ M (1/2π) ∫∫ x × ∇H²(x) dA   (about the origin),

dA the reference area (the magnetic energy is per unit reference area); the pressure's net force and torque on a
closed surface vanish and the elastic energy is invariant under both. A balloon held at its centre (the origin)
feels the reaction −F; one free to turn about it is in equilibrium only where T = 0.
"""
import numpy as np

from .equilibrium import SurfaceEquilibrium
from ..galerkin.equilibrium import Parameters

LOADS = ("force", "torque")  # each (3,) per state


def loads(eq: SurfaceEquilibrium, c: np.ndarray, params: Parameters) -> dict:
    """{'force': F, 'torque': T} of the field on the state c (module docstring); zeros without a field."""
    if not eq.has_field:
        return {"force": np.zeros(3), "torque": np.zeros(3)}
    values = eq.node_values(c)
    x, gradient = values["state"][:3], values["field"][1:4]
    weights = 0.5 * params.chi * params.M * np.repeat(eq.basis.nodes["weights"], eq.basis.n_phi)
    return {"force": gradient @ weights, "torque": np.cross(x, gradient, axis=0) @ weights}
