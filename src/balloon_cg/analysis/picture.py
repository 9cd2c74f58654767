"""The whole picture of a scene: primary branch, stability, branch points, pear branches, snap-through.

``analyse(scene)`` traces the primary branch, assesses every point (``stability``), locates and classifies its
branch points (``bifurcation``), follows each pear-shaped branch both ways (the branch and its mirror image,
north and south poles swapped) until it rejoins the primary branch or stops, assesses those too, and lists the
snap-throughs under pressure control. Every branch carries its assessments in ``branch.stability``.
"""
from dataclasses import dataclass, field

import numpy as np

from . import bifurcation
from .branch import SpecialPoint, trace_primary
from .stability import assess_branch


@dataclass
class Picture:
    branches: list
    branch_points: list = field(default_factory=list)
    snaps: list = field(default_factory=list)  # dicts: from (branch, index, P) to (branch, index)
    unsettled: dict = field(default_factory=dict)  # branch name -> point indices whose flags change at 2N


def _assess(branch, scene, symmetric):
    results, unsettled = assess_branch(branch, scene.stability.degree, symmetric,
                                       check_degree=2 * scene.stability.degree, m_max=scene.stability.m_max)
    branch.stability = results
    branch.unsettled = unsettled
    return unsettled


def analyse(scene, progress=None, pear: bool = True) -> Picture:
    primary = trace_primary(scene, progress=progress)
    picture = Picture([primary])
    picture.unsettled["primary"] = _assess(primary, scene, primary.disc.symmetric)
    if not primary.disc.symmetric:
        return picture
    events = bifurcation.detect(primary, primary.stability)
    for n, (index, block, k) in enumerate(events):
        bp = bifurcation.classify(primary, bifurcation.locate(primary, index, block, k))
        picture.branch_points.append(bp)
        mode = "pear (odd)" if block == "odd_held" else "equator-symmetric (even)"
        primary.special.append(SpecialPoint(bp.kind, index, bp.X, f"{mode} mode, branch point {n}", bp.E))
    primary.special.sort(key=lambda s: s.index)
    if pear:
        _trace_pears(scene, primary, picture, progress)
    picture.snaps = snap_throughs(picture.branches)
    return picture


def _trace_pears(scene, primary, picture, progress):
    """Pear branches from the pear branch points; a branch that rejoins at an already traced point is not repeated."""
    reached = set()
    for n, bp in enumerate(picture.branch_points):
        if bp.block != "odd_held" or n in reached:
            continue
        for sign, suffix in ((1.0, ""), (-1.0, "_mirror")):
            name = f"pear_{n}{suffix}"
            branch = bifurcation.trace_pear(primary, bp, sign, name, progress)
            if branch is None:
                continue
            branch.parent = ("primary", n)
            end = _rejoin_point(primary, branch, picture.branch_points, n)
            if end is not None:
                reached.add(end)
                branch.stop_reason += f" at branch point {end}"
            picture.unsettled[name] = _assess(branch, scene, symmetric=False)
            picture.branches.append(branch)


def _rejoin_point(primary, branch, branch_points, origin):
    """The pear branch point where ``branch`` rejoined the primary branch (nearest in P), if any."""
    if "rejoined" not in branch.stop_reason:
        return None
    P_end = branch.pressure[-1]
    candidates = [(abs(bp.X[-1] - P_end), n) for n, bp in enumerate(branch_points)
                  if n != origin and bp.block == "odd_held"]
    return min(candidates)[1] if candidates else None


def snap_throughs(branches):
    """Under pressure control: where a stable stretch of a branch ends (fold or loss of stability) with P
    increasing, the jump to the lowest-energy stable point at the same P on any branch (or none found)."""
    snaps = []
    for branch in branches:
        stable = np.array([a.stable_pressure for a in branch.stability])
        for i in range(len(stable) - 1):
            if stable[i] and not stable[i + 1]:
                P = branch.pressure[i]
                target = _stable_at(branches, P, exclude=(branch.name, i))
                snaps.append({"from_branch": branch.name, "from_index": i, "pressure": float(P),
                              "to_branch": target[0] if target else "", "to_index": target[1] if target else -1})
    return snaps


def _stable_at(branches, P, exclude):
    best = None
    for branch in branches:
        stable = np.array([a.stable_pressure for a in branch.stability])
        p = branch.pressure
        for i in range(len(p) - 1):
            if (branch.name, i) == exclude or abs(i - exclude[1]) <= 1 and branch.name == exclude[0]:
                continue
            if stable[i] and stable[i + 1] and (p[i] - P) * (p[i + 1] - P) <= 0:
                volume = branch.equilibrium.volume(branch.X[i, :-1])
                if best is None or volume > best[0]:
                    best = (volume, branch.name, i)
    return best[1:] if best else None
