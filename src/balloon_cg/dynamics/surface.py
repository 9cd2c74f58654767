"""Natural frequencies of the states of a surface branch (whole sphere, ``surface``): per symmetry sector and
reading (MODEL.md §8, §11; docs/dynamics.md).

The stability of a surface branch (surface/stability.py) solves H c = μ G c in each symmetry sector of its
SphericalBasis, H the Hessian of the energy per 2π with moduli over μ/2 (the axisymmetric K's units) and
G = (1/2π)∫∫|δu|² dA the displacement norm over the reference, c·c/2π in the orthonormal harmonics on the sphere
(``SphericalBasis.gram``), ``SphericalBasis.mass`` on a spheroid (dA = S' d(cos θ) dφ: surface/stability.py
``mass_factor``). The membrane's kinetic energy per 2π is (ρ T0 R0⁴) ½ (1/2π)∫∫|δu̇|² dA: G is the mass matrix M
of ``pencil``, so each
μ is a ν of K q = ν M q and Ω² = ν/2 (``pencil.PER_EIGENVALUE``), per sector and reading: held or free, under
pressure (H), volume (H on gᵀc = 0) or gas control (H + (P/Ṽ) g gᵀ), the zero modes removed. At an axisymmetric
state the sectors even under the mirror y → −y hold the axisymmetric blocks' modes (m = 0 and the cos mφ family
of every m ≥ 1); the odd ones the sin mφ family (the same Ω² for m ≥ 1) and the torsion δφ(θ) (m = 0, no
axisymmetric block).

The points' values are the assessment's eigenvalues (``SurfaceBranch.sectors``, each point read on the basis it
was traced on: surface_assessment, ``spectrum_count`` of them per sector); each special point's are solved at its
own state on the branch's basis. A block is named '<reading>_<signs>': the reading (held, free, held_volume, …)
and the sector's characters under the basis' reflections (its ``symmetry``, in order) as + and −, e.g.
'held_+-' for the sector odd under the second; '<reading>_all' for a basis without reflections.
"""
from dataclasses import dataclass

import numpy as np

from ..analysis.results import Kind
from ..analysis.surface.assessment import spectrum_count
from ..numerics import interrupt
from ..numerics.threads import limited_blas
from ..surface import stability as surface_stability
from ..surface.equilibrium import SurfaceEquilibrium
from .pencil import FOLD_CONTROL, PER_EIGENVALUE, table_of

READINGS = {r.name: r for r in surface_stability.READINGS}


@dataclass(frozen=True)
class SurfaceFrequencies:
    """The lowest Ω² of every sector and reading of a surface branch: ``omega2[block]`` (points × count), NaN where
    a sector has fewer modes; ``special[block]`` (special points × count) at each special point's own state."""

    omega2: dict
    special: dict
    count: int


def sector_block(reading: str, characters: tuple) -> str:
    """The block name of a sector under a reading (module docstring): 'held_+-', 'free_volume_--', 'held_all'."""
    return f"{reading}_{''.join('+' if c > 0 else '-' for c in characters) or 'all'}"


@limited_blas
def surface_frequencies(branch, count: int, copied: SurfaceFrequencies | None = None) -> SurfaceFrequencies:
    """The frequencies of an assessed surface branch (module docstring); ``copied``: the points' values of the
    branch this one is the image of under a reflection the scene keeps (a sector's perturbations map to the image's
    sector of the same characters, every spectrum the same), so that only its special points are solved. A branch
    whose sectors were read with fewer than ``count`` eigenvalues each: ValueError."""
    if branch.sectors is None:
        raise ValueError(f"{branch.name}: not assessed (no sector spectra); its frequencies need its stability")
    read = spectrum_count(branch.scene)
    if read < count:
        raise ValueError(f"{branch.name}: its sectors were read with {read} eigenvalues each, fewer than count = "
                         f"{count} (the scene's [dynamics] count when it was assessed)")
    readings = tuple(READINGS[name] for name in branch.sectors)
    names = [sector_block(r, key) for r, sectors in branch.sectors.items() for key in sectors]
    eq = SurfaceEquilibrium(branch.scene, branch.basis)
    special = table_of([_at_state(branch, eq, s.X, count, readings) for s in branch.special], names, count)
    if copied is not None:
        return SurfaceFrequencies(copied.omega2, special, count)
    omega2 = {}
    for reading, sectors in branch.sectors.items():
        for key, values in sectors.items():
            table = np.full((len(values), count), np.nan)
            table[:, :min(count, values.shape[1])] = values[:, :count]
            omega2[sector_block(reading, key)] = PER_EIGENVALUE * table
    return SurfaceFrequencies(omega2, special, count)


def _at_state(branch, eq, X, count: int, readings) -> dict:
    """{block: its ``count`` lowest Ω²} at the state X = (c, p) of ``branch`` (``eq`` on its basis)."""
    interrupt.check()
    params = branch.params.with_value(branch.parameter, X[-1])
    spectra = surface_stability.sector_spectra(eq, X[:-1], params, count, readings)
    return {sector_block(r.name, key): PER_EIGENVALUE * values
            for r, sectors in spectra.items() for key, values in sectors.items()}



def surface_matching_block(special, branch) -> str | None:
    """The block one of whose Ω² vanishes at a special point of a surface branch, in the reading of its states
    (held or free): a fold in P, V or n (LP, LV, LN) the state's own sector under that control; a branch point its
    sector (a secondary one's ``sector``, the origin's the state's own: the branch is born along a mode of its own
    invariant subspace) under pressure control; None for the others (EP, UZ: no stability change)."""
    reading = "held" if branch.held else "free"
    if special.kind == Kind.BP:
        return sector_block(reading, special.sector or branch.basis.characters)
    if special.kind not in FOLD_CONTROL:
        return None
    return sector_block(reading + FOLD_CONTROL[special.kind], branch.basis.characters)
