"""The free balloon's pitchfork (the pear block with the axial translation, odd_free) beside the held one, against
AUTO-07p on the same boundary-value problem (issue 27: a uniform mesh of 80 collocation intervals), and the
reading (held, free, both) of every stored point and branch."""
from pathlib import Path

import h5py
import numpy as np
import pytest

from balloon_cg.analysis.points import branch_points as bifurcation
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.results import Block, Classification, Gauge, Kind, SpecialPoint, Status
from balloon_cg.analysis.stability.axisymmetric import SecondVariation, assess_branch
from balloon_cg.analysis.switching.pear import trace_pear
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.io import hdf5
from balloon_cg.io.run_file import read_run, write_run
from balloon_cg.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]

# AUTO-07p (issue 27): the symmetry-breaking branch points of the two-coil scene at M = 0.002, (λ2(0), P)
AUTO = {Block.ODD_HELD: (1.66896, 2.25270), Block.ODD_FREE: (1.68137, 2.23420)}
AUTO_DIGITS = 2e-5  # AUTO's values are given to 5 decimals (its collocation error is below that)


@pytest.fixture(scope="module")
def two_coils():
    """The two-coil primary branch at M = 0.002, assessed (m = 0 blocks), and its located pear points by block."""
    scene = load_scene(ROOT / "scenes" / "spom1_two_coils_M0.002.toml")
    primary = trace_primary(scene)
    primary.stability, primary.unsettled = assess_branch(primary, scene.stability.degree, True, check=True)
    points = {block: bifurcation.locate(primary, index, block, k)
              for index, block, k in bifurcation.detect(primary, primary.stability)}
    return primary, points


def test_the_free_pitchfork_is_located_apart_from_the_held_one(two_coils):
    """Both pear pitchforks are located: at each, the crossing eigenvalue of its own block (odd_held; odd_free,
    the translation included), recomputed at the located point on the plain basis of the extended system, vanishes
    to the solver's tolerance while the other block's does not; (λ2(0), P) within 2e-5 of AUTO-07p's; the free one
    is labelled free, the held one held."""
    primary, points = two_coils
    assert set(points) == {Block.ODD_HELD, Block.ODD_FREE}
    tol = primary.scene.solver.tol
    for block, (lam_auto, p_auto) in AUTO.items():
        bp = points[block]
        assert bp.kind == Kind.BP and bp.status == Status.LOCATED, bp.reason
        assert bp.gauge == (Gauge.HELD if block == Block.ODD_HELD else Gauge.FREE)
        degree = bifurcation.plain_degree(primary, bp.X)
        plain = Discretisation(degree, True, primary.disc.pin_translation)
        X = primary.disc.transfer(bp.X, plain)
        blocks = SecondVariation(Equilibrium(primary.scene, plain), degree).assess(
            X[:-1], primary.params_at(X), True).blocks
        assert np.abs(blocks[block.value]).min() <= 10 * tol
        other = Block.ODD_FREE if block == Block.ODD_HELD else Block.ODD_HELD
        assert np.abs(blocks[other.value]).min() > 1e-4
        lam = primary.pole_values(bp.X)["lam2_top"][0]
        assert abs(lam - lam_auto) <= AUTO_DIGITS and abs(bp.X[-1] - p_auto) <= AUTO_DIGITS
    assert points[Block.ODD_FREE].X[-1] < points[Block.ODD_HELD].X[-1] - 1e-2


def test_the_free_pear_branch_is_traced_with_the_translation_free(two_coils):
    """The free pitchfork is classified like the held one (the reduced energy on the free layout), and its pear
    branch is traced on the general layout with b_0 an unknown (its equation: the net axial force vanishes, not
    a reaction): every point a converged solution of that system, labelled free, leaving the primary branch into
    pear shapes (the pole stretches part by more than 0.5) until the membrane nears a wire."""
    primary, points = two_coils
    bp = bifurcation.classify(primary, points[Block.ODD_FREE])
    assert bp.classification in (Classification.PITCHFORK_SUPER, Classification.PITCHFORK_SUB)
    pear = trace_pear(primary, bp, 1.0, "pear_free_1")
    assert pear is not None and pear.gauge == Gauge.FREE and not pear.disc.pin_translation
    assert len(pear.X) > 10 and pear.residual.max() <= primary.scene.solver.tol
    poles = pear.pole_values()
    assert np.abs(poles["lam2_top"] - poles["lam2_bottom"]).max() > 0.5
    assert abs(pear.X[0, -1] - bp.X[-1]) < 1e-3  # starts at the free pitchfork, not the held one
    held = trace_pear(primary, points[Block.ODD_HELD], 1.0, "pear_0")
    assert held.gauge == Gauge.HELD and held.disc.pin_translation
    assert abs(held.X[0, -1] - pear.X[0, -1]) > 1e-2


