"""A surface branch's stored error estimates are those of the bases its points were traced on.

A branch refined along its trace stores every point on its final basis; a state of a coarser basis has a tail of
zeros there, so an estimate read on the final basis alone would claim an accuracy the point never had (SPOM1's
m = 1 branch from degree 4: points traced at degree 12 read 1.3e-14 on degree 20 against up to 6.7e-11 on their
own basis). The branch here (SPOM1 at M = 0, its pear point read as an m = 1 point, the pear branch turned by 90°)
starts at `[surface] degree` 4 and is refined twice within 12 points. The same branch shows a refinement carrying the
point the resolution stop rejected to the finer basis as the branch's next point (``surface.branches.follow``)."""
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Block
from balloon_cg.analysis.surface import branches as surface_branches
from balloon_cg.numerics import workers
from balloon_cg.scene import load_scene
from balloon_cg.surface.measures import tail

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def refined_branch():
    """(the SurfaceBranch, [(degree of the basis a point was traced on, its tail there)] per stored point, [(the
    rejected point's degree and X, the finer degree and the point solved there)] per refinement)."""
    scene = load_scene(ROOT / "scenes" / "spom1.toml").with_overrides(
        {"continuation.stop_stretch": 2.0, "surface.branches": "none", "surface.degree": 4})
    primary = analyse(scene).primary
    bp = replace(primary.branch_points()[0], m=1, block=Block.M1_HELD)
    own, carried, collected, carry = [], [], surface_branches.collected, surface_branches._carried

    def spied(trace, segments, folds, stop):
        own.extend((t.basis.degree, tail(t.basis, c)) for t, c in surface_branches.traced_points(segments))
        return collected(trace, segments, folds, stop)

    def carrying(trace, point, rejoin, stop):
        moved = carry(trace, point, rejoin, stop)
        carried.append((trace.basis.degree, point.X, moved[0].basis.degree, moved[1].X))
        return moved

    surface_branches.collected, surface_branches._carried = spied, carrying
    try:
        with workers.serial():
            branch = surface_branches.trace_surface(primary, 0, bp, 1.0, "m1", 12)
    finally:
        surface_branches.collected, surface_branches._carried = collected, carry
    return branch, own, carried


def test_each_point_keeps_the_estimate_of_the_basis_it_was_traced_on(refined_branch):
    branch, own, _ = refined_branch
    degrees = [d for d, _ in own]
    assert len(set(degrees)) >= 2 and degrees[-1] == branch.basis.degree  # refined along the trace
    assert len(own) == len(branch.error_estimate)
    for (degree, estimate), stored in zip(own, branch.error_estimate):
        assert stored >= estimate
    # the coarse points' tails are far above what their coefficients read on the final basis: the case that matters
    coarse = [k for k, d in enumerate(degrees) if d < branch.basis.degree]
    on_final = np.array([tail(branch.basis, branch.coefficients[k]) for k in coarse])
    assert max(own[k][1] / max(f, 1e-300) for k, f in zip(coarse, on_final)) > 100.0
    assert branch.error_estimate.max() <= branch.scene.solver.max_error


def test_a_refinement_carries_the_rejected_point_as_the_next_one(refined_branch):
    """At each refinement the point the resolution stop rejected (converged on the coarse basis, its tail above
    max_error) is solved on the finer basis and stored as the next point: no step is repeated from the last point
    re-solved; its P moves by less than 1e-6 on the way."""
    branch, own, carried = refined_branch
    assert len(carried) >= 2
    degrees = [d for d, _ in own]
    for coarse, X, fine, solved in carried:
        assert fine > coarse
        n = int(np.flatnonzero(branch.values == solved[-1])[0])  # stored as it was solved
        assert degrees[n] == fine
        # the point before it kept on the coarse basis, but the first point off the branch point (no stop rule
        # checked its tail), solved again with it where its tail is above max_error
        assert degrees[n - 1] == coarse or (n == 2 and own[1][1] <= branch.scene.solver.max_error)
        assert abs(solved[-1] - X[-1]) < 1e-6
