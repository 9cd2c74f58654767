"""A fold in P inside a step whose end point the resolution stop rejects (``surface.branches.follow``).

The paper coil's m = 1 branch (scenes/spom1_paper_coil.toml; its primary traced to a pole stretch of 1.66, just past
the branch point at P = 2.28360: a second of CPU) falls in P, folds at P = 2.2825349 and rises; the step over the
fold ends at a point whose tail exceeds solver.max_error. The basis is refined for that rejected point, the last point
is solved again there and the step taken again from it, the fold located on that one basis. s28-surfsteps refined
the basis for the last point instead, which is resolved: the same basis came back and the step, the fold and the
resolution stop repeated for ever (``balloon-cg run scenes/spom1_paper_coil.toml`` hung)."""
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Block, Kind, StopCode
from balloon_cg.analysis.surface import branches as surface_branches
from balloon_cg.numerics import continuation, workers
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
MAX_POINTS = 8  # the fold lies between points 5 and 6
RUNS = 3 * MAX_POINTS  # continuation runs allowed: each is one step or more, or a refinement (the old code: unbounded)


@pytest.fixture(scope="module")
def folded_branch():
    """(the SurfaceBranch of 8 points, [(unknowns, stop code, points, fold indices)] per continuation run)."""
    scene = load_scene(ROOT / "scenes" / "spom1_paper_coil.toml").with_overrides(
        {"continuation.stop_stretch": 1.66, "surface.branches": "none"})
    primary = analyse(scene).primary
    bp = primary.branch_points()[0]
    assert bp.block == Block.M1_HELD
    runs, trace = [], continuation.trace

    def counted(system, start, *args, **kwargs):
        if len(runs) == RUNS:
            raise AssertionError(f"{RUNS} continuation runs for {MAX_POINTS} points: the trace repeats a step")
        path = trace(system, start, *args, **kwargs)
        runs.append((start.X.size, path.stop.code, len(path.points), [f.index for f in path.folds]))
        return path

    continuation.trace = counted
    try:
        with workers.serial():
            branch = surface_branches.trace_surface(primary, 0, bp, 1.0, "m1_bp0", MAX_POINTS)
    finally:
        continuation.trace = trace
    return branch, runs


def test_a_fold_in_a_rejected_step_is_located_on_the_finer_basis(folded_branch):
    branch, runs = folded_branch
    # the case: a run stopped by the resolution rule with a fold in the step to the point it rejected
    assert any(code == StopCode.RESOLUTION and count - 1 in folds for _, code, count, folds in runs)
    sizes = [n for n, *_ in runs]
    assert sizes == sorted(set(sizes))  # every run on a finer basis than the one before: no step repeated
    assert len(branch.values) == MAX_POINTS and branch.error_estimate.max() <= branch.scene.solver.max_error
    folds = [s for s in branch.special if s.kind == Kind.LP]
    assert len(folds) == 1
    fold = folds[0]
    # P falls to the point before the fold and rises from the one after it; the fold's P below every stored one
    P = branch.values
    assert np.all(np.diff(P[:fold.index + 1]) < 0) and np.all(np.diff(P[fold.index + 1:]) > 0)
    assert fold.X[-1] < P.min()
    # on the branch's final basis: the fold solved again on the hyperplane normal to its tangent (regular at a fold)
    # moves P by less than its error estimate, and its tangent there has dP/ds = 0
    system = surface_branches.SurfaceTrace(branch.scene, branch.basis, branch.params, branch.held).system
    X = system.point(fold.X[:-1], fold.X[-1])
    reference = system.point(branch.coefficients[fold.index + 1] - branch.coefficients[fold.index], 0.0)
    t = continuation.tangent(system, X, reference)
    solver = branch.scene.solver
    again = newton(system.residual, system.jacobian, X, t, t @ X, solver.tol, solver.max_newton)
    assert again.converged
    t_again = continuation.tangent(system, again.x, t, again.factors)
    error = max(1e-9 * abs(fold.X[-1]), branch.error_estimate[fold.index:fold.index + 2].max())
    assert abs(again.x[-1] - fold.X[-1]) <= error  # 4.4e-16 (error: 2.3e-9)
    assert abs(t_again[-1]) < 1e-9  # 7.8e-16 (its neighbours' P: 6.7e-5 and 2.9e-5 above its P)
