"""Φ(λ1, λ2) and its derivatives for a strain energy (scene/energies.py), from its generated kernels.

The sphere closed forms and the elastic stresses of the Ogden presets are written out in numpy
(model/sphere.py, model/sphere_modes.py, model/stresses.py); for any other energy they use these values,
computed by the class's ``membrane_derivatives`` kernel (codegen/stretch_derivatives.py).
"""
import functools

import numpy as np

from .kernels import KernelSet

LABELS = ("phi", "phi_1", "phi_2", "phi_11", "phi_12", "phi_22")


@functools.cache
def _kernels(material) -> KernelSet:
    return KernelSet(material)


def stretch_derivatives(material, lam1, lam2) -> dict:
    """{label: array} of Φ, Φ_1, Φ_2, Φ_11, Φ_12, Φ_22 at (λ1, λ2) (broadcast; scalars give 0-d arrays)."""
    l1, l2 = np.broadcast_arrays(np.asarray(lam1, dtype=float), np.asarray(lam2, dtype=float))
    shape = l1.shape
    out = _kernels(material).nodes("membrane_derivatives", {"lam1": np.ascontiguousarray(l1.ravel()),
                                                             "lam2": np.ascontiguousarray(l2.ravel())})
    return {label: row.reshape(shape) for label, row in zip(LABELS, out)}
