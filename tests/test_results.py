"""Results are plain data: a Branch pickles as its arrays and metadata (no solver), the solver objects are rebuilt
from it and give the same residuals; special points and stops are typed."""
import pickle

import numpy as np
import pytest

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.results import Block, Classification, Kind, Status, StopCode
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.scene import parse_scene

SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 2.0\n'


@pytest.fixture(scope="module")
def picture():
    return analyse(parse_scene(SCENE, "small"))


def test_branch_pickles_as_plain_data(picture):
    branch = picture.primary
    text = pickle.dumps(branch)
    arrays = sum(a.nbytes for a in (branch.X, branch.iterations, branch.residual, branch.error_estimate,
                                    branch.degree, *(s.X for s in branch.special)))
    arrays += sum(v.nbytes for a in branch.stability for v in a.blocks.values())
    arrays += sum(s.mode.nbytes for s in branch.special if s.mode is not None)
    # arrays + metadata: a pickled Discretisation is its five defining fields, not its tables
    assert len(text) < 1.5 * arrays + 8000
    assert len(pickle.dumps(branch.disc)) < 200
    assert not any(isinstance(v, Equilibrium) for v in vars(branch).values())
    copy = pickle.loads(text)
    np.testing.assert_array_equal(copy.X, branch.X)
    assert copy.disc == branch.disc and copy.legs == branch.legs and copy.stop_reason == branch.stop_reason


def test_solver_rebuilt_from_a_result_gives_its_residuals(picture):
    branch = pickle.loads(pickle.dumps(picture.primary))
    eq = equilibrium_of(branch)
    for X in branch.X[::10]:
        residual = eq.residual(X[:-1], branch.params.with_value("P", X[-1]))
        assert np.abs(residual).max() < 1e-9


def test_special_points_and_stops_are_typed(picture):
    branch = picture.primary
    assert [s.kind for s in branch.special] == [Kind.EP, Kind.LP, Kind.BP, Kind.EP]
    bp = branch.branch_points()[0]
    assert (bp.classification, bp.block, bp.status) == (Classification.PITCHFORK_SUPER, Block.ODD_HELD,
                                                         Status.LOCATED)
    assert bp.mode is not None and np.isfinite(bp.E).all()
    assert [leg.label for leg in branch.legs] == ["up", "down"]
    assert [leg.stop.code for leg in branch.legs] == [StopCode.STOP_STRETCH, StopCode.MIN_STRETCH]
    assert branch.special[-1].stop.code == StopCode.STOP_STRETCH
    pear = picture.branches[1]
    assert pear.parent == ("primary", 0) and pear.legs[0].label == "forward"
