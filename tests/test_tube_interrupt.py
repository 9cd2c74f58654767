"""Issue 42's contract on tubes (issue 38): a signal during `run` or `critical` on a tube scene stops it at its next
point (or before its next stage), writes what is finished flagged ``interrupted`` with the stage named, and exits
130 with one line that says what the file says; what is written is the uninterrupted run's, point for point, up to
where it stopped. The moments are placed by the code's own hooks (the n-th call of a function, in a fresh
interpreter that sends itself the signal there: test_signal_moments.py's driver) and, for the latency, by the
command's own CPU time (tests/cpu_moments.py): no sleeps, the same on any machine."""
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.app.cli import main
from balloon_cg.io.tube_file import read_tube_run

from cpu_moments import command, evenly, handled, warm_reference
from shared_pictures import TUBE, TUBE_COIL, TUBE_COIL_FAST, TUBE_FAST, tube_critical_file, tube_run_file
from test_signal_moments import balloon_cg, one_line

LATENCY = 2.0  # CPU seconds from the signal to the process's exit (issue 42)


def run_argv(output: str) -> list:
    return ["run", str(TUBE), "-o", output, "--quiet", "--force", *TUBE_FAST]  # ~3 s of CPU, every branch


def critical_argv(output: str) -> list:
    return ["critical", str(TUBE_COIL), "--parameter", "M", "-o", output, "--quiet", "--force", *TUBE_COIL_FAST]


@pytest.fixture(scope="module")
def references(tmp_path_factory):
    """The uninterrupted run and critical files: the session's (tests/shared_pictures.py, the same commands run
    once for the tube CLI tests; in a process of their own or this one, the numbers are the same bit for bit: the
    computation limits BLAS to one thread either way, numerics/threads.py)."""
    return read_tube_run(tube_run_file(tmp_path_factory)), read_tube_run(tube_critical_file(tmp_path_factory))


def checked(path: Path, line: str, reference: dict) -> str:
    """The stage the file names, checked against the command's ``line`` and the uninterrupted ``reference``: the
    stage's branch (or curve; in the bulge stage the switched branch being traced) ends ``interrupted`` where it had
    started, its points the reference's first ones bit for
    bit, and is absent where it had not; every other branch is the reference's whole."""
    run = read_tube_run(path)
    stage = run["attrs"]["interrupted"]
    stopped = next((n for n, b in run["branches"].items() if b["attrs"]["stop_code"] == "interrupted"), None)
    stored = run["onset"] if stage == "onset" else run["branches"].get(stopped)
    if stage == "modes":  # after the last branch's last check: every branch whole, their m ≥ 1 blocks not read
        assert stopped is None
        what = "the branches whole, their m ≥ 1 blocks not read"
    elif stored is None:
        what = "not started"
    else:
        what = f"{stored['attrs']['stop_message']}, after {len(stored['pressure'])} points"
        assert stored["attrs"]["stop_code"] == "interrupted"
        whole = reference["onset"] if stage == "onset" else reference["branches"][stopped]
        n = len(stored["pressure"])
        assert n < len(whole["pressure"]) and np.array_equal(stored["unknowns"], whole["unknowns"][:n])
    assert line == (f"balloon-cg: interrupted ({stage}: {what}); what was finished is written to {path.name} "
                    "(flagged interrupted)"), line
    for name, branch in run["branches"].items():
        if name != stopped:
            assert branch["attrs"]["stop_code"] != "interrupted"
            assert np.array_equal(branch["unknowns"], reference["branches"][name]["unknowns"])
    return stage


# (the hook, its call, the stage it falls in, whether that stage's branch had started)
RUN_MOMENTS = [("after balloon_cg.numerics.continuation:correct", 10, "primary", True),  # the primary's 10th step
               ("after balloon_cg.tube.primary:stressed", 1, "bulge", False),  # the primary's points located
               ("after balloon_cg.tube.bulge:Equilibrium", 1, "bulge", True),  # the bulge's start
               ("after balloon_cg.tube.bulge:Equilibrium", 3, "bulge", True)]  # the third switched branch's start


@pytest.mark.parametrize("moment, call, stage, started, sig", [
    (*moment, ("SIGINT", "SIGTERM")[k % 2]) for k, moment in enumerate(RUN_MOMENTS)])
