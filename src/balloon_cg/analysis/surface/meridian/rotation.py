"""The other half of a pitchfork born at an m ≥ 1 zero of a surface over a meridian: the image of the branch traced
along +φ (trace.py) under the rotation by π/g about the axis, g the greatest common divisor of its basis' orders
(the branch's m: its orders are 0, m, 2m, …).

The rotation Q by π/g (φ ↦ φ − π/g) maps each order's fields cos kφ, sin kφ to (−1)^(k/g) times themselves: it
is diagonal on the coefficients, c_k ↦ (−1)^(k/g) c_k, and maps the critical mode φ (order m = g) to −φ. It is a
symmetry of every scene the engine traces (an axisymmetric reference meridian, coaxial coils, pressure, the
held gauge's rows of order 1 map to minus themselves: the image's centroid held as the source's), and of the
discrete energy too where n_phi is a multiple of 2g (basis.py: Q maps the nodes in φ to nodes), so the image of an
equilibrium is an equilibrium of the same equations to the rounding of the source: P, V/V0, the error estimate (norms
of whole orders), the mirror sector's eigenvalues (Q maps the sector to itself and keeps G) and the folds are the
source's, the amplitude φᵀ G c_m and the gauge's reaction τ (a multiplier of an order-1 row) change sign. For odd m
it is also the rotation by π, for even m (which that rotation maps to itself) the rotation by π/m: either way the
sphere's traced −φ half is not needed on a meridian basis.
"""
import math
from dataclasses import replace

import numpy as np

from .basis import MeridianSurfaceBasis
from .trace import MeridianSurfaceBranch


def half_period(basis: MeridianSurfaceBasis) -> int:
    """g: the greatest common divisor of the basis' orders ≥ 1 (the rotation by π/g is diagonal on them)."""
    return math.gcd(*basis.orders[1:])


def rotation_signs(basis: MeridianSurfaceBasis) -> np.ndarray:
    """Per coefficient of c the sign (−1)^(k/g) of Q on its order k (order 0: +1); ValueError where n_phi is no
    multiple of 2g (the discrete energy would not keep Q: the image no equilibrium of it)."""
    if len(basis.orders) < 2:
        raise ValueError(f"orders: {basis.orders} (allowed: an order m ≥ 1, the branch's)")
    g = half_period(basis)
    if basis.n_phi % (2 * g):
        raise ValueError(f"n_phi: {basis.n_phi} (allowed: a multiple of {2 * g}, for the rotation by π/{g} to map "
                         "the nodes in φ to nodes)")
    signs = np.ones(basis.size)
    for k in basis.orders[1:]:
        signs[basis.block(k)] = (-1) ** (k // g)
    return signs


def rotated(branch: MeridianSurfaceBranch, source: str) -> MeridianSurfaceBranch:
    """The image of ``branch`` (named ``source``) under the rotation by π/g about the axis (module docstring):
    every point's coefficients (and its UZ points') times ``rotation_signs``, its amplitude and reaction negated,
    ``image_of`` the source."""
    if branch.image_of:
        raise ValueError(f"rotated: {source} is itself the image of {branch.image_of} (allowed: a traced branch)")
    signs = rotation_signs(branch.basis)
    return replace(branch, coefficients=branch.coefficients * signs, amplitude=-branch.amplitude,
                   reaction=-branch.reaction, image_of=source,
                   events=tuple(replace(e, coefficients=e.coefficients * signs) for e in branch.events))
