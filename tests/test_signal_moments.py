"""A signal at every moment of balloon-cg's own code (issue 42, items 2 and 3): at start-up (the imports, the
argument parsing), at the end of a sweep (the last member stored, the view rebuilt, the summary, after the
command returned, while Python exits) the command ends with exit 130 and one line saying what is kept, or exit 0
when the work had finished (and one line saying so, or nothing once Python exits), never by the signal (−2, −15)
nor with a traceback. The moments are picked by the code's own hooks (an import, a function called), in a fresh
interpreter that sends the signal to itself there: no sleeps, the same on any machine."""
import os
import signal
import subprocess
import sys

import pytest

import balloon_cg as bc
from balloon_cg.numerics import interrupt

from cpu_moments import foreground

# The driver: a hook that sends ``sig`` to this process at ``moment``, then the `balloon-cg` entry point itself.
DRIVER = r'''
import atexit, importlib, os, signal, sys
sig, moment, argv = getattr(signal, sys.argv[1]), sys.argv[2], sys.argv[3:]
fire = lambda: os.kill(os.getpid(), sig)
if moment.startswith("import "):
    class Hook:
        def find_spec(self, name, path=None, target=None):
            if name == moment.removeprefix("import "):
                sys.meta_path.remove(self)
                fire()
    sys.meta_path.insert(0, Hook())
from balloon_cg.__main__ import run
if moment.startswith("after "):  # after a function returns: "after module:function"
    module, _, name = moment.removeprefix("after ").partition(":")
    module = importlib.import_module(module)
    owner, _, attribute = name.rpartition(".")
    holder = getattr(module, owner) if owner else module
    original = getattr(holder, attribute)
    calls = {"n": 0}
    def wrapped(*args, **kwargs):
        value = original(*args, **kwargs)
        calls["n"] += 1
        if calls["n"] == int(os.environ.get("SIGNAL_AT_CALL", "1")):
            fire()
        return value
    setattr(holder, attribute, wrapped)
if moment == "at exit":  # registered before run: Python calls it after run's own exit handler
    atexit.register(fire)
sys.argv = ["balloon-cg", *argv]
sys.exit(run())
'''


def balloon_cg(tmp_path, sig: str, moment: str, argv: list, at_call: int = 1):
    """Run the `balloon-cg` entry point with ``argv``, ``sig`` sent to itself at ``moment``: (exit code, stderr)."""
    env = os.environ | {"BALLOON_CG_WORKERS": "1", "SIGNAL_AT_CALL": str(at_call)}
    done = subprocess.run([sys.executable, "-c", DRIVER, sig, moment, *argv], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path, env=env, preexec_fn=foreground)
    return done.returncode, done.stderr


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 1.4\n'


NOT_STARTED = "balloon-cg: interrupted: nothing is written to r.h5 (the work had not started)"


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("moment, line", [
    ("import balloon_cg.app.cli", "balloon-cg: error: interrupted"),
    ("import numpy", "balloon-cg: error: interrupted"),
    ("import balloon_cg.scene", "balloon-cg: error: interrupted"),
    ("after argparse:ArgumentParser.parse_known_args", "balloon-cg: error: interrupted"),
    ("import balloon_cg.analysis.picture", NOT_STARTED),  # imported as the scene loads: run's contract from there
])
def test_a_signal_at_start_up_exits_130_in_one_line(tmp_path, sig, moment, line):
    (tmp_path / "s.toml").write_text(SCENE)
    code, err = balloon_cg(tmp_path, sig, moment, ["run", "s.toml", "-o", "r.h5", "--quiet"])
    assert code == 130 and one_line(err) == line, (code, err)
    assert not (tmp_path / "r.h5").exists()


@pytest.fixture(scope="module")
def scene_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sweep")
    (folder / "s.toml").write_text(SCENE)
    return folder


SWEEP = ["sweep", "s.toml", "--vary", "stop_stretch=1.2,1.3", "--primary-only", "--workers", "2", "-o", "w.h5",
         "--quiet"]
KEPT = "balloon-cg: interrupted: the finished members are stored; re-run the same command to resume"


@pytest.mark.parametrize("sig, moment, at_call, code, line", [
    ("SIGTERM", "after balloon_cg.io.sweep_file:Store.write_member", 2, 130, KEPT),  # the last member stored
    ("SIGINT", "after balloon_cg.io.sweep_file:View.catch_up", 2, 130, KEPT),  # the view finishing (its table)
    ("SIGTERM", "after balloon_cg.io.sweep_file:View.finish", 1, 130, KEPT),  # the view finished, not renamed
    ("SIGTERM", "after balloon_cg.app.sweep:run_sweep", 1, 130, KEPT),
    ("SIGINT", "after balloon_cg.app.cli:main", 1, 130, "balloon-cg: error: interrupted"),  # before run has it
    ("SIGINT", "after balloon_cg.__main__:_over", 1, 0, "balloon-cg: SIGINT after the work had finished: exit 0"),
    ("SIGTERM", "at exit", 1, 0, None),
], ids=["last member stored", "view finishing", "view finished", "sweep returned", "command returning", "command over",
        "python exiting"])