def test_a_signal_during_a_tube_run_writes_what_is_finished(references, tmp_path, capsys, moment, call, stage,
                                                            started, sig):
    """SIGINT and SIGTERM in turn: the whole computation and its write run under one handler for both
    (numerics.interrupt.stop_on_signals), so each moment is reached by one of them (until session 30: by each)."""
    code, err = balloon_cg(tmp_path, sig, moment, run_argv("r.h5"), call)
    assert code == 130, err
    assert checked(tmp_path / "r.h5", one_line(err), references[0]) == stage
    assert ("bulge" in read_tube_run(tmp_path / "r.h5")["branches"]) == (stage == "bulge" and started)
    assert main(["inspect", str(tmp_path / "r.h5")]) == 0
    assert f"interrupted    a signal stopped the {stage} stage: what follows it is missing" in capsys.readouterr().out


CRITICAL_MOMENTS = [("after balloon_cg.numerics.continuation:correct", 10, "primary"),
                    ("after balloon_cg.tube.primary:stressed", 1, "onset"),  # the curve not started
                    ("after balloon_cg.tube.onset:newton", 1, "onset")]  # the curve's first point


@pytest.mark.parametrize("moment, call, stage", CRITICAL_MOMENTS)
def test_a_signal_during_critical_on_a_tube_writes_what_is_finished(references, tmp_path, moment, call, stage):
    code, err = balloon_cg(tmp_path, "SIGINT", moment, critical_argv("c.h5"), call)
    assert code == 130, err
    assert checked(tmp_path / "c.h5", one_line(err), references[1]) == stage
    run = read_tube_run(tmp_path / "c.h5")
    assert (run["onset"] is not None) == (moment.endswith(":newton"))


@pytest.mark.parametrize("moment", ["after balloon_cg.io.tube_file:write_tube_run",
                                    "after balloon_cg.io.tube_file:read_tube_run"])  # the file read back
def test_a_signal_once_the_file_is_written_exits_0_and_says_so(references, tmp_path, moment):
    code, err = balloon_cg(tmp_path, "SIGTERM", moment, run_argv("r.h5"))
    assert code == 0 and one_line(err) == "balloon-cg: a signal arrived once the work had finished: r.h5 is " \
                                          "written whole"
    run = read_tube_run(tmp_path / "r.h5")
    assert run["attrs"]["interrupted"] == "" and set(run["branches"]) == set(references[0]["branches"])


@pytest.fixture(scope="module")
def reference_cpu(tmp_path_factory):
    """The CPU seconds of an uninterrupted tube run from the call of its command (cpu_moments.handled), on compiled
    kernels."""
    folder = tmp_path_factory.mktemp("cpu")
    done = warm_reference(folder, run_argv("r.h5"), handled("balloon_cg.app.tube_commands:run_tube"))
    assert done.code == 0 and done.stderr == "", done.stderr
    return folder, done.handler_cpu


@pytest.mark.parametrize("k", range(3))
def test_a_signal_at_an_evenly_spaced_moment_stops_a_tube_run_within_2_s(references, reference_cpu, k):
    """Three moments evenly spaced over the run's CPU: within 2 s of CPU after the signal the command has exited,
    130 with the file's line (or 0 where the work had finished, and it says so)."""
    folder, total = reference_cpu
    t = evenly(total, 3)[k]
    (folder / "r.h5").unlink(missing_ok=True)
    got = command(folder, run_argv("r.h5"), "SIGTERM", handled("balloon_cg.app.tube_commands:run_tube", t))
    if not got.fired:  # the replay finished before the moment
        assert got.code == 0 and got.stderr == ""
        print(f"moment {t:.3f} s of {total:.3f} s CPU: finished before it")
        return
    assert got.cpu_after <= LATENCY, (got.cpu_after, got.stderr)
    line = one_line(got.stderr)
    if got.code == 0:
        assert line == "balloon-cg: a signal arrived once the work had finished: r.h5 is written whole"
        print(f"moment {t:.3f} s of {total:.3f} s CPU: the work had finished")
        return
    assert got.code == 130, line
    stage = checked(folder / "r.h5", line, references[0])
    print(f"moment {t:.3f} s of {total:.3f} s CPU: {stage}, exit after {got.cpu_after:.3f} s CPU")


