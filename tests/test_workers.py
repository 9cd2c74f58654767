"""Independent work on every core (numerics.workers): the results of the serial loop, in order, from forked
workers; in this process where it does not pay, inside ``serial()`` and with BALLOON_CG_WORKERS=1."""
import os

import numpy as np
import pytest

from balloon_cg.numerics import interrupt, workers

BIG = [workers.MIN_COST] * 6  # costs that make ``spread`` fork


def _pid_and_square(i):
    return os.getpid(), i * i


def test_spread_forks_and_keeps_the_order(monkeypatch):
    monkeypatch.setenv("BALLOON_CG_WORKERS", "2")
    arrived = []
    found = workers.spread(_pid_and_square, range(6), BIG, on_result=lambda: arrived.append(1))
    assert [square for _, square in found] == [i * i for i in range(6)]
    assert os.getpid() not in {pid for pid, _ in found}
    assert len(arrived) == 6


@pytest.mark.parametrize("how", ["cheap", "one worker", "serial"])
def test_spread_stays_in_this_process(monkeypatch, how):
    monkeypatch.setenv("BALLOON_CG_WORKERS", "1" if how == "one worker" else "2")
    costs = [1.0] * 6 if how == "cheap" else BIG
    if how == "serial":
        with workers.serial():
            found = workers.spread(_pid_and_square, range(6), costs)
    else:
        found = workers.spread(_pid_and_square, range(6), costs)
    assert found == [(os.getpid(), i * i) for i in range(6)]


def _fails_at_three(i):
    if i == 3:
        raise ValueError("point 3")
    return i


def test_spread_raises_the_work_s_error(monkeypatch):
    monkeypatch.setenv("BALLOON_CG_WORKERS", "2")
    with pytest.raises(ValueError, match="point 3"):
        workers.spread(_fails_at_three, range(6), BIG)


def test_a_signal_stops_the_pool(monkeypatch):
    monkeypatch.setenv("BALLOON_CG_WORKERS", "2")
    interrupt.request()
    try:
        with pytest.raises(interrupt.Interrupted):
            workers.spread(_pid_and_square, range(6), BIG)
    finally:
        interrupt._flag.clear()


def test_assessments_on_two_workers_are_the_serial_ones(monkeypatch):
    """The SPOM1 primary branch assessed at degree 60 with m = 1 (a cost that forks) on two workers and in this
    process: every eigenvalue, flag, degree and unsettled point identical."""
    from balloon_cg.analysis.branches.primary import trace_primary
    from balloon_cg.analysis.stability.axisymmetric import assess_branch
    from balloon_cg.scene import load_scene

    branch = trace_primary(load_scene("spom1"))
    found = {}
    for count in ("1", "2"):
        monkeypatch.setenv("BALLOON_CG_WORKERS", count)
        found[count] = assess_branch(branch, 60, check=True, m_max=1)
    (serial, unsettled), (spread, unsettled_spread) = found["1"], found["2"]
    assert sum(2 * 60.0 ** 3 for _ in serial) > workers.MIN_COST  # it forked
    assert unsettled == unsettled_spread
    for a, b in zip(serial, spread):
        assert a.flags() == b.flags() and a.degree == b.degree
        for block, values in a.blocks.items():
            np.testing.assert_array_equal(values, b.blocks[block])


