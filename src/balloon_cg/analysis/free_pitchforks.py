"""The m = 0 branch points of the free balloon's primary branch in a field without equator symmetry (``picture``'s
``FREE_PRIMARY``): their critical modes, classification and the pear branches born there.

A field whose H² is symmetric about a plane z = h (one coil: its own plane) leaves the free balloon centred there
(the net axial force vanishes), so its primary branch keeps that symmetry and breaks it at pitchforks, which the
general layout sees as zeros of the free blocks of every control (``control_points``: all_free, all_volume_free,
all_gas_free at one point, the pear mode keeping the volume to first order). At each such zero of the pressure
control's block (all_free) the critical mode is the eigenvector of the full second variation (every mode and the
axial translation, Legendre in x at the point's assessed degree) whose eigenvalue is nearest zero; the point is
classified by the reduced energy along it (``bifurcation.classify``, the balloon free) and the pear branch is
traced both ways (``switching.trace_pear``; no reflection maps one onto the other about z = h). The other controls'
zeros at the same point (P within POINT_TOL) take its mode and classification.
"""
from dataclasses import replace

import numpy as np

from . import bifurcation
from .problem import equilibrium_of
from .results import Block, Branch, SpecialPoint, Status
from .stability import SecondVariation, assessed_degrees

SEARCH = 3  # the lowest eigenvalues among which the critical (nearest zero) one is taken
POINT_TOL = 1e-8  # |ΔP| within which another control's zero in the same interval is the same point
FREE_BLOCKS = (Block.ALL_FREE, Block.ALL_VOLUME_FREE, Block.ALL_GAS_FREE)


def critical(branch: Branch, bp: SpecialPoint) -> SpecialPoint:
    """``bp`` (a zero of the all_free block) with its critical mode (module docstring) and classification."""
    degrees = assessed_degrees(branch)
    degree = max(degrees[bp.index], degrees[min(bp.index + 1, len(degrees) - 1)])
    variation = SecondVariation(equilibrium_of(branch), degree, basis="legendre")
    u, params, every = bp.X[:-1], branch.params_at(bp.X), np.arange(variation.basis.size)
    values, vectors = bifurcation.eigenpairs(variation, u, params, every, SEARCH)
    mode = vectors[:, int(np.argmin(np.abs(values)))]
    return bifurcation.classify(branch, replace(bp, mode=mode))


def classified(branch: Branch) -> list[tuple[int, SpecialPoint]]:
    """The free primary branch's special points with its m = 0 branch points classified (module docstring), in
    place; returns (number among the branch's m = 0 branch points, point) of each located all_free zero: the
    pitchforks whose branches are traced (an approximate one, whose chord corrector failed near the singular point,
    is left as it is: flagged by the verdict)."""
    points = {id(s): critical(branch, s) for s in branch.special
              if s.block == Block.ALL_FREE and s.status == Status.LOCATED}
    same = {}
    for s in branch.special:
        if s.block in FREE_BLOCKS[1:]:
            match = next((points[id(p)] for p in branch.special if id(p) in points and p.index == s.index
                          and abs(p.X[-1] - s.X[-1]) <= POINT_TOL), None)
            if match is not None:
                same[id(s)] = replace(s, mode=match.mode, E=match.E, classification=match.classification)
    branch.special = [points.get(id(s)) or same.get(id(s)) or s for s in branch.special]
    m0 = [s for s in branch.branch_points() if s.m == 0]
    return [(n, s) for n, s in enumerate(m0) if s.block == Block.ALL_FREE and s.status == Status.LOCATED]