def test_a_signal_during_a_tube_runs_frequencies_stops_them_at_the_next_point(references, tmp_path):
    """With [dynamics] frequencies the signal after the 3rd point's frequencies (of the primary branch's ~20): the
    command exits 130 within that point, the branches are the uninterrupted run's whole, no branch has frequencies
    (the primary's were not finished) and the line says so."""
    argv = run_argv("r.h5") + ["--set", "dynamics.frequencies=true"]
    code, err = balloon_cg(tmp_path, "SIGTERM", "after balloon_cg.dynamics.tube:tube_frequencies", argv, 3)
    assert code == 130, err
    assert one_line(err) == ("balloon-cg: interrupted (frequencies: the branches whole, the frequencies of none "
                             "written); what was finished is written to r.h5 (flagged interrupted)")
    run = read_tube_run(tmp_path / "r.h5")
    assert run["attrs"]["interrupted"] == "frequencies"
    assert set(run["branches"]) == set(references[0]["branches"]) and {"primary", "bulge"} < set(run["branches"])
    for name, branch in run["branches"].items():
        assert branch["frequencies"] is None
        assert np.array_equal(branch["unknowns"], references[0]["branches"][name]["unknowns"])
        assert branch["attrs"]["stop_code"] == references[0]["branches"][name]["attrs"]["stop_code"]


def _signalled_after(monkeypatch, module, name):
    """``module.name`` asking for a stop (as a signal's handler does) once it returns: a signal after the last check of
    the flag in the trace it made."""
    from balloon_cg.numerics import interrupt

    original = getattr(module, name)

    def traced(*args, **kwargs):
        found = original(*args, **kwargs)
        interrupt.request()
        return found
    monkeypatch.setattr(module, name, traced)


@pytest.mark.parametrize("settings, stage, what", [
    ([], "modes", "the branches whole, their m ≥ 1 blocks not read"),  # [surface] "first" after them
    (["--set", "stability.m_max=0", "--set", "dynamics.frequencies=true"], "frequencies",
     "the branches whole, the frequencies of none written")])
def test_a_signal_after_the_primary_s_last_check_interrupts_the_stage_after_it(references, tmp_path, capsys,
                                                                              monkeypatch, settings, stage, what):
    """`run --primary-only`: a signal after the primary branch's last point (its branch points being located) skipped
    the m ≥ 1 blocks (and the surface branch after them) or the frequencies, and the file said it was whole: it now
    names the stage not computed, exit 130 with the file's line, the primary branch the uninterrupted run's."""
    from balloon_cg.tube import picture

    _signalled_after(monkeypatch, picture, "primary_branch")
    path = tmp_path / "r.h5"
    assert main(run_argv(str(path)) + ["--primary-only", *settings]) == 130
    assert one_line(capsys.readouterr().err) == (f"balloon-cg: interrupted ({stage}: {what}); what was finished is "
                                                 f"written to {path} (flagged interrupted)")
    run = read_tube_run(path)
    assert run["attrs"]["interrupted"] == stage and set(run["branches"]) == {"primary"}
    assert np.array_equal(run["branches"]["primary"]["unknowns"], references[0]["branches"]["primary"]["unknowns"])
    assert main(["inspect", str(path)]) == 0
    assert f"a signal stopped the {stage} stage" in capsys.readouterr().out


def test_a_signal_after_the_bulge_s_last_check_in_continue_interrupts_its_modes(tmp_path_factory, tmp_path, capsys,
                                                                               monkeypatch):
    """`continue` at the onset label: a signal after the bulge branch's last point: its m ≥ 1 blocks (and the surface
    branch) not read, the file says so (it said whole), exit 130; the bulge is the uninterrupted continue's."""
    from balloon_cg.tube import picture
    from shared_pictures import tube_run_file

    stored = tube_run_file(tmp_path_factory)
    whole = tmp_path / "whole.h5"
    assert main(["continue", str(stored), "1", "-o", str(whole), "--quiet"]) == 0
    _signalled_after(monkeypatch, picture, "traced_bulge")
    path = tmp_path / "c.h5"
    assert main(["continue", str(stored), "1", "-o", str(path), "--quiet"]) == 130
    assert one_line(capsys.readouterr().err) == ("balloon-cg: interrupted (modes: the branches whole, their m ≥ 1 "
                                                 f"blocks not read); what was finished is written to {path} (flagged "
                                                 "interrupted)")
    run, reference = read_tube_run(path), read_tube_run(whole)
    assert run["attrs"]["interrupted"] == "modes" and reference["attrs"]["interrupted"] == ""
    assert np.array_equal(run["branches"]["bulge"]["unknowns"], reference["branches"]["bulge"]["unknowns"])
