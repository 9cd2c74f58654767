"""A fold candidate at a pear branch's rejoin is the primary branch's branch point (analysis/switching/pear.py).

SPOM1 at M = 0: the isola leaves the sphere at its first pear point and rejoins it at the second, both closed
forms (sphere_modes.bifurcation_pressures). P is even in the pear amplitude there, so a step across the rejoin
(from the pear branch's last point to the mirror branch's, the state reflected) brackets an extremum of P: a
fold candidate in that interval is the second pear point, LOCATED at its closed-form pressure; a fold candidate
elsewhere, or one whose bracket is far from the branch point, stays a fold.
"""
from dataclasses import replace

import numpy as np
import pytest

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Block, Classification, Kind, SpecialPoint, Status
from balloon_cg.analysis.switching.pear import mark_rejoin, rejoin_fold
from balloon_cg.model.sphere_modes import bifurcation_pressures
from balloon_cg.scene import parse_scene
from balloon_cg.scene.materials import get_preset


@pytest.fixture(scope="module")
def isola():
    scene = parse_scene('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 6.0\n', name="spom1")
    picture = analyse(scene)
    branches = {b.name: b for b in picture.branches}
    return picture, branches["pear_0"], branches["pear_0_mirror"]


def across_the_rejoin(pear, mirror):
    """The pear branch with one more point: the mirror branch's last one (the reflected state), so that its last
    interval crosses the primary branch; a fold candidate (APPROXIMATE) in that interval."""
    X = np.vstack([pear.X, mirror.disc.transfer(mirror.X[-1], pear.disc)])
    last = len(X) - 2
    fold = SpecialPoint(Kind.LP, last, X[-1], status=Status.APPROXIMATE, uncertainty=0.1, reason="root search")
    return replace(pear, X=X, special=[fold])


def test_fold_at_the_rejoin_is_the_branch_point(isola):
    picture, pear, mirror = isola
    assert pear.rejoins == 1
    bp = picture.branch_points[1]
    _, closed_form = bifurcation_pressures(get_preset("SPOM1"), 1, lam_max=6.0)
    assert np.abs(closed_form - bp.X[-1]).min() <= 1e-8
    crossed = across_the_rejoin(pear, mirror)
    P = crossed.pressure[-2:]
    assert bp.X[-1] < P.min() or bp.X[-1] > P.max()  # an extremum of P: not bracketed in P
    mark_rejoin(crossed, picture.primary, bp)
    (s,) = crossed.special
    assert (s.kind, s.block, s.status, s.index) == (Kind.BP, Block.ODD_HELD, Status.LOCATED, len(crossed.X) - 2)
    assert s.classification == bp.classification != Classification.NONE
    assert s.X[-1] == bp.X[-1]
    assert crossed.pole_values(s.X)["lam2_top"][0] == pytest.approx(
        picture.primary.pole_values(bp.X)["lam2_top"][0], abs=1e-9)


def test_other_fold_candidates_stay_folds(isola):
    picture, pear, mirror = isola
    crossed = across_the_rejoin(pear, mirror)
    primary = picture.primary
    start = primary.disc.transfer(picture.branch_points[0].X, crossed.disc)
    rejoin = primary.disc.transfer(picture.branch_points[1].X, crossed.disc)
    assert rejoin_fold(crossed, crossed.special[0], rejoin)
    assert not rejoin_fold(crossed, crossed.special[0], start)  # the bracket is far from the other pear point
    middle = replace(crossed.special[0], index=len(pear.X) // 2)  # no sign change of the amplitude there
    assert not rejoin_fold(crossed, middle, rejoin)
    kept = replace(crossed, special=[middle])
    mark_rejoin(kept, primary, picture.branch_points[1])
    assert kept.special == [middle]
