"""A signal during the non-axisymmetric (surface) branches stops them as every other stage stops (issue 42, item 1):
the trace at its next point (leg stop ``interrupted``), the stability at its next point (the branch then kept as
traced, not assessed), the picture flagged interrupted in the phase it was in, and `balloon-cg run` exits 130
saying what the file says. The moment is picked by the work itself (the n-th point, the n-th spectrum), never by a
clock: the tests count the work done after the request, which does not depend on the machine's speed."""
from dataclasses import replace
from pathlib import Path

import h5py
import numpy as np
import pytest

from balloon_cg.analysis.surface import assessment as surface_assessment
from balloon_cg.analysis.picture import Picture, analyse, stopped
from balloon_cg.analysis.results import Block, StopCode, TraceStop
from balloon_cg.analysis.surface.branches import trace_surface
from balloon_cg.analysis.timing import Step
from balloon_cg.analysis.verdict import Gap, incomplete
from balloon_cg.numerics import interrupt, workers
from balloon_cg.scene import load_scene

from test_signal_moments import balloon_cg, one_line

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def pear_point():
    """SPOM1 without a field: its primary branch and the pear point read as an m = 1 point (the branch born there
    is the pear branch turned by 90°: tests/test_surface.py), a surface branch of a few seconds."""
    scene = load_scene(ROOT / "scenes" / "spom1.toml").with_overrides({"continuation.stop_stretch": 2.0,
                                                                       "surface.branches": "none"})
    primary = analyse(scene).primary
    bp = primary.branch_points()[0]
    return primary, replace(bp, m=1, block=Block.M1_HELD)


def test_a_signal_during_a_surface_trace_stops_it_at_the_next_point(pear_point):
    primary, bp = pear_point
    points = []

    def tick(point):
        points.append(point)
        if len(points) == 3:
            interrupt.request()  # what the signal handler does

    with interrupt.stop_on_signals():
        branch = trace_surface(primary, 0, bp, 1.0, "m1", 40, progress=tick)
    assert not interrupt.requested()  # cleared with the handlers
    assert branch.legs[0].stop.code == StopCode.INTERRUPTED
    # no point after the request: the branch point, the first step off it (``switch``) and the 3 traced
    assert len(points) == 3 and len(branch.values) == 5
    assert branch.stability == {}  # not assessed: no half-assessed branch
    assert [item.gap for item in incomplete([branch])] == [Gap.INTERRUPTED]


def test_a_signal_during_a_surface_assessment_stops_it_at_the_next_point(pear_point, monkeypatch):
    primary, bp = pear_point
    calls = []
    spectra = surface_assessment.surface_stability.sector_spectra

    def counted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            interrupt.request()
        return spectra(*args, **kwargs)

    monkeypatch.setattr(surface_assessment.surface_stability, "sector_spectra", counted)
    with interrupt.stop_on_signals(), workers.serial():  # counted in this process (forked workers count their own)
        branch = trace_surface(primary, 0, bp, 1.0, "m1", 6)
    assert len(calls) == 2  # the point being read finished, no further one started
    assert branch.stability == {} and [s.kind.value for s in branch.special] == ["BP", "EP"]  # as traced
    assert branch.legs[0].stop.code == TraceStop.MAX_POINTS and len(branch.values) == 6


def test_the_picture_names_the_phase_it_stopped_in(pear_point):
    primary, _ = pear_point
    picture = Picture([primary])
    with interrupt.stop_on_signals():
        with picture.clock.step(Step.SURFACE_BRANCHES):
            assert not stopped(picture)
            interrupt.request()
            assert stopped(picture)
        with picture.clock.step(Step.SNAP_THROUGHS):
            assert stopped(picture)  # the first phase it was seen in stays
    entry = [item for item in picture.incomplete if item.gap == Gap.INTERRUPTED]
    assert len(entry) == 1 and "interrupted by a signal during non-axisymmetric branches" in entry[0].message