def test_a_signal_at_the_end_of_a_sweep_exits_130_or_0_and_says_so(scene_folder, tmp_path, sig, moment, at_call,
                                                                    code, line):
    """Exit 130 where the command had not returned to the entry point (the file is whole all the same: the same
    command resumes it, computing nothing), 0 after; one line each, never −2 or −15."""
    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "s.toml").write_text(SCENE)
    got, err = balloon_cg(folder, sig, moment, SWEEP, at_call)
    assert got == code, (got, err)
    assert (err.strip() == "") if line is None else (one_line(err) == line), err
    assert sorted(bc.load(folder / "w.h5").members) == [0, 1]  # both members stored and in the view
    again, err = balloon_cg(folder, "SIGTERM", "never", SWEEP)  # no signal
    assert again == 0 and err == "", err


LOADS = {"run": ["run", "s.toml", "-o", "out.h5", "--quiet"],
         "critical": ["critical", "s.toml", "--parameter", "alpha1", "-o", "out.h5", "--quiet"]}


@pytest.mark.parametrize("command, moment, sig", [
    ("run", "after balloon_cg.scene.tables:_read_text", "SIGINT"),  # the scene file read, not parsed
    ("run", "after balloon_cg.app.cli:configured", "SIGTERM"),  # the scene and its settings loaded
    ("critical", "after balloon_cg.scene.tables:_read_text", "SIGTERM"),
    ("critical", "after balloon_cg.app.cli:configured", "SIGINT"),
    ("critical", "after balloon_cg.analysis.critical.second_parameter:resolve", "SIGTERM"),  # its kernels bound
])
def test_a_signal_while_the_scene_loads_writes_nothing_and_says_so(tmp_path, command, moment, sig):
    """`run` and `critical` load their scene (and `critical` its kernels) under the interrupt contract of the work
    (numerics.interrupt.stop_on_signals, as `continue` reads its file): the signal only sets the flag, so no
    KeyboardInterrupt is raised where a finalizer (h5py's) could swallow it (a traceback and exit 0), and the command
    exits 130 saying nothing is written, and writes nothing."""
    (tmp_path / "s.toml").write_text(SCENE)
    code, err = balloon_cg(tmp_path, sig, moment, LOADS[command])
    assert code == 130, (code, err)
    assert one_line(err) == "balloon-cg: interrupted: nothing is written to out.h5 (the work had not started)", err
    assert not (tmp_path / "out.h5").exists() and not list(tmp_path.glob(".out.h5*"))


def test_a_signal_swallowed_while_the_last_member_is_copied_still_stops_the_sweep(tmp_path, monkeypatch):
    """A signal whose KeyboardInterrupt is swallowed (it landed in a finalizer, h5py's, while a member was copied
    into the view: once in CI) has still set the flag: the sweep stops after that member as if it had raised, even
    when it is the pool's last (the pool's loop checks the flag only between its waits). The swallowing is played
    by setting the flag in the last ``View.add``; the view then holds every stored member."""
    from balloon_cg.app.sweep import run_sweep
    from balloon_cg.io import sweep_file
    from balloon_cg.numerics import interrupt
    from balloon_cg.scene import load_scene

    add, calls = sweep_file.View.add, []

    def add_then_swallowed(view, index):
        add(view, index)
        calls.append(index)
        if len(calls) == 3:
            interrupt.request()

    monkeypatch.setattr(sweep_file.View, "add", add_then_swallowed)
    with interrupt.sigterm_raises(), pytest.raises(KeyboardInterrupt):
        run_sweep(load_scene("spom1"), ["stop_stretch=1.1:1.3:3"], tmp_path / "w.h5", mode="primary-only",
                  workers=2)
    assert len(calls) == 3 and sorted(bc.load(tmp_path / "w.h5").members) == sorted(calls)


@pytest.mark.parametrize("stage", ["write_member", "copy_tree"])
def test_a_signal_while_a_member_is_written_or_copied_is_not_raised_inside_h5py(tmp_path, monkeypatch, stage):
    """The sweep's parent writes each member to the store (``Store.write_member``) and copies it into the view
    (``View.add``: h5py's copy) under ``sigterm_raises``: a KeyboardInterrupt raised inside an h5py call can surface
    as "SystemError: <cyfunction FastRLock.__exit__> returned a result with an exception set" (exit 3: seen once in
    test_cli_conventions' interrupted sweep under load). A signal there only sets the flag: the call finishes, and
    the sweep stops right after it (KeyboardInterrupt), the member stored and in the view. The signal is raised from
    inside the h5py work (the member file's verdict written, the copy's start)."""
    from balloon_cg.app.sweep import run_sweep
    from balloon_cg.io import hdf5, run_file, sweep_file
    from balloon_cg.scene import load_scene

    finished = []

    def signalling(original):
        def inside(*args, **kwargs):
            if not finished:
                signal.raise_signal(signal.SIGTERM)  # the handler runs here, inside the h5py work
                finished.append(stage)  # reached only if the handler did not raise
            return original(*args, **kwargs)
        return inside

    if stage == "copy_tree":
        monkeypatch.setattr(sweep_file, "copy_tree", signalling(hdf5.copy_tree))
    else:
        monkeypatch.setattr(sweep_file, "verdict_attrs", signalling(run_file.verdict_attrs))
    with interrupt.sigterm_raises(), pytest.raises(KeyboardInterrupt):
        run_sweep(load_scene("spom1"), ["stop_stretch=1.1:1.3:3"], tmp_path / "w.h5", mode="primary-only",
                  workers=1)
    assert finished == [stage]
    assert sorted(bc.load(tmp_path / "w.h5").members) == [0]
