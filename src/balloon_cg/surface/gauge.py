"""The gauge of the whole-sphere problem (MODEL.md §8): which exact zero modes are removed, and how.

- Relabellings (a material rotation of the reference sphere, or of a spheroid about its axis: the axes of
  SphericalBasis.relabellings) leave every surface unchanged: removed by the phase conditions
  ∫∫ (e_k × X) · u dA = 0 (no rigid-rotation part of u in the reference frame), for each such axis k whose
  rotation field lies in the basis' symmetry subspace. They are linear, homogeneous and hold for every
  axisymmetric state.
- Translations: ∫∫ u dA = 0 (the l = 0 coefficients) along every axis where the balloon is held (``held``: the
  centre ∫∫ x dA/4π is held at the origin, the multiplier is the reaction force: the field's net force, along the
  axis of coaxial loops off the equator as in the axisymmetric solver's held reading), along none where it is free
  (an equilibrium then needs a zero net force); without a field along every axis (held and free coincide).
- Rigid rotations of x are zero modes where the field allows them (every axis at M = 0, the coil axis for coaxial
  loops, none for loops anywhere: the balloon turns until the field's torque about its held centre vanishes). In
  a subspace that keeps one of them (other than on a sphere state, where it is a relabelling) the gauge would need
  a phase condition on the current state: refused for now (``UnsupportedGauge``).

The constraints G c = 0 touch only l ≤ 1 coefficients; the reduced coordinates are c = Z a with Z the identity on
every other coefficient and an orthonormal null-space block on those.
"""
import enum
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numba import njit

from .basis import SphericalBasis


class UnsupportedGauge(ValueError):
    """A subspace with a rigid-rotation zero mode that this gauge does not remove."""


class FieldSymmetry(enum.Enum):
    """What the applied field leaves free (module docstring): the rigid motions that are zero modes."""

    NONE = "none"  # no field acts (no coils, or M = 0): every translation and rotation
    AXIAL = "axial"  # coaxial loops: the rotation about the coil axis z, the axial translation
    GENERAL = "general"  # loops anywhere: none

    @property
    def free_rotations(self) -> tuple:
        """The axes of the rigid rotations that are zero modes."""
        return {FieldSymmetry.NONE: (0, 1, 2), FieldSymmetry.AXIAL: (2,), FieldSymmetry.GENERAL: ()}[self]

    def held_translations(self, held: bool) -> tuple:
        """The axes along which ∫∫ u dA = 0 is imposed for a balloon ``held`` (or free) at its centre."""
        if self == FieldSymmetry.NONE:
            return (0, 1, 2)
        return (0, 1, 2) if held else ()


@dataclass(frozen=True)
class Gauge:
    """Constraints of a SphericalBasis: ``held`` (the centre held), ``field_symmetry`` (what the applied field
    leaves free, module docstring)."""

    basis: SphericalBasis
    held: bool = True
    field_symmetry: FieldSymmetry = FieldSymmetry.NONE
    constraints: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        rows = [self._translation(axis) for axis in self.field_symmetry.held_translations(self.held)]
        rows = [row for row in rows if row is not None]
        rotations = [self._rotation(axis) for axis in range(3)]
        rows += [rotations[axis] for axis in self.basis.relabellings if rotations[axis] is not None]
        kept = [axis for axis in self.field_symmetry.free_rotations if rotations[axis] is not None]
        if kept:
            raise UnsupportedGauge(
                f"the rigid rotation about the {'xyz'[kept[0]]} axis is a zero mode of this subspace (symmetry "
                f"{self.basis.symmetry}, field {self.field_symmetry.value}) and no phase condition removes it: add a "
                "reflection that excludes it")
        object.__setattr__(self, "constraints", np.array(rows).reshape(-1, self.basis.size))

    def _translation(self, axis: int):
        """The constraint row ∫∫ u_axis dA (dA the reference area: S' dθ sin θ dφ on a spheroid; its moments:
        ``basis.project``), normalised, or None (not in the subspace)."""
        return self._moments(np.eye(3)[axis][:, None] * self._area)

    def _rotation(self, axis: int):
        """The constraint row ∫∫ (e_axis × X) · u dA, normalised, or None when the subspace excludes it."""
        reference = self.basis.nodes["reference"][:3]
        return self._moments(np.cross(np.eye(3)[axis][:, None], reference, axis=0) * self._area)

    @property
    def _area(self) -> np.ndarray:
        """The reference area element per the sphere's at the nodes (S'(θ); 1 on the sphere)."""
        return np.repeat(self.basis.nodes["rate"], self.basis.n_phi)

    def _moments(self, field: np.ndarray):
        row = self.basis.project(field)
        norm = np.linalg.norm(row)
        return row / norm if norm > 1e-10 else None

    @cached_property
    def _split(self) -> tuple:
        """(free coefficients, constrained ones, the orthonormal null-space block Z_S)."""
        G = self.constraints
        touched = np.flatnonzero(np.abs(G).max(axis=0, initial=0.0) > 1e-14)
        free = np.setdiff1d(np.arange(self.basis.size), touched)
        if touched.size == 0:
            return free, touched, np.zeros((0, 0))
        _, sigma, vt = np.linalg.svd(G[:, touched])
        rank = int((sigma > 1e-10).sum())
        return free, touched, vt[rank:].T.copy()

    @property
    def size(self) -> int:
        free, _, block = self._split
        return free.size + block.shape[1]

    def expand(self, a: np.ndarray) -> np.ndarray:
        """c = Z a."""
        free, touched, block = self._split
        c = np.zeros(self.basis.size)
        c[free] = a[:free.size]
        c[touched] = block @ a[free.size:]
        return c

    def reduce(self, r: np.ndarray) -> np.ndarray:
        """Zᵀ r (a residual, or the coordinates a of a c that meets the constraints)."""
        free, touched, block = self._split
        return np.concatenate([r[free], block.T @ r[touched]])

    def reduce_matrix(self, H: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Zᵀ H Z (into ``out`` when given, e.g. the Jacobian's columns)."""
        free, touched, block = self._split
        out = np.empty((self.size, self.size)) if out is None else out
        n = free.size
        _take(H, free, out)
        side = H[np.ix_(free, touched)] @ block
        out[:n, n:], out[n:, :n] = side, side.T
        out[n:, n:] = block.T @ H[np.ix_(touched, touched)] @ block
        return out


@njit(cache=True)
def _take(H, index, out):
    """out[:k, :k] = H[index][:, index] (k = index.size; one pass, no index arrays of k² entries)."""
    k = index.size
    for i in range(k):
        row = H[index[i]]
        for j in range(k):
            out[i, j] = row[index[j]]
