"""A tube's bulge branch held to the resolution policy: retraced at a higher degree where a point is not resolved.

The interval basis is one Legendre series over the whole tube, so a branch is traced at one degree: where a point's
Legendre tail (galerkin/interval.IntervalDiscretisation.tail) passes ``max_error`` the trace stops there
(IntervalStop.UNRESOLVED, tube/bulge.py: that point is not stored) and the primary branch and the bulge branch are
traced again from the onset at the degree grown by the policy's factor (analysis/branches/resolution.Resolution: 1.5,
up to ``max_degree``), until the branch reaches its stop resolved or the degree is ``max_degree``: then the branch
is returned as traced there, stopped with IntervalStop.UNRESOLVED at its last resolved point. Every stored point has
its tail (``IntervalBranch.tail``) at most max_error.
"""
from .bulge import bulge_branch
from .primary import primary_branch
from .results import IntervalStop
from ..analysis.branches.resolution import Resolution
from ..galerkin.interval import Mirror


def resolved_bulge_branch(scene, stop_volume: float | None = None, step: float | None = None,
                          policy: Resolution | None = None) -> tuple:
    """(primary, bulge) of a tube scene, the bulge switched at the primary branch's first odd branch point and every
    stored point resolved to ``policy.max_error`` (None: the scene's solver.max_error and max_degree), from
    solver.degree (module docstring); ``stop_volume`` and ``step``: tube/bulge.bulge_branch's. The bulge is None
    where the primary branch has no odd branch point (up to continuation.stop_stretch)."""
    policy = Resolution.of(scene) if policy is None else policy
    degree = scene.solver.degree
    while True:
        primary = primary_branch(scene, degree)
        onsets = primary.branch_points(Mirror.ODD)
        if not onsets:
            return primary, None
        branch = bulge_branch(scene, primary, onsets[0], stop_volume, step, max_error=policy.max_error)
        if branch.stop.code != IntervalStop.UNRESOLVED or degree >= policy.max_degree:
            return primary, branch
        degree = policy.grow(degree)
