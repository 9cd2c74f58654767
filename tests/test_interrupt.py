"""numerics.interrupt: a signal whose KeyboardInterrupt lands where Python cannot raise it (a weakref callback)
prints no traceback and still stops the work (the flag); other unraisable errors are still reported. A stop
during the stability assessment takes effect at the next point."""
import signal
import subprocess
import sys
import time
import weakref
from pathlib import Path

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
    from balloon_cg.analysis.points import branch_points as bifurcation

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


def _catches_sigterm(pid: int) -> bool:
    """Whether the process has a handler for SIGTERM (bit 15 of SigCgt in /proc/PID/status)."""
    for line in open(f"/proc/{pid}/status"):
        if line.startswith("SigCgt:"):
            return bool(int(line.split()[1], 16) >> (signal.SIGTERM - 1) & 1)
    return False


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs /proc")
@pytest.mark.parametrize("command", [[sys.executable, "-m", "balloon_cg"],
                                     [str(Path(sys.executable).parent / "balloon-cg")]], ids=["-m", "script"])
def test_sigterm_during_the_imports_exits_130(command, tmp_path):
    """Issue 30 item 12: a SIGTERM as soon as the process has a handler for it (balloon_cg.__main__.run installs one
    before importing the CLI; the `balloon-cg` script enters there too) ends with exit 130 and one line, not −15."""
    if not Path(command[0]).exists():
        pytest.skip("the balloon-cg script is not installed beside this interpreter")
    scene = tmp_path / "s.toml"
    scene.write_text('[material]\npreset = "SPOM1"\n')
    proc = subprocess.Popen([*command, "run", str(scene), "-o", str(tmp_path / "x.h5"), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while proc.poll() is None and not _catches_sigterm(proc.pid) and time.monotonic() < deadline:
            time.sleep(0.001)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 130 and err.strip().splitlines() == ["balloon-cg: error: interrupted"], (proc.returncode,
                                                                                                    err)


def test_the_entry_points_catch_sigterm_before_importing_the_cli():
    """What makes the window before the handler empty: `balloon-cg` and `python -m balloon_cg` enter at
    balloon_cg.__main__.run, and app.cli (numpy, the scene layer: ~0.2 s of imports) is imported only after run has
    installed its SIGTERM handler (recorded by an import hook in a fresh interpreter)."""
    import importlib.metadata

    scripts = {e.name: e.value for e in importlib.metadata.entry_points(group="console_scripts")}
    assert scripts["balloon-cg"] == "balloon_cg.__main__:run"
    probe = ("import signal, sys\n"
             "class Hook:\n"
             "    def find_spec(self, name, path=None, target=None):\n"
             "        if name == 'balloon_cg.app.cli':\n"
             "            print(signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL)\n"
             "sys.meta_path.insert(0, Hook())\n"
             "sys.argv = ['balloon-cg', '--version']\n"
             "from balloon_cg.__main__ import run\n"
             "run()\n")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert out.stdout.splitlines()[0] == "True", out


@pytest.mark.parametrize("method", ["assess", "flags"])
def test_a_stop_while_a_point_s_blocks_are_built_comes_before_their_eigenvalues(monkeypatch, method):
    """A point's blocks cost up to ~1 s of CPU on two coils at the check degree: a stop asked for while the first
    point of ``method`` builds them raises Interrupted before any of its blocks is solved (``assess``, the first pass:
    their eigenvalues, the m = 0 reductions built by ``SecondVariation._families``; ``flags``, the check-degree pass:
    their Cholesky test, the blocks built by ``SecondVariation.blocks``)."""
    from balloon_cg.analysis.stability import axisymmetric as stability
    from balloon_cg.analysis.branches.primary import trace_primary
    from balloon_cg.numerics import eigen, workers

    branch = trace_primary(load_scene("spom1").with_overrides({"continuation.stop_stretch": 2.0}))
    builder = "_families" if method == "assess" else "blocks"
    blocks, run = getattr(stability.SecondVariation, builder), getattr(stability.SecondVariation, method)
    lowest, definite, relatives = stability.merged_lowest, eigen.positive_definite, eigen.lowest_with_relatives
    inside, solved = [], []

    def asked(self, *args, **kwargs):
        out = blocks(self, *args, **kwargs)
        if inside and not interrupt.requested():
            interrupt.request()  # as the signal's handler does, as the first point of ``method`` builds its blocks
        return out

    def entered(self, *args, **kwargs):
        inside.append(1)
        return run(self, *args, **kwargs)

    def solving(solve):
        def counted(*args, **kwargs):
            solved.append(interrupt.requested())
            return solve(*args, **kwargs)
        return counted

    monkeypatch.setattr(stability.SecondVariation, builder, asked)
    monkeypatch.setattr(stability.SecondVariation, method, entered)
    monkeypatch.setattr(stability, "merged_lowest", solving(lowest))
    monkeypatch.setattr(eigen, "positive_definite", solving(definite))
    monkeypatch.setattr(eigen, "lowest_with_relatives", solving(relatives))
    with interrupt.stop_on_signals(), workers.serial(), pytest.raises(interrupt.Interrupted):
        stability.assess_branch(branch, branch.scene.stability.degree, check=True)
    assert len(inside) == 1 and True not in solved  # the point's blocks built, none solved after the request


@pytest.mark.parametrize("dropped", [False, True])
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_continue_reads_its_file_stops_the_read_at_once(tmp_path, monkeypatch, capsys, sig, dropped):
    """`continue` reads its run file before any work (seconds of CPU for a file with surface branches): a signal
    then ends the read at once, not after it (the next branch is not read), exit 130, nothing written. Where its
    KeyboardInterrupt is raised in a callback that drops it (``dropped``: a ``__del__`` of h5py's, say), the flag it
    set still stops the command once the read ends (CI saw that signal lost, the work done, exit 0)."""
    from balloon_cg.app.cli import main
    from balloon_cg.io import run_file

    run = tmp_path / "r.h5"
    assert main(["run", "spom1", "--set", "continuation.stop_stretch=3", "-o", str(run), "--quiet"]) == 0
    assert len(read_run(run)["branches"]) >= 2
    checked, check_branch = [], run_file.check_branch

    def signalled(*args, **kwargs):
        checked.append(args)
        if len(checked) == 1:
            try:
                signal.raise_signal(sig)
            except KeyboardInterrupt:
                if not dropped:
                    raise
        return check_branch(*args, **kwargs)

    monkeypatch.setattr(run_file, "check_branch", signalled)
    capsys.readouterr()
    assert main(["continue", str(run), "1", "-o", str(tmp_path / "c.h5"), "--quiet"]) == 130
    assert (len(checked) > 1) == dropped and not (tmp_path / "c.h5").exists()
    assert capsys.readouterr().err.strip() == (f"balloon-cg: interrupted: nothing is written to {tmp_path / 'c.h5'} "
                                               "(the work had not started)")


FREQUENCIES_SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 2.0\n[dynamics]\nfrequencies = true\n'


def _stop_at(n: int, progress=None):
    """A tracer's per-point ``progress`` that asks for a stop (as a signal's handler does) at its ``n``-th point."""
    ticks = []

    def tick(*args):
        ticks.append(1)
        if progress is not None:
            progress(*args)
        if len(ticks) == n:
            interrupt.request()
    return tick


def _interrupted_in(incomplete) -> list:
    """The messages of the picture's own interrupted entry (not a leg's)."""
    return [i.message for i in incomplete if i.gap == Gap.INTERRUPTED and i.message.startswith("interrupted by")]


def test_a_signal_during_a_primary_only_trace_is_recorded_in_the_trace_not_the_frequencies(monkeypatch):
    """app.api.computed's primary-only picture (built without ``picture.stopped``) with [dynamics] frequencies: a stop
    asked for during the trace names the trace as the phase it came in, not the frequencies (not started)."""
    from balloon_cg.analysis.branches import primary
    from balloon_cg.app.api import computed
    from balloon_cg.scene import parse_scene

    trace = primary.trace_primary
    monkeypatch.setattr(primary, "trace_primary", lambda scene, progress=None: trace(scene, progress=_stop_at(3, progress)))
    with interrupt.stop_on_signals():
        branches, _, found, _, _ = computed(parse_scene(FREQUENCIES_SCENE, "s"), primary_only=True)
    assert branches[0].frequencies is None
    assert _interrupted_in(found) == ["interrupted by a signal during trace: the branches and phases after the stored "
                                      "points were not computed"], found


def test_a_signal_during_continue_s_trace_is_recorded_in_the_trace_not_the_frequencies(tmp_path):
    """``continue`` (app.restart.restart) from a label of an unassessed branch returns ``Picture([traced])``: a stop
    asked for during its trace names the trace, not the frequencies, as the phase it came in."""
    import balloon_cg as bc
    from balloon_cg.app.restart import find_label, restart
    from balloon_cg.scene import parse_scene

    bc.trace(parse_scene(FREQUENCIES_SCENE, "s")).save(tmp_path / "t.h5")
    run = read_run(tmp_path / "t.h5")
    start = find_label(run, 1)
    with interrupt.stop_on_signals():
        picture = restart(start, None, progress=_stop_at(3))
    assert picture.primary.frequencies is None
    assert _interrupted_in(picture.incomplete) == [
        "interrupted by a signal during trace: the branches and phases after the stored points were not computed"]


def test_a_signal_during_continue_s_pear_branches_is_recorded_in_them(tmp_path):
    """``continue`` at a pear pitchfork (app.restart.switch): the pear branches' time is on the picture's clock as
    run's is, and a stop asked for during their trace names them as the phase it came in (it named none)."""
    from balloon_cg.analysis.results import Kind
    from balloon_cg.analysis.timing import Step
    from balloon_cg.app.cli import main
    from balloon_cg.app.restart import find_label, restart

    scene = tmp_path / "spom1.toml"
    scene.write_text(load_scene("spom1").with_overrides({"surface.branches": "none"}).to_toml())
    assert main(["run", str(scene), "-o", str(tmp_path / "run.h5"), "--quiet"]) == 0
    run = read_run(tmp_path / "run.h5")
    label = next(s["label"] for s in run["branches"]["primary"]["special_points"]
                 if s["kind"] == Kind.BP.value and s["block"] == "odd_held")
    with interrupt.stop_on_signals():
        picture = restart(find_label(run, label), None, progress=_stop_at(3))
    assert picture.interrupted and picture.interrupted_in == Step.PEAR_BRANCHES.value
    assert picture.clock.seconds[Step.PEAR_BRANCHES] > 0
    assert _interrupted_in(picture.incomplete) == [
        "interrupted by a signal during pear branches: the branches and phases after the stored points were not "
        "computed"]
