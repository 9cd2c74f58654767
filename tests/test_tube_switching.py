"""Branches switched at a tube's branch points other than the first odd one (issue 38): the even branch points of a
uniform primary branch (sliding ends, closed or held apart), tube/bulge.py, and ``run`` switching at every branch
point it can (tube/picture.py).

On a tube of length L with sliding ends (planes of symmetry) the mode cos(2πS/L) of the even block is the mode
cos(πS/(L/2)) of the tube of length L/2 repeated: a state of the branch switched at the even branch point, restricted
to S ∈ [0, L/2], is a state of the tube of length L/2 on the branch switched at its first odd branch point (the bulge
at S = 0, the neck at L/2, where ρ' = 0 by the mirror symmetry), at the same P and V/V0. So the two branches, computed
on different tubes at matching resolution (degree 2N on L, N on L/2), have the same volume fold: the second method.
"""
from dataclasses import replace

import numpy as np
import pytest

from balloon_cg.analysis.results import IntervalStop, Kind, StopCode
from balloon_cg.galerkin.interval import Mirror
from balloon_cg.galerkin.interval_elements import collocated
from balloon_cg.tube.bulge import UnswitchableBranchPoint, bulge_branch
from balloon_cg.tube.picture import branch_name, rejoined_at, switchable, tube_picture
from balloon_cg.tube.primary import primary_branch, volume_ratio
from balloon_cg.galerkin.equilibrium import Equilibrium

from test_interval import tube_scene


def switched(length, degree, block, extra=""):
    """The primary branch of SPOM1 on a tube of ``length`` (sliding ends, ``extra`` scene keys) and the branch switched
    at its first branch point of ``block``, to V/V0 = 20."""
    scene = tube_scene("SPOM1", length, extra + f"[solver]\ndegree = {degree}\n[continuation]\nstop_stretch = 2.0\n"
                                                "step_max = 0.5\n")
    primary = primary_branch(scene)
    point = primary.branch_points(block)[0]
    return scene, primary, point, bulge_branch(scene, primary, point, stop_volume=20.0 * np.pi * length, step=0.02)


@pytest.mark.parametrize("extra", ["", "axial_stretch = 1.2\n"])
def test_even_branch_point_switches_to_the_half_tubes_bulge(extra):
    """Closed and held apart (λ = 1.2): the branch switched at the first even branch point of L = 20 (degree 60) is
    mirror-symmetric (its odd coefficients zero), bulges at both ends (ρ(0) = ρ(L) > ρ(L/2)), and its first volume
    fold (taut) has the P and V/V0 of the first volume fold of the bulge branch of L = 10 (degree 30) within 1e-9
    (measured 3.1e-11 and 8.2e-12); the branch points themselves, both located, within 1e-12 (measured 1.3e-15 and
    8.9e-16; the held even one was found only to 5.6e-7 before tube/zeros.off_mode_corrector)."""
    folds, onsets = {}, {}
    for length, degree, block in ((10.0, 30, Mirror.ODD), (20.0, 60, Mirror.EVEN)):
        scene, primary, point, branch = switched(length, degree, block, extra)
        assert point.status == "located"
        onsets[block] = point.pressure
        assert branch.stop.code in (StopCode.STOP_VOLUME, IntervalStop.REJOINED)
        fold = next(s for s in branch.special if s.kind == "LV")
        assert fold.smallest_stress > 0 and fold.status == "located"
        eq = Equilibrium(scene, branch.disc)
        folds[block] = (fold.pressure, volume_ratio(eq, np.append(fold.u, fold.pressure)))
    odd = branch.disc.block(Mirror.ODD)
    assert np.abs(branch.states[:, odd]).max() == 0  # traced on the even block
    rho = branch.disc.profile(branch.states[-1], np.array([0.0, 10.0, 20.0]))[0]
    assert rho[0] == pytest.approx(rho[2], abs=1e-12) and rho[0] > rho[1] + 1
    assert abs(onsets[Mirror.EVEN] - onsets[Mirror.ODD]) <= 1e-12
    assert abs(folds[Mirror.EVEN][0] - folds[Mirror.ODD][0]) <= 1e-9
    assert abs(folds[Mirror.EVEN][1] - folds[Mirror.ODD][1]) <= 1e-9


def test_branch_points_that_are_not_switched_are_refused_in_one_line():
    """An even branch point in a coil field (the primary branch is not uniform there), any branch point on plugged
    ends (the line says why: closed, no odd bifurcation where resolved; held apart, the necks compressed at theirs:
    docs/tubes.md, benchmarks/plugged_odd_block.py) and a fold: UnswitchableBranchPoint, one line."""
    coil = "[field]\nM = 0.01\n[[field.coils]]\nradius = 2.5\nheight = 0\ncurrent = 1\n"
    for extra, block, message in ((coil, Mirror.EVEN, "uniform primary branch .* not in a coil field"),
                                  ('ends = "plugged"\n', Mirror.ODD, "on sliding ends, not plugged: closed plugged "
                                   "ends have no odd bifurcation .* held apart .* compressed")):
        scene = tube_scene("SPOM1", 10.0, extra + "[solver]\ndegree = 16\n[continuation]\nstop_stretch = 1.7\n")
        primary = primary_branch(scene)
        fold = primary.special[0]
        assert fold.kind == Kind.LP
        with pytest.raises(UnswitchableBranchPoint, match=message) as refused:
            bulge_branch(scene, primary, replace(fold, kind=Kind.BP, block=block))
        assert "\n" not in str(refused.value)
    with pytest.raises(UnswitchableBranchPoint, match="not at LP"):
        bulge_branch(scene, primary, fold)


