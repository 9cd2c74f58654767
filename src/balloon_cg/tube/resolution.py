"""A tube's bulge branch held to the resolution policy: retraced at a higher degree where a point is not resolved.

The interval basis is one Legendre series over the whole tube, so a branch is traced at one degree: where a point's
Legendre tail (galerkin/interval.IntervalDiscretisation.tail) passes ``max_error`` the trace stops there
(IntervalStop.UNRESOLVED, tube/bulge.py: that point is not stored) and the primary branch and the bulge branch are
traced again from the onset at the degree grown by the policy's factor (analysis/branches/resolution.Resolution: 1.5,
up to ``max_degree``), until the branch reaches its stop resolved or the degree is ``max_degree``: then the branch
is returned as traced there, stopped with IntervalStop.UNRESOLVED at its last resolved point, its message naming
max_degree. Every stored point has its tail (``IntervalBranch.tail``) at most max_error.

``balloon-cg run`` traces the bulge branch so where the scene asks for it (``solver.tube_resolution = "refine"``,
``traced_bulge``), on spectral elements refined until every point is resolved where it says "elements"
(tube/front.py: the front resolved, which one series is not); by default ("flag") at the scene's degree, with
every point stored and those past max_error counted by ``inspect``.
"""
from dataclasses import replace

from .bulge import bulge_branch
from .front import front_bulge
from .primary import primary_branch
from ..analysis.results import IntervalStop
from ..analysis.branches.resolution import Resolution
from ..galerkin.interval import Mirror
from ..numerics.continuation import Stop

REFINE = "refine"  # solver.tube_resolution: the bulge branch retraced until resolved (scene/tables.TUBE_RESOLUTIONS)
ELEMENTS = "elements"  # solver.tube_resolution: an odd branch point's branch on refined spectral elements (front.py)


def traced_bulge(scene, primary, point, **trace) -> tuple:
    """(primary, point, bulge) of ``run``: the bulge branch switched at ``point`` of ``primary`` (tube/bulge.
    bulge_branch, ``trace`` its stop_volume, step, stop_stretch), at the primary's degree with every point stored
    (solver.tube_resolution "flag"), or held to the scene's policy (``refined_bulge``: "refine"), the primary branch
    and its branch point then the ones of the degree the bulge was resolved on, or on spectral elements refined
    until resolved ("elements": tube/front.front_bulge; the primary branch kept) (an even branch point's branch
    is traced as by "flag")."""
    if scene.solver.tube_resolution == REFINE and point.block == Mirror.ODD:
        return refined_bulge(scene, primary, point, **trace)
    if scene.solver.tube_resolution == ELEMENTS and point.block == Mirror.ODD:
        return primary, point, front_bulge(scene, primary, point, **trace)
    return primary, point, bulge_branch(scene, primary, point, **trace)


def refined_bulge(scene, primary, point, policy: Resolution | None = None, **trace) -> tuple:
    """(primary, point, bulge): the bulge branch switched at ``point``, an odd branch point of ``primary``, with every stored
    point resolved to ``policy.max_error`` (None: the scene's solver.max_error and max_degree), the primary branch
    traced again at the grown degree where it stops unresolved below max_degree and the bulge switched at its odd
    branch point nearest ``point`` in P (the same onset at a finer degree: module docstring); ``trace``:
    tube/bulge.bulge_branch's stop_volume, step, stop_stretch."""
    policy = Resolution.of(scene) if policy is None else policy
    while True:
        branch = bulge_branch(scene, primary, point, max_error=policy.max_error, **trace)
        degree = primary.disc.degree
        if branch.stop.code != IntervalStop.UNRESOLVED:
            return primary, point, branch
        if degree >= policy.max_degree:
            message = f"{branch.stop.message} = solver.max_degree: raise it or solver.max_error"
            return primary, point, replace(branch, stop=Stop(branch.stop.code, message))
        finer = primary_branch(scene, policy.grow(degree))
        onsets = finer.branch_points(Mirror.ODD)
        if not onsets:
            return primary, point, branch
        primary, point = finer, min(onsets, key=lambda s: abs(s.pressure - point.pressure))


def resolved_bulge_branch(scene, stop_volume: float | None = None, step: float | None = None,
                          policy: Resolution | None = None) -> tuple:
    """(primary, bulge) of a tube scene, the bulge switched at the primary branch's first odd branch point and every
    stored point resolved to ``policy.max_error`` (``refined_bulge``), from solver.degree; ``stop_volume`` and
    ``step``: tube/bulge.bulge_branch's. The bulge is None where the primary branch has no odd branch point (up to
    continuation.stop_stretch)."""
    primary = primary_branch(scene, scene.solver.degree)
    onsets = primary.branch_points(Mirror.ODD)
    if not onsets:
        return primary, None
    primary, _, bulge = refined_bulge(scene, primary, onsets[0], policy, stop_volume=stop_volume, step=step)
    return primary, bulge
