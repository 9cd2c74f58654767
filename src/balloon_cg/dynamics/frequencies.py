"""Natural frequencies of an equilibrium per second-variation block (MODEL.md §11, docs/dynamics.md).

Small oscillations solve K q̂ = ν M q̂ per block, M the mass matrix of the membrane's kinetic energy
(generated/inertia.py), and the dimensionless frequency Ω = ω R0 √(ρ/μ) has Ω² = ν/2 (``pencil``).

K is the block's matrix under the scene's control: pressure, the Hessian H; volume, H on the perturbations that
keep the volume (gᵀq = 0, g = ∂Ṽ/∂q: the constrained subspace); gas, H + (P/Ṽ) g gᵀ (its stiffness); held or free
(analysis/stability/axisymmetric.py: the same blocks and names as the stability assessment). M is the displacement norm of the
stability blocks, so ν are their eigenvalues on that norm (``SecondVariation(norm="displacement")`` for m = 0,
``AzimuthalBasis.gram`` for m ≥ 1): one assembly, one reduction to a standard matrix (``numerics.eigen``) per block.
Ω² < 0 is an unstable mode (kept as such).
"""
from dataclasses import dataclass, replace

import numpy as np

from ..analysis.stability.azimuthal import merged_lowest
from ..analysis.picture import stopped
from ..analysis.branches.problem import equilibrium_of
from ..analysis.results import Block, Branch, Gauge, Kind, Origin, SurfaceBranch
from ..analysis.stability.axisymmetric import SecondVariation, assessed_degrees, assessment_cost, first_of_each
from ..analysis.timing import Step
from ..galerkin.profiles import theta_grid
from ..numerics import interrupt, workers
from ..numerics.threads import limited_blas
from .modes import COMPONENTS, block_modes
from .pencil import FOLD_CONTROL, MASS_NORM, PER_EIGENVALUE, mass_variation, table_of
from .surface import surface_frequencies
from .translation import DIRECTIONS, translation_omega2


def frequencies(variation: SecondVariation, u, params, symmetric: bool, m_max: int = 0, count: int = 3) -> dict:
    """{block name: its ``count`` lowest Ω² (ascending)} at the equilibrium u (unknowns of the variation's
    equilibrium) at ``params``: the m = 0 blocks of the control modes and, m = 1..m_max, 'm<m>_held' (and
    'm<m>_free' with a field) (``SecondVariation.blocks``)."""
    if variation.norm != MASS_NORM:
        raise ValueError(f"frequencies need the mass matrix as the Gram matrix (norm {MASS_NORM!r}), "
                         f"not {variation.norm!r}")
    return {name: PER_EIGENVALUE * merged_lowest(parts, count)
            for name, parts, _ in variation.blocks(u, params, symmetric, m_max)}


@dataclass(frozen=True)
class BranchFrequencies:
    """The lowest Ω² of every block at every point of a branch: ``omega2[name]`` (points × count), NaN where a point
    has fewer than ``count`` modes in a block; ``degree`` the perturbation degree per point (``frequency_degrees``);
    ``special[name]`` (special points × count) the same at each special point's own state, at the
    higher degree of the points around it; ``translation[direction]`` (points,) the rigid translations' Ω²
    (translation.translation_omega2: 0 without a field, else > 0 restored, < 0 pulled); ``modes[name]``
    (special points × count × 3 × θ, NaN where fewer modes) the mode shapes of ``special`` on ``theta``
    (modes.block_modes: δρ, δz, δφ over R0 for a unit modal mass), or None when not asked for."""

    omega2: dict
    degree: np.ndarray
    special: dict
    translation: dict
    count: int
    m_max: int
    modes: dict | None = None
    theta: np.ndarray | None = None