def test_run_switches_every_branch_point_once():
    """``tube_picture`` (``run``), SPOM1, L = 10, degree 16, to a hoop stretch of 5: a branch at each of the primary
    branch's branch points in order (odd and even: its labels 1..7), named "bulge" at the first odd one and
    "bulge_<label>" at the others, each starting at its branch point's state and knowing its parent label; the
    branch from label 5 rejoins the mirror-symmetric states at label 6, so label 6 is not switched again. The second
    method: the branch switched at label 6 alone (tube/bulge.py) is that branch from its other end: it rejoins at
    label 5, over the same P range (to 1e-4: the end steps), each of its points within a step of one of ours. An odd
    branch point's branch is on spectral elements (solver.tube_resolution "elements"): its first state is the branch
    point's profile (ρ, η at 201 reference arclengths, 1e-12: the Legendre state collocated onto the elements by least
    squares, measured 1.4e-13 at S = 0)."""
    scene = tube_scene("SPOM1", 10.0, "[solver]\ndegree = 16\n[continuation]\nstop_stretch = 5.0\nstep_max = 0.5\n"
                                      "[stability]\nm_max = 0\n")
    picture = tube_picture(scene)
    primary = picture.branches["primary"]
    labels = [k for k, s in enumerate(primary.special) if s.kind == Kind.BP]
    assert labels == list(range(1, 8)) and switchable(scene, primary) == labels
    assert [primary.special[k].block for k in (1, 2, 5, 6)] == [Mirror.ODD, Mirror.EVEN, Mirror.ODD, Mirror.ODD]
    assert list(picture.branches) == ["primary", "bulge", "bulge_2", "bulge_3", "bulge_4", "bulge_5", "bulge_7"]
    for name, branch in list(picture.branches.items())[1:]:
        label = branch.parent[1]
        assert branch.parent == ("primary", label) and branch_name(primary, label) == name
        if branch.disc == primary.disc:
            assert np.array_equal(branch.states[0], primary.special[label].u)
        else:  # on spectral elements: the same profile
            S = np.linspace(0.0, primary.disc.length, 201)
            for drawn, expected in zip(branch.disc.profile(branch.states[0], S),
                                       primary.disc.profile(primary.special[label].u, S)):
                assert np.abs(drawn - expected).max() <= 1e-12, name
    rejoined = picture.branches["bulge_5"]
    assert rejoined.stop.code == IntervalStop.REJOINED and rejoined.rejoins == 6
    assert all(b.rejoins is None for n, b in picture.branches.items() if n != "bulge_5")
    other = bulge_branch(scene, primary, primary.special[6], stop_stretch=5.0)
    assert other.stop.code == IntervalStop.REJOINED and rejoined_at(scene, primary, other, 6) == 5
    assert abs(other.pressure.min() - rejoined.pressure.min()) <= 1e-4  # measured 3.1e-5 and 4.8e-5: the end steps
    assert abs(other.pressure.max() - rejoined.pressure.max()) <= 1e-4
    ours = np.column_stack([rejoined.states, rejoined.pressure])
    theirs = other.states if other.disc == rejoined.disc else collocated(other.disc, other.states, rejoined.disc)
    for u, P in zip(theirs[1:-1], other.pressure[1:-1]):  # each of its points within a step of one of ours (ours
        # on spectral elements: its Legendre states moved there, exactly: order 16 holds degree 16)
        assert np.linalg.norm(ours - np.append(u, P), axis=1).min() <= scene.continuation.step_max


def test_which_branch_points_run_switches():
    """On sliding ends every odd and even branch point; in a coil field (the primary branch not uniform) the odd ones
    alone; on plugged ends none (their branch points are not resolved: docs/tubes.md)."""
    scene = tube_scene("SPOM1", 10.0, "[solver]\ndegree = 16\n[continuation]\nstop_stretch = 2.0\n")
    primary = primary_branch(scene)
    labels = [k for k, s in enumerate(primary.special) if s.kind == Kind.BP]
    odd = [k for k in labels if primary.special[k].block == Mirror.ODD]
    assert switchable(scene, primary) == labels and odd != labels
    coil = tube_scene("SPOM1", 10.0, "[field]\nM = 0.01\n[[field.coils]]\nradius = 2.5\nheight = 0\ncurrent = 1\n")
    assert switchable(coil, primary) == odd
    assert switchable(tube_scene("SPOM1", 10.0, 'ends = "plugged"\n'), primary) == []
    assert branch_name(primary, odd[0]) == "bulge" and branch_name(primary, labels[1]) == f"bulge_{labels[1]}"


