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

The general layout's chord corrector is singular at such a pitchfork (the pear mode, odd about z = h, is a null
vector of the Jacobian on every chord), and the root search may fail inside its bracket: the point is then
APPROXIMATE (on the one coil's free branch traced to λ2(0) = 1.7, 1.72 or 1.74: P = 2.2464763, 3e-5 off). Where the
coils pair up about the plane z = h (``symmetry_plane``) the free balloon's branch is the branch of the scene
moved down by h, which is equator-symmetric, moved up (``symmetric_scene``): there the pitchfork of the free reading
(odd_free) is located by the symmetric solver's extended system (``bifurcation.locate``) and its state moved up by
h onto the free branch's discretisation (``located_by_symmetry``), for the zero of every control's free block in
that interval (the pear mode keeps the volume).
"""
from dataclasses import replace

import numpy as np

from . import branch_points as bifurcation
from ..branches.primary import trace_primary
from ..branches.problem import equilibrium_of
from ..results import Block, Branch, SpecialPoint, Status
from ..stability.axisymmetric import SecondVariation, assess_branch, assessed_degrees

SEARCH = 3  # the lowest eigenvalues among which the critical (nearest zero) one is taken
POINT_TOL = 1e-8  # |ΔP| within which another control's zero in the same interval is the same point
FREE_BLOCKS = (Block.ALL_FREE, Block.ALL_VOLUME_FREE, Block.ALL_GAS_FREE)
PLANE_TOL = 1e-12  # |h_i + h_j − 2h| within which two coils pair up about the plane z = h


def symmetry_plane(coils) -> float | None:
    """The height h of the plane about which the coaxial ``coils`` pair up: each (a, h_i, s) has a partner
    (a, 2h − h_i, ±s), one sign rule for all (as ``Field.is_equator_symmetric`` about z = 0), so H² is even in
    z − h; None without one."""
    if not coils or not all(c.is_coaxial for c in coils):
        return None
    heights = [c.height for c in coils]
    h = 0.5 * (min(heights) + max(heights))
    signs = set()
    for c in coils:
        partner = next((d for d in coils if d.radius == c.radius and abs(c.height + d.height - 2 * h) <= PLANE_TOL
                        and abs(d.current) == abs(c.current)), None)
        if partner is None:
            return None
        signs.add(partner.current == c.current)
    return h if len(signs) <= 1 else None


def symmetric_scene(scene, h: float):
    """``scene`` moved down by h (every coil's height h_i − h): its field is equator-symmetric when the coils pair
    up about z = h."""
    return scene.with_overrides({f"field.coils[{i}].height": coil.height - h
                                 for i, coil in enumerate(scene.field.coils)}, name=scene.name)


def located_by_symmetry(branch: Branch, points: list[SpecialPoint]) -> dict:
    """{id(point): the point located} for the APPROXIMATE zeros of the free blocks among ``points`` (module
    docstring); {} when the coils pair up about no plane, the moved scene is not equator-symmetric, or its
    odd_free pitchfork in their bracket is not located (they stay APPROXIMATE: the verdict says so)."""
    h = symmetry_plane(branch.scene.field.coils)
    if h is None or not points:
        return {}
    moved = symmetric_scene(branch.scene, h)
    if not moved.field.is_equator_symmetric:
        return {}
    primary = trace_primary(moved)
    primary.stability, _ = assess_branch(primary, moved.stability.degree, True)
    found = [bifurcation.locate(primary, *event) for event in bifurcation.detect(primary, primary.stability)
             if event[1] == Block.ODD_FREE]
    out = {}
    for s in points:
        low, high = sorted((branch.X[s.index, -1], branch.X[s.index + 1, -1]))
        bp = next((bp for bp in found if bp.status == Status.LOCATED and low <= bp.X[-1] <= high), None)
        if bp is None:
            continue
        a, b = branch.disc.split(primary.disc.transfer(bp.X[:-1], branch.disc))
        b[0] += h  # moved up: the constant part of η
        X = np.append(branch.disc.join(a, b), bp.X[-1])
        out[id(s)] = replace(s, X=X, status=Status.LOCATED, reason="", uncertainty=0.0,
                             note=f"located on the scene moved down by {h:g} (equator-symmetric), moved up")
    return out


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
    approximate = [s for s in branch.special if s.block in FREE_BLOCKS and s.status == Status.APPROXIMATE]
    relocated = located_by_symmetry(branch, approximate)
    branch.special = [relocated.get(id(s), s) for s in branch.special]
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
