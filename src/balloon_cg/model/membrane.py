"""Φ(λ1, λ2) and its derivatives: for a strain energy (scene/energies.py) from its generated kernels, for an Ogden
material (MODEL.md §2) in closed form,

    Φ = Σ (μ/α)(λ1^α + λ2^α + (λ1λ2)^−α − 3),   Φ_1 = Σ μ (λ1^(α−1) − λ1^(−α−1) λ2^−α),
    Φ_11 = Σ μ ((α − 1) λ1^(α−2) + (α + 1) λ1^(−α−2) λ2^−α),   Φ_12 = Σ μ α (λ1λ2)^(−α−1)   (Φ_2, Φ_22 by symmetry).

The sphere closed forms and the elastic stresses of the Ogden presets are written out in numpy
(model/sphere.py, model/sphere_modes.py, model/stresses.py); for any other energy they use these values,
computed by the class's ``membrane_derivatives`` kernel (codegen/stretch_derivatives.py).

Under the voltage Φ̄ ([electric]) a dielectric elastomer membrane has the effective energy (``Charged``; MODEL.md §2,
units μ/2)

    Φ_eff = Φ − Φ̄² λ1² λ2²,   Φ_eff,1 = Φ_1 − 2Φ̄² λ1 λ2²,   Φ_eff,11 = Φ_11 − 2Φ̄² λ2²,
    Φ_eff,12 = Φ_12 − 4Φ̄² λ1 λ2   (Φ_eff,2, Φ_eff,22 by symmetry),

so that a closed form written for any material's Φ (model/tube.py) holds under a voltage with Φ_eff in its place.
"""
import functools
from dataclasses import dataclass

import numpy as np

from .kernels import KernelSet
from ..scene.energies import StrainEnergy

LABELS = ("phi", "phi_1", "phi_2", "phi_11", "phi_12", "phi_22")


@functools.cache
def _kernels(material) -> KernelSet:
    return KernelSet(material)


@dataclass(frozen=True)
class Charged:
    """The effective energy Φ_eff = Φ − Φ̄² λ1² λ2² of ``material`` under the voltage Φ̄ (module docstring)."""

    material: object
    voltage: float


def scene_energy(scene):
    """The membrane energy of a scene as the closed forms take it: its material, ``Charged`` under [electric]."""
    return scene.material if scene.electric is None else Charged(scene.material, scene.electric.voltage)


def stretch_derivatives(material, lam1, lam2) -> dict:
    """{label: array} of Φ, Φ_1, Φ_2, Φ_11, Φ_12, Φ_22 at (λ1, λ2) (broadcast; scalars give 0-d arrays); of Φ_eff
    for a ``Charged`` material."""
    l1, l2 = np.broadcast_arrays(np.asarray(lam1, dtype=float), np.asarray(lam2, dtype=float))
    shape = l1.shape
    if isinstance(material, Charged):
        d, v2 = stretch_derivatives(material.material, l1, l2), material.voltage**2
        return {"phi": d["phi"] - v2 * (l1 * l2) ** 2, "phi_1": d["phi_1"] - 2 * v2 * l1 * l2**2,
                "phi_2": d["phi_2"] - 2 * v2 * l1**2 * l2, "phi_11": d["phi_11"] - 2 * v2 * l2**2,
                "phi_12": d["phi_12"] - 4 * v2 * l1 * l2, "phi_22": d["phi_22"] - 2 * v2 * l1**2}
    if not isinstance(material, StrainEnergy):
        return _ogden(material, l1, l2)
    out = _kernels(material).nodes("membrane_derivatives", {"lam1": np.ascontiguousarray(l1.ravel()),
                                                             "lam2": np.ascontiguousarray(l2.ravel())})
    return {label: row.reshape(shape) for label, row in zip(LABELS, out)}


def _ogden(material, l1, l2) -> dict:
    """``stretch_derivatives`` of an Ogden material in closed form (module docstring)."""
    mu = np.asarray(material.mu, dtype=float).reshape((-1,) + (1,) * l1.ndim)
    alpha = np.asarray(material.alpha, dtype=float).reshape(mu.shape)
    j = (l1 * l2) ** -alpha

    def first(a, b):
        return np.sum(mu * (a ** (alpha - 1) - j / a), axis=0)

    def second(a):
        return np.sum(mu * ((alpha - 1) * a ** (alpha - 2) + (alpha + 1) * j / a**2), axis=0)

    return {"phi": np.sum(mu / alpha * (l1**alpha + l2**alpha + j - 3), axis=0), "phi_1": first(l1, l2),
            "phi_2": first(l2, l1), "phi_11": second(l1), "phi_12": np.sum(mu * alpha * j / (l1 * l2), axis=0),
            "phi_22": second(l2)}