def test_a_branch_that_cannot_start_is_listed_and_the_run_is_incomplete(tmp_path, monkeypatch, capsys):
    """Where the first step off a branch point does not converge (BranchStartError, forced here at label 2), ``run``
    traces the other branches, lists that one as not started in the file and in ``inspect``, and exits 1 with one
    line; the other branches are those of the run without the failure."""
    from balloon_cg.app.cli import main
    from balloon_cg.io.tube_file import read_tube_run
    from balloon_cg.tube import resolution
    from balloon_cg.tube.bulge import BranchStartError

    scene = tmp_path / "t.toml"
    scene.write_text('[material]\npreset = "SPOM1"\n[geometry]\nshape = "tube"\nlength = 10.0\n[solver]\ndegree = 16\n'
                     "[continuation]\nstop_stretch = 3.0\nstep_max = 0.5\n[stability]\nm_max = 0\n")
    whole = tmp_path / "whole.h5"
    assert main(["run", str(scene), "-o", str(whole), "--quiet"]) == 0
    traced = resolution.bulge_branch

    def failing(scene, primary, point, **kwargs):
        if point is primary.special[2]:
            raise BranchStartError("the first step of the bulge branch did not converge: forced")
        return traced(scene, primary, point, **kwargs)

    monkeypatch.setattr(resolution, "bulge_branch", failing)
    out = tmp_path / "t.h5"
    assert main(["run", str(scene), "-o", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err.strip()
    assert err == (f"balloon-cg: incomplete (not started: bulge_2: the first step of the bulge branch did not converge:"
                   f" forced); the rest is written to {out}")
    run, expected = read_tube_run(out), read_tube_run(whole)
    assert run["attrs"]["not_started"] == "bulge_2: the first step of the bulge branch did not converge: forced"
    assert set(run["branches"]) == set(expected["branches"]) - {"bulge_2"}
    for name, branch in run["branches"].items():
        assert np.array_equal(branch["unknowns"], expected["branches"][name]["unknowns"])
    assert main(["inspect", str(out)]) == 0
    text = capsys.readouterr().out
    assert "not started    bulge_2: the first step" in text
    assert ("result         incomplete: not_started (bulge_2: the first step of the bulge branch did not converge: "
            "forced)") in text and bool(run["attrs"]["complete"]) is False


@pytest.mark.parametrize("failure", ["not_started", "unresolved"])
def test_continue_exits_by_the_verdict_it_stores(tmp_path, monkeypatch, capsys, failure):
    """``continue`` at the onset label writes the verdict ``run`` would (tube/picture.gaps) and exits by it, as ``run``:
    1 with one line where the bulge branch did not start (a KeyError, exit 3, before) or stopped unresolved (exit 0,
    before, though the file said incomplete)."""
    from balloon_cg.app.cli import main
    from balloon_cg.io.tube_file import read_tube_run, tube_labels
    from balloon_cg.numerics.continuation import Stop
    from balloon_cg.tube import picture
    from balloon_cg.tube.bulge import BranchStartError

    scene = tmp_path / "t.toml"
    scene.write_text('[material]\npreset = "SPOM1"\n[geometry]\nshape = "tube"\nlength = 10.0\n[solver]\ndegree = 16\n'
                     "[continuation]\nstop_stretch = 3.0\nstep_max = 0.5\n[stability]\nm_max = 0\n")
    whole = tmp_path / "whole.h5"
    assert main(["run", str(scene), "-o", str(whole), "--quiet", "--primary-only"]) == 0
    label = next(i for i, (name, _, s) in enumerate(tube_labels(read_tube_run(whole)))
                 if name == "primary" and (s["kind"], s["block"]) == ("BP", "odd"))
    traced = picture.traced_bulge

    def failing(scene, primary, point, **kwargs):
        if failure == "not_started":
            raise BranchStartError("the first step of the bulge branch did not converge: forced")
        found = traced(scene, primary, point, **kwargs)
        return (*found[:-1], replace(found[-1], stop=Stop(IntervalStop.UNRESOLVED, "forced at the cap")))

    monkeypatch.setattr(picture, "traced_bulge", failing)
    out = tmp_path / "c.h5"
    capsys.readouterr()
    assert main(["continue", str(whole), str(label), "-o", str(out)]) == 1
    err = capsys.readouterr().err.strip()
    stored = read_tube_run(out)["attrs"]
    assert len(err.splitlines()) == 1 and err.startswith("balloon-cg: incomplete (") and bool(stored["complete"]) is False
    assert list(stored["incomplete_gaps"]) == ["not_started" if failure == "not_started" else "stopped_short"]
    assert ("not started: bulge: the first step" if failure == "not_started" else "bulge: forced at the cap, after") in err
