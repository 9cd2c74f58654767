"""Crossings of the second variation's eigenvalues, and a perturbation degree per point that resolves them.

A crossing (``sign_changes``) is an eigenvalue μ_k (from the lowest, k = 0) of a block that changes sign
between neighbouring points n and n + 1: where the branch-point searches (``bifurcation``: the blocks odd_held,
even and odd_free of an equator-symmetric branch; ``azimuthal_points``: the blocks m<m>_held/free) look for a branch
point. At a bracketing point assessed at perturbation degree N, μ_k is *resolved* (``resolved``) when its value
at the check degree N' (``stability.check_degree``: 2N, at solver.max_degree the coarser N/1.5) agrees with it
in sign and to half its size,

    sign μ_k(N) = sign μ_k(N'),   |μ_k(N) − μ_k(N')| < ½ |μ_k(N)|.

``follow_modes`` makes the degree follow the mode: a bracketing point whose crossing eigenvalue is not resolved
is re-assessed at N' (which replaces its assessment) and checked again, until it is resolved or N' can grow no
further. Raising a point's degree can remove the sign change (a spurious crossing: the under-resolved eigenvalue
had the wrong sign) or create one with a neighbour, which is checked in turn, so the refinement walks along the
branch as far as the mode is under-resolved. A crossing that survives is a converged sign change (the searches
locate it at the raised degree); one whose points stay unresolved at solver.max_degree is reported by
``stability.convergence_problems`` (the branch point is APPROXIMATE). Where every crossing is resolved at N the
cost is one assessment at N' per bracketing point, which the flags check of ``stability.assess_branch`` reuses.
"""
from dataclasses import dataclass

import numpy as np

from ..results import Block

RESOLVED_SHARE = 0.5  # a resolved eigenvalue moves by less than this share of itself from N to the check degree


def resolved(coarse: float, fine: float) -> bool:
    """Whether an eigenvalue at degree N (``coarse``) is resolved against its value at the check degree (``fine``):
    the same sign and |coarse − fine| < RESOLVED_SHARE·|coarse| (module docstring)."""
    return bool(np.sign(coarse) == np.sign(fine) and abs(coarse - fine) < RESOLVED_SHARE * abs(coarse))


def sign_changes(assessments, block: str) -> list[tuple[int, int]]:
    """(n, k) for every eigenvalue μ_k of ``block`` that changes sign between points n and n + 1: the number of
    negative ones among the block's lowest eigenvalues goes from a to b, and k runs over min(a, b)..max(a, b) − 1
    (none when the assessments do not hold the block)."""
    if not assessments or block not in assessments[0].blocks:
        return []
    return count_changes([int(np.sum(a.blocks[block] < 0)) for a in assessments])


def count_changes(negative) -> list[tuple[int, int]]:
    """(n, k) for every eigenvalue μ_k (ascending, from 0) that changes sign between points n and n + 1, from the
    number of negative eigenvalues at each point (``negative``): k runs over min(a, b)..max(a, b) − 1 where it goes
    from a to b."""
    return [(n, k) for n in range(len(negative) - 1)
            for k in range(min(negative[n], negative[n + 1]), max(negative[n], negative[n + 1]))]


def branch_point_crossings(assessments, m_max: int, folds=frozenset()) -> list[tuple[int, Block, int]]:
    """(n, block, k) of every crossing a branch-point search reads, ordered by n: the pear and the even block
    (the even block's crossing at a fold in P, an interval in ``folds``, is the fold, not a branch point:
    ``bifurcation.detect``), the pear block of a free balloon in a field (odd_free: the translation included),
    then the azimuthal blocks m = 1..m_max, held then free (``azimuthal_points``)."""
    events = [(n, block, k) for block in (Block.ODD_HELD, Block.EVEN, Block.ODD_FREE)
              for n, k in sign_changes(assessments, block) if not (block == Block.EVEN and n in folds)]
    events += [(n, block, k) for m in range(1, m_max + 1) for block in (Block.azimuthal(m, True),
                                                                          Block.azimuthal(m, False))
               for n, k in sign_changes(assessments, block)]
    return sorted(events, key=lambda event: event[0])


@dataclass
class Followed:
    """What ``follow_modes`` returns: the assessments (some at raised degrees), their degrees, and the
    assessments it computed at the check degree of each point's final degree (point index -> Assessment)."""

    assessments: list
    degrees: list
    checked: dict


def follow_modes(assessments, degrees, assess, check_degree, crossings) -> Followed:
    """Raise the perturbation degree of the bracketing points of every crossing until its eigenvalue is resolved
    there or the check degree is no finer (module docstring). ``assess(n, N)``: the Assessment of point n at
    degree N; ``check_degree(N)``: the degree N is checked against; ``crossings(assessments)``: the (n, block, k)
    to resolve (``branch_point_crossings``)."""
    assessments, degrees = list(assessments), [int(N) for N in degrees]
    checked, settled = {}, set()  # settled: (point, block, k) resolved, or not refinable, at the point's degree
    while True:
        open_ = [(p, block, k) for n, block, k in crossings(assessments) for p in (n, n + 1)
                 if (p, block, k) not in settled]
        if not open_:
            return Followed(assessments, degrees, checked)
        p, block, k = open_[0]
        finer = check_degree(degrees[p])
        if p not in checked:
            checked[p] = assess(p, finer)
        if finer <= degrees[p] or resolved(assessments[p].blocks[block][k], checked[p].blocks[block][k]):
            settled.add((p, block, k))
            continue
        assessments[p], degrees[p] = checked.pop(p), finer
        settled = {s for s in settled if s[0] != p}