@limited_blas
def branch_frequencies(branch, count: int = 3, m_max: int = 0, symmetric: bool | None = None,
                       copied: "BranchFrequencies | None" = None, modes: bool = False) -> BranchFrequencies:
    """``frequencies`` and ``translation_omega2`` at every point of ``branch`` (on every core:
    ``numerics.workers.spread``, as the stability assessment; one BLAS thread: ``numerics.threads``), and
    ``frequencies`` at each special point's own state (at the higher degree of the points around it), each point
    at ``frequency_degrees``; with ``modes`` the special points' mode shapes too (``modes.block_modes`` on the
    run's θ grid, scene.output.theta_points). ``copied``: the
    points' values of the branch this one is the mirror image of (the energy is invariant under the reflection:
    every block's spectrum and the translations' are the same), so that only its special points are computed."""
    symmetric = branch.disc.symmetric if symmetric is None else symmetric
    eq = equilibrium_of(branch)
    degrees = frequency_degrees(branch)
    variations = {}
    theta = theta_grid(branch.scene.output.theta_points) if modes else None

    def variation_at(N):
        return variations.get(N) or variations.setdefault(N, mass_variation(eq, N))

    def at(X, N):
        interrupt.check()
        return frequencies(variation_at(N), X[:-1], branch.params_at(X), symmetric, m_max, count)

    def point(n):
        X, N = branch.X[n], int(degrees[n])
        return at(X, N), translation_omega2(variation_at(N), X[:-1], branch.params_at(X))

    def shapes(s, blocks):
        interrupt.check()
        variation = variation_at(int(degrees[s.index:s.index + 2].max()))
        return {name: block_modes(variation, s.X[:-1], branch.params_at(s.X), symmetric, name, count, theta)[1]
                for name in blocks}

    special = [at(s.X, int(degrees[s.index:s.index + 2].max())) for s in branch.special]
    shaped = {} if modes else None
    if modes:
        per_point = [shapes(s, row) for s, row in zip(branch.special, special)]
        for name in dict.fromkeys(name for row in special for name in row):
            shaped[name] = np.full((len(special), count, len(COMPONENTS), theta.size), np.nan)
            for n, row in enumerate(per_point):
                if name in row:
                    shaped[name][n, :len(row[name])] = row[name]
    if copied is not None:
        return replace(copied, special=table_of(special, list(copied.omega2), count), modes=shaped, theta=theta)
    results = workers.spread(point, range(len(branch.X)), [assessment_cost(N, m_max) for N in degrees],
                             here=first_of_each(degrees))
    rows = [row for row, _ in results]
    names = list(dict.fromkeys(name for row in rows for name in row))
    translation = {direction: np.array([rigid[direction] for _, rigid in results]) for direction in DIRECTIONS}
    return BranchFrequencies(table_of(rows, names, count), degrees, table_of(special, names, count), translation,
                             count, m_max, shaped, theta)


def frequency_degrees(branch) -> np.ndarray:
    """The perturbation degree per point: its stability assessment's (``assessed_degrees``), at least the Legendre
    degree of a branch stored in x (its basis holds the equilibrium and its Jacobian: a located fold's or branch
    point's null vector is in it; at the default stability.degree 20 a pear branch of degree 90 leaves that
    eigenvalue ~1e-3 from zero); a mapped branch's assessed degrees hold its points already."""
    degrees = np.array(assessed_degrees(branch), dtype=int)
    return degrees if branch.disc.mapping is not None else np.maximum(degrees, branch.disc.degree)


def matching_block(special, branch) -> str | None:
    """The block one of whose Ω² vanishes at a special point of ``branch``: a branch point's own block (on a branch
    without equator symmetry an even or odd block's point, e.g. a pear branch's rejoin at the primary's pitchfork,
    is in all modes of its reading: all_held, all_free); a fold in P (LP), V (LV) or n (LN) the block of the
    equator-symmetric modes under that control (even, even_volume, even_gas), on a branch without that symmetry
    all modes in the branch's reading (all_held, all_volume_free, ...); None for the others (TP, EP, UZ: no
    stability change)."""
    free = branch.gauge == Gauge.FREE
    if special.kind == Kind.BP:
        block = special.block
        if branch.disc.symmetric or block.m or block.value.startswith("all"):
            return block.value
        free = block == Block.ODD_FREE or (block == Block.EVEN and free)
        return f"all_{'free' if free else 'held'}"
    if special.kind not in FOLD_CONTROL:
        return None
    control = FOLD_CONTROL[special.kind]
    if branch.disc.symmetric:
        return f"even{control}"
    return f"all{control}_{'free' if free else 'held'}"


def attach(branches, count: int, m_max: int, modes: bool = False) -> None:
    """``branch.frequencies`` of every branch: ``branch_frequencies`` of an axisymmetric one (with the special points'
    mode shapes if ``modes``), ``surface.surface_frequencies`` of an assessed surface branch (its sectors' Ω²; one
    whose assessment a signal stopped is left without), a reflected image's points copied from its source."""
    done = {}
    for branch in branches:
        source = done.get(branch.reflection_of) if branch.origin == Origin.REFLECTED else None
        if isinstance(branch, Branch):
            branch.frequencies = branch_frequencies(branch, count, m_max, copied=source, modes=modes)
        elif isinstance(branch, SurfaceBranch) and branch.sectors is not None:
            branch.frequencies = surface_frequencies(branch, count, copied=source)
        done[branch.name] = branch.frequencies


def attach_to(picture, dynamics) -> None:
    """``attach`` to the branches and surface branches of ``picture`` (analysis.picture.Picture), timed
    (Step.FREQUENCIES), when ``dynamics`` (the scene's [dynamics]) asks for them and no signal stopped the work; a
    signal that came before them (after the last check of the flag of the phase then running, or on a picture built
    without ``picture.stopped``: the primary-only trace, ``continue``'s) interrupts the picture in the phase its
    clock ran last, and they are not started; a signal during them stops them at the next point (the branches not
    reached are kept without) and the picture is interrupted in that phase."""
    if not dynamics.frequencies or stopped(picture):
        return
    try:
        with picture.clock.step(Step.FREQUENCIES):
            interrupt.check()
            attach(picture.branches + picture.surface_branches, dynamics.count, dynamics.m_max, dynamics.modes)
    except interrupt.Interrupted:
        stopped(picture)
