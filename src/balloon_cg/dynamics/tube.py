"""Natural frequencies of a tube's states (m = 0; MODEL.md §11, docs/dynamics.md "Tubes").

The membrane's kinetic energy over the reference tube, dA = R dS dφ with R = 1, is per 2π
T = ½ ∫_0^L (δρ̇² + δη̇²) dS (the ends and the gas massless), δρ = δλ2 (ρ = λ2 R): the sphere's density
½(R² λ̇2² + η̇²) S' (generated/inertia.py) at the tube's nodes, which hold R' = 0 and R = 1 in the places of cos θ and
sin θ (galerkin/interval.py), S' = 1. Assembled on the interval basis like the Hessian (``tube_mass``: M = Σ_q W_q
Tᵀ m T, the node maps T of u), the small oscillations solve K q̂ = ν M q̂ with Ω² = ν/2 (``pencil``), K the
Hessian ∂R/∂u of the loaded energy per block:

    mirror-symmetric state (the primary branch)   even, even_volume (on δV = 0), odd (δV = 0 there by symmetry)
    other states (the bulge branch)               all, all_volume

the blocks of tube/stability.py (interval.Mirror; a held λ̄ is no unknown). A tube has no m ≥ 1 blocks.
"""
from dataclasses import dataclass, replace

import numpy as np

from ..analysis.results import Kind
from ..galerkin.equilibrium import Equilibrium, Parameters
from ..galerkin.interval import IntervalDiscretisation, Mirror
from ..model.meridian import mass_density
from ..numerics import eigen, interrupt
from ..tube.picture import Stage
from .pencil import PER_EIGENVALUE, table_of

VOLUME = "_volume"  # the suffix of a block under volume control


def tube_mass(eq: Equilibrium) -> np.ndarray:
    """M with uᵀMu = ∫_0^L (δρ² + δη²) dS (module docstring), size × size."""
    disc = eq.disc
    return disc.hessian(mass_density(eq.scene.geometry, "axisymmetric", disc.cos_theta, disc.sin_theta))


def tube_blocks(disc: IntervalDiscretisation, symmetric: bool) -> dict:
    """{block name: (its unknowns, whether on δV = 0)} (module docstring)."""
    if symmetric:
        even = disc.block(Mirror.EVEN)
        return {Mirror.EVEN.value: (even, False), Mirror.EVEN.value + VOLUME: (even, True),
                Mirror.ODD.value: (disc.block(Mirror.ODD), False)}
    return {"all": (disc.free, False), "all" + VOLUME: (disc.free, True)}


def tube_frequencies(eq: Equilibrium, mass: np.ndarray, u, params: Parameters, symmetric: bool,
                     count: int) -> dict:
    """{block: its ``count`` lowest Ω² (ascending)} at the state u at ``params``: ν of K q = ν M q on each block of
    ``tube_blocks``, on gᵀq = 0 (g = ∂Ṽ/∂u = −∂R/∂P) for the volume blocks, each the Ritz value of its computed
    eigenvector (numerics/eigen.lowest_ritz: a dense solve reads ν near zero only to ε ν_max, the layout's highest
    mode: ±3e-11 in Ω² at tube_spom1_L10's fold on elements, the Ritz value ~1e-15)."""
    H = eq.jacobian(u, params)
    g = -eq.parameter_derivative(u, params, "P")
    out = {}
    for name, (index, constrained) in tube_blocks(eq.disc, symmetric).items():
        normals = g[index][None, :] if constrained else eigen.NO_CONSTRAINT
        factor = eigen.GramFactor(mass[np.ix_(index, index)])
        out[name] = PER_EIGENVALUE * eigen.lowest_ritz(H, factor, count, normals, index)
    return out


@dataclass(frozen=True)
class TubeFrequencies:
    """The lowest Ω² of every block at every point of a tube branch, ``omega2[block]`` (points × count), and at its
    located points, ``special[block]`` (located points × count); NaN where a block has fewer modes."""

    omega2: dict
    special: dict
    count: int


def tube_branch_frequencies(scene, branch, count: int = 3) -> TubeFrequencies:
    """``tube_frequencies`` at every point and located point of ``branch`` (tube/results.IntervalBranch), the
    mirror blocks where it is mirror-symmetric (its ``lowest`` per Mirror block is not empty); numerics.interrupt's
    Interrupted before any point once a signal asked for a stop."""
    eq = Equilibrium(scene, branch.disc)
    mass = tube_mass(eq)
    symmetric = bool(branch.lowest)
    names = list(tube_blocks(branch.disc, symmetric))

    def at(u, pressure):
        interrupt.check()
        return tube_frequencies(eq, mass, u, branch.params.with_value("P", float(pressure)), symmetric, count)

    rows = [at(u, P) for u, P in zip(branch.states, branch.pressure)]
    special = [at(s.u, s.pressure) for s in branch.special]
    return TubeFrequencies(table_of(rows, names, count), table_of(special, names, count), count)


def tube_matching_block(special, symmetric: bool) -> str:
    """The block one of whose Ω² vanishes at a located point: a branch point's mirror block (every unknown on a
    branch without mirror symmetry), a fold in P the pressure block, a fold in V the volume block."""
    whole = Mirror.EVEN.value if symmetric else "all"
    if special.kind == Kind.BP:
        return special.block.value if symmetric else "all"
    return whole + (VOLUME if special.kind == Kind.LV else "")


def with_frequencies(scene, picture):
    """``picture`` (tube/picture.TubePicture) with every branch's TubeFrequencies where the scene's [dynamics] asks
    for them (``count`` each), else as it is: also where a signal stopped the picture (they are not computed then:
    a signal ends the work at its next stage, numerics.interrupt). A signal since the last check of the stage before
    (none are computed) or while they are computed stops them at the next point: the branches finished keep theirs,
    the others have none, and the picture is interrupted in the frequencies stage (Stage.FREQUENCIES)."""
    if not scene.dynamics.frequencies or picture.interrupted is not None:
        return picture
    count = scene.dynamics.count
    found = {}
    try:
        interrupt.check()
        for name, branch in picture.branches.items():
            found[name] = tube_branch_frequencies(scene, branch, count)
    except interrupt.Interrupted:
        return replace(picture, frequencies=found, interrupted=Stage.FREQUENCIES)
    return replace(picture, frequencies=found)