def test_a_surface_branch_read_by_sector_groups_on_two_workers_is_the_serial_reading(monkeypatch):
    """The SPOM1 m = 1 branch at M = 0 (12 points, four symmetry sectors): its sectors read in two groups on two
    workers, each group along the whole branch, give every stored eigenvalue and secondary point of the serial
    reading bit for bit (a sector follows its own spectra only)."""
    from dataclasses import replace

    from balloon_cg.analysis.surface import assessment as surface_assessment, branches as surface_branches
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.analysis.results import Block
    from balloon_cg.scene import load_scene

    primary = analyse(load_scene("spom1").with_overrides({"continuation.stop_stretch": 4.0,
                                                          "surface.branches": "none"})).primary
    bp = primary.branch_points()[0]
    captured = []
    monkeypatch.setattr(surface_branches, "assess", lambda sb, traced, readings, stream: captured.append((sb, traced)))
    branch = surface_branches.trace_surface(primary, 0, replace(bp, m=1, block=Block.M1_HELD), 1.0, "m1", 12)
    (sb, traced), = captured
    sizes = surface_assessment._sector_sizes(traced)
    assert len(sizes) == 4 and len(surface_assessment._sector_groups(sizes, 2)) == 2
    assert sum(float(c.size) ** 3 for _, c in traced) > workers.MIN_COST  # it forks
    read = {}
    for count in ("1", "2"):
        monkeypatch.setenv("BALLOON_CG_WORKERS", count)
        read[count] = replace(branch, special=list(sb.special), stability={})
        surface_assessment.assessed(read[count], traced)
    serial, spread = read["1"], read["2"]
    assert serial.stability.keys() == spread.stability.keys()
    for name, values in serial.stability.items():
        np.testing.assert_array_equal(values, spread.stability[name])
    assert [(s.kind, s.index, s.sector) for s in serial.special] == [(s.kind, s.index, s.sector)
                                                                     for s in spread.special]
    for a, b in zip(serial.special, spread.special):
        np.testing.assert_array_equal(a.X, b.X)



def test_a_surface_branch_read_beside_its_trace_is_the_serial_reading(monkeypatch):
    """The SPOM1 m = 1 branch at M = 0 traced with its sectors read beside the trace (``assessment.readers``: two
    forked workers fed each point as it is kept) and traced with the reading at the end in this process: the same
    points, every stored eigenvalue and every secondary point bit for bit."""
    from dataclasses import replace

    from balloon_cg.analysis.surface import branches as surface_branches
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.analysis.results import Block
    from balloon_cg.scene import load_scene

    primary = analyse(load_scene("spom1").with_overrides({"continuation.stop_stretch": 4.0,
                                                          "surface.branches": "none"})).primary
    bp = replace(primary.branch_points()[0], m=1, block=Block.M1_HELD)
    found = {}
    for count in ("1", "2"):
        monkeypatch.setenv("BALLOON_CG_WORKERS", count)
        with workers.Stream(lambda keys: None, [(), ()], 1e12) as probe:
            assert bool(probe.workers) == (count == "2")  # the readers fork with two workers, not with one
        found[count] = surface_branches.trace_surface(primary, 0, bp, 1.0, "m1", 12)
    serial, beside = found["1"], found["2"]
    np.testing.assert_array_equal(serial.coefficients, beside.coefficients)
    assert serial.stability.keys() == beside.stability.keys() and serial.stability
    for name, values in serial.stability.items():
        np.testing.assert_array_equal(values, beside.stability[name])
    for name, sectors in serial.sectors.items():
        for key, values in sectors.items():
            np.testing.assert_array_equal(values, beside.sectors[name][key])
    assert [(s.kind, s.index, s.sector) for s in serial.special] == [(s.kind, s.index, s.sector)
                                                                     for s in beside.special]
    for a, b in zip(serial.special, beside.special):
        np.testing.assert_array_equal(a.X, b.X)


def test_a_stream_raises_its_workers_exception_and_stops_them(monkeypatch):
    """A consumer that raises in a forked stream worker: ``results`` raises it here, and no worker is left."""
    monkeypatch.setenv("BALLOON_CG_WORKERS", "2")

    def make(group):
        def consume(item):
            if item == group:
                raise ValueError(f"item {item}")
            return item
        return consume

    stream = workers.Stream(make, [1, 2], 1e12)
    processes = [process for process, _, _ in stream.workers]
    assert len(processes) == 2
    for item in (0, 1, 2):
        stream.feed(item)
    with pytest.raises(ValueError, match="item 1"):
        stream.results()
    assert not stream.workers and not any(process.is_alive() for process in processes)
    with workers.Stream(make, [5, 6], 1e12) as ok:
        for item in (0, 1):
            ok.feed(item)
        assert ok.results() == [[0, 1], [0, 1]]