def test_readings_are_stored_and_older_files_read_them_from_the_layout(two_coils, tmp_path, capsys, monkeypatch):
    """A run file holds each branch's and each special point's reading (``gauge``); inspect shows them; a file
    written before (no gauge column, no gauge attribute) reads them from the block (a branch point's) and the
    layout (the branch's, and its other points')."""
    from balloon_cg.app.cli import main

    primary, points = two_coils
    primary.special = sorted(points.values(), key=lambda s: s.index) + [
        SpecialPoint(Kind.LP, 1, primary.X[1].copy(), gauge=Gauge.BOTH)]
    path = write_run(tmp_path / "run.h5", primary.scene, [primary])
    branch = read_run(path)["branches"]["primary"]
    assert branch["attrs"]["gauge"] == "both"
    assert {(s["block"], s["gauge"]) for s in branch["special_points"]} == {
        ("odd_held", "held"), ("odd_free", "free"), ("", "both")}
    assert main(["inspect", str(path)]) == 0
    text = capsys.readouterr().out
    assert "equator-symmetric, held and free" in text
    assert "BP free" in text and "BP held" in text
    monkeypatch.setattr(hdf5, "can_checksum", lambda dtype, size: False)  # an older version wrote no checksums
    path = write_run(tmp_path / "old.h5", primary.scene, [primary])
    with h5py.File(path, "r+") as f:  # as written before the free reading
        del f["branches/primary/special_points/gauge"]
        del f["branches/primary"].attrs["gauge"]
    branch = read_run(path)["branches"]["primary"]
    assert branch["attrs"]["gauge"] == "both"
    assert [s["gauge"] for s in branch["special_points"]] == [s.gauge.value for s in primary.special]


def test_the_crossing_eigenvalue_is_followed_by_its_eigenvector():
    """A weak field leaves the free balloon's translation nearly a zero mode (eigenvalue ~1e-3): the pear eigenvalue
    passes it on its way through zero, so by rank the crossing would be read as 1e-3 → −0.03 (and the Newton start
    put at the bracket's start); followed by its eigenvector it is the pear eigenvalue, 0.118 → −0.031."""
    values = [np.array([7.7e-4, 0.118, 2.7]), np.array([-0.031, 7.7e-4, 2.6])]
    translation, pear, other = np.eye(3)
    vectors = [np.stack([translation, pear, other], axis=1), np.stack([pear, translation, other], axis=1)]
    assert bifurcation.followed_crossing(values, vectors, np.eye(3), 0) == (1, 0)
    same = [np.array([0.2, 1.0, 2.0]), np.array([-0.1, 1.1, 2.1])]  # no passing: the rank's own crossing
    assert bifurcation.followed_crossing(same, [np.eye(3), np.eye(3)], np.eye(3), 0) == (0, 0)


def test_the_free_pitchfork_of_a_weak_field_is_located():
    """The single coil of radius 4 (a weak field at the balloon): its free pitchforks, where the pear eigenvalue
    passes the nearly free translation's, are located, within 1e-3 of the held ones in P (relative: the field barely
    couples the translation), each the free block's zero."""
    scene = load_scene(ROOT / "scenes" / "spom1_single_coil.toml")
    primary = trace_primary(scene)
    primary.stability, _ = assess_branch(primary, scene.stability.degree, True, check=True)
    found = [bifurcation.locate(primary, *event) for event in bifurcation.detect(primary, primary.stability)]
    held = [bp for bp in found if bp.block == Block.ODD_HELD]
    free = [bp for bp in found if bp.block == Block.ODD_FREE]
    assert len(free) == len(held) == 2 and all(bp.status == Status.LOCATED for bp in found)
    for h, f in zip(held, free):
        assert abs(h.X[-1] - f.X[-1]) < 1e-3 * h.X[-1] and f.gauge == Gauge.FREE
