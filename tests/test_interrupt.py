"""numerics.interrupt: a signal whose KeyboardInterrupt lands where Python cannot raise it (a weakref callback)
prints no traceback and still stops the work (the flag); other unraisable errors are still reported. A stop
during the stability assessment takes effect at the next point."""
import signal
import sys
import weakref

import pytest

from balloon_cg.analysis.picture import Phase, Progress, analyse
from balloon_cg.analysis.verdict import Gap
from balloon_cg.io.run_file import read_run, write_run
from balloon_cg.numerics import interrupt
from balloon_cg.scene import load_scene


class Thing:
    pass


def _collected_with(callback):
    """Create and drop an object whose weakref callback is ``callback`` (run at once, by reference counting)."""
    thing = Thing()
    ref = weakref.ref(thing, lambda _: callback())
    del thing
    return ref


@pytest.mark.parametrize("handlers", [interrupt.sigterm_raises, interrupt.stop_on_signals])
def test_an_interrupt_inside_a_callback_is_not_printed_and_sets_the_flag(monkeypatch, handlers):
    reported = []
    monkeypatch.setattr(sys, "unraisablehook", reported.append)
    with handlers():
        if handlers is interrupt.stop_on_signals:
            interrupt.request()  # the first signal is pending: the second raises
        _collected_with(lambda: signal.raise_signal(signal.SIGTERM))  # the handler runs inside the callback
        assert interrupt.requested()
        assert reported == []  # without the hook: "Exception ignored in ..." and a KeyboardInterrupt traceback
        _collected_with(lambda: 1 / 0)
        assert [type(r.exc_value) for r in reported] == [ZeroDivisionError]  # a bug is still shown
    assert sys.unraisablehook == reported.append and not interrupt.requested()


class _StopAfter(Progress):
    """A Progress that asks for a stop (as a signal's handler does) after ``count`` points of ``phase``."""

    def __init__(self, phase, count):
        self.phase, self.count, self.ticks = phase, count, 0

    def tick(self, phase):
        if phase == self.phase:
            self.ticks += 1
            if self.ticks == self.count:
                interrupt.request()


@pytest.mark.parametrize("phase", [Phase.STABILITY, Phase.PEAR])
def test_a_stop_during_stability_ends_the_analysis_at_the_next_point(tmp_path, phase):
    """A stop asked for while points are assessed takes effect at the next point (the assessment of the
    branch in progress is abandoned: kept as traced, not assessed), not after every point of every branch; the
    partial picture writes a readable file flagged interrupted."""
    scene = load_scene("spom1")
    with interrupt.stop_on_signals():
        progress = _StopAfter(phase, 5)
        picture = analyse(scene, progress)
    assert picture.interrupted and Gap.INTERRUPTED in {i.gap for i in picture.incomplete}
    if phase == Phase.STABILITY:  # the primary branch's assessment stopped at its sixth point
        assert progress.ticks == 5 and picture.primary.stability is None and len(picture.branches) == 1
    else:  # the first pear branch stopped tracing at its next point; it is kept, not assessed
        assert picture.primary.stability is not None and picture.branches[-1].stability is None
    write_run(tmp_path / "partial.h5", scene, picture.branches, found=picture.incomplete)
    run = read_run(tmp_path / "partial.h5")
    assert not run["attrs"]["complete"] and "interrupted" in run["attrs"]["incomplete_gaps"]


def test_a_stop_while_branch_points_are_located_keeps_those_located(monkeypatch):
    """A stop asked for during the location of the first branch point: that one is kept (located and
    classified), no other is started, no pear branch is traced, the special points stay in order."""
    from balloon_cg.analysis import bifurcation

    locate = bifurcation.locate

    def interrupted_locate(*args, **kw):
        interrupt.request()  # as the handler does, in the middle of the location
        return locate(*args, **kw)

    monkeypatch.setattr(bifurcation, "locate", interrupted_locate)
    with interrupt.stop_on_signals():
        picture = analyse(load_scene("spom1"))
    assert picture.interrupted and len(picture.branch_points) == 1 and len(picture.branches) == 1
    indices = [s.index for s in picture.primary.special]
    assert indices == sorted(indices)