def _sleep_then_mark(item):
    import time

    i, folder = item
    time.sleep(30 if i == 0 else 0)
    (folder / f"done_{i}").write_text("")


def test_workers_are_gone_when_spread_raises(monkeypatch, tmp_path):
    """A signal while an item runs: Interrupted, the worker running the 30 s item killed, not waited for (its mark
    never written), no worker left."""
    import multiprocessing
    import threading

    monkeypatch.setenv("BALLOON_CG_WORKERS", "2")
    threading.Timer(0.5, interrupt.request).start()
    try:
        with pytest.raises(interrupt.Interrupted):
            workers.spread(_sleep_then_mark, [(i, tmp_path) for i in range(4)], BIG[:4])
    finally:
        interrupt._flag.clear()
    assert not multiprocessing.active_children()
    assert not (tmp_path / "done_0").exists()


def test_a_picture_with_its_branch_points_on_two_workers_is_the_serial_one(monkeypatch):
    """Two coils to the first branch points with 3-point surface branches (tests/test_interrupt_moments.py's scene):
    on two workers (the m = 0 branch points located on both: ``picture._branch_points``) and in this process, the
    same branches, special points, assessments and surface branches, bit for bit."""
    from pathlib import Path

    from balloon_cg.analysis import picture
    from balloon_cg.analysis.results import Block
    from balloon_cg.scene import load_scene

    root = Path(__file__).resolve().parents[1]
    scene = load_scene(root / "scenes" / "spom1_two_coils_M0.002.toml").with_overrides(
        {"continuation.stop_stretch": 1.7, "surface.max_points": 3})
    forked, spread = [], workers.spread

    def spied(work, items, costs=None, *args, **kwargs):
        items = list(items)
        if items and isinstance(items[0], tuple) and len(items[0]) == 3 and isinstance(items[0][1], Block):
            forked.append(workers.sharing(len(items), sum(costs)) > 1)  # the m = 0 branch points' spread
        return spread(work, items, costs, *args, **kwargs)

    monkeypatch.setattr(workers, "spread", spied)
    found = {}
    for count in ("1", "2"):
        monkeypatch.setenv("BALLOON_CG_WORKERS", count)
        found[count] = picture.analyse(scene)
    assert forked == [False, True]
    serial, spread = found["1"], found["2"]
    assert [b.name for b in serial.branches] == [b.name for b in spread.branches]
    assert serial.surface_branches and [b.name for b in serial.surface_branches] == [b.name for b in
                                                                                      spread.surface_branches]
    assert (serial.not_started, serial.not_switched, serial.not_asked) == (spread.not_started, spread.not_switched,
                                                                           spread.not_asked)
    for a, b in zip(serial.branches + serial.surface_branches, spread.branches + spread.surface_branches):
        assert repr(a.special) == repr(b.special), a.name
        for s, t in zip(a.special, b.special):
            np.testing.assert_array_equal(s.X, t.X)
        np.testing.assert_array_equal(getattr(a, "X", getattr(a, "coefficients", None)),
                                      getattr(b, "X", getattr(b, "coefficients", None)))
    for a, b in zip(serial.branches, spread.branches):
        assert len(a.stability) == len(b.stability) and a.unsettled == b.unsettled, a.name
        for s, t in zip(a.stability, b.stability):
            assert (s.flags(), s.degree, s.blocks.keys()) == (t.flags(), t.degree, t.blocks.keys())
            for key, values in s.blocks.items():
                np.testing.assert_array_equal(values, t.blocks[key])
    for a, b in zip(serial.surface_branches, spread.surface_branches):
        assert a.stability.keys() == b.stability.keys()
        for name, values in a.stability.items():
            np.testing.assert_array_equal(values, b.stability[name])