def test_run_says_what_the_file_says(tmp_path):
    """`balloon-cg run` interrupted (a SIGTERM sent by the process to itself as the primary branch's assessment
    returns): exit 130, one line naming the phase, the file incomplete with the same entry."""
    (tmp_path / "s.toml").write_text('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 1.5\n')
    code, err = balloon_cg(tmp_path, "SIGTERM", "after balloon_cg.analysis.picture:_assess",
                           ["run", "s.toml", "-o", "r.h5", "--quiet"])
    line = one_line(err)
    assert code == 130 and line.startswith("balloon-cg: interrupted (primary: interrupted by a signal during "), err
    with h5py.File(tmp_path / "r.h5", "r") as f:
        assert not f.attrs["complete"]
        gaps, messages = list(f.attrs["incomplete_gaps"]), list(f.attrs["incomplete_messages"])
    message = messages[gaps.index("interrupted")]
    assert f"(primary: {message});" in line


@pytest.mark.slow
def test_run_of_two_coils_interrupted_in_its_surface_branches(tmp_path):
    """The issue's case: two coils, SIGTERM as the surface branch takes its first step off the branch point (about
    30 s of axisymmetric work before): exit 130, the line and the file name the phase, the surface branch is
    stored as far as it went."""
    code, err = balloon_cg(tmp_path, "SIGTERM", "after balloon_cg.analysis.surface.branches:switch",
                           ["run", str(ROOT / "scenes" / "spom1_two_coils_M0.002.toml"), "-o", "r.h5", "--quiet"])
    line = one_line(err)
    assert code == 130 and "during non-axisymmetric branches" in line, err
    with h5py.File(tmp_path / "r.h5", "r") as f:
        assert not f.attrs["complete"] and "interrupted" in list(f.attrs["incomplete_gaps"])
        assert list(f["branches/m1_bp1"].attrs["leg_stop_codes"]) == ["interrupted"]
        assert "stability" not in f["branches/m1_bp1"]


def test_a_signal_inside_a_point_s_spectra_stops_at_its_next_sector(pear_point, monkeypatch):
    """A point's spectra are read one symmetry sector at a time (a large two-coil point: ~2 s of CPU for all of
    them); a signal as the first sector of the first point is assembled stops the assessment before that sector's
    eigenvalues (``surface.stability.sector_spectra`` polls at each sector): no other sector is read."""
    primary, bp = pear_point
    sectors = surface_assessment.surface_stability._sectors

    def reading(signal: bool) -> list:
        """The sectors assembled, per call of sector_spectra (a point), while the branch is assessed; with
        ``signal`` the stop is requested as the first sector is assembled."""
        calls = []

        def counted(*args, **kwargs):
            calls.append(0)
            for sector in sectors(*args, **kwargs):
                calls[-1] += 1
                if signal and calls == [1]:
                    interrupt.request()
                yield sector

        monkeypatch.setattr(surface_assessment.surface_stability, "_sectors", counted)
        with interrupt.stop_on_signals(), workers.serial():
            branch = trace_surface(primary, 0, bp, 1.0, "m1", 6)
        return calls, branch

    whole, _ = reading(False)
    calls, branch = reading(True)
    assert whole[0] >= 3  # a point has several sectors: stopping in the first cuts it short
    assert calls == [1]  # the first sector assembled, its eigenvalues not computed, no other
    assert branch.stability == {} and [s.kind.value for s in branch.special] == ["BP", "EP"]  # as traced


def test_a_signal_as_a_surface_branch_would_refine_stops_it_there(pear_point, monkeypatch):
    """A point whose tail exceeds solver.max_error refines the basis, is solved again there and goes on (~1 s
    of CPU on two coils before the next point's poll): a signal then stops the branch where it is, not refined
    (the third point's tail made to exceed max_error as the signal comes)."""
    from balloon_cg.analysis.surface import branches as surface_branches

    primary, bp = pear_point
    tail, refine, tails, refined = surface_branches.tail, surface_branches.refined, [], []

    def exceeding(basis, c):
        tails.append(1)
        if len(tails) == 3:
            interrupt.request()
            return np.inf
        return tail(basis, c)

    monkeypatch.setattr(surface_branches, "tail", exceeding)
    monkeypatch.setattr(surface_branches, "refined",
                        lambda *args: refined.append(interrupt.requested()) or refine(*args))
    with interrupt.stop_on_signals():
        branch = trace_surface(primary, 0, bp, 1.0, "m1", 40)
    assert True not in refined and branch.legs[0].stop.code == StopCode.INTERRUPTED  # no refinement after it
    assert len(branch.values) == 4  # the branch point, the first step off it and the two points before the third
    assert [item.gap for item in incomplete([branch])] == [Gap.INTERRUPTED]
