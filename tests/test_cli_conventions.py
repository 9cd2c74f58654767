"""CLI conventions: --version, python -m balloon_cg, run --set and the default output name, plot --what a,b,
strict JSON from inspect (run, sweep and curve files), SIGINT on a running run."""
import fcntl
import json
import os
import select
import shutil
import shlex
import signal
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import balloon_cg
from balloon_cg.app.cli import SCENE_HELP, build_parser, main, scene_of, strict_json
from balloon_cg.io.run_file import read_run
from balloon_cg.scene import load_scene, parse_scene
from shared_pictures import SMALL, small_run_file

SCENES = Path(__file__).resolve().parents[1] / "scenes"


def cli(*args, cwd=None, **kw):
    return subprocess.run([sys.executable, "-m", "balloon_cg", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, **kw)


def test_version_and_module_entry_point():
    done = cli("--version")
    assert done.returncode == 0 and done.stdout.strip() == f"balloon-cg {balloon_cg.__version__}"
    done = cli("--help")
    assert done.returncode == 0 and "run" in done.stdout and "Documentation:" in done.stdout
    docs = done.stdout.split("Documentation:")[1].split()[0]
    assert (Path(docs) / "plots.md").is_file()  # the help names installed documentation


def test_every_scene_argument_says_what_it_takes():
    """Each subcommand's SCENE goes to scene.load_scene (a file, or the name of a shipped scene): its help says
    so (kernels' said "scene TOML file" only)."""
    import argparse

    commands = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices
    helps = {name: a.help for name, p in commands.items() for a in p._actions if a.dest == "scene"}
    assert set(helps) == {"run", "solve", "critical", "sweep", "kernels"}
    assert all(text.startswith(SCENE_HELP) for text in helps.values()), helps


def test_help_speaks_of_every_shape():
    """``balloon-cg --help`` names the four reference shapes, and the help of every command that computes on or reads a
    tube says what it does with one (they spoke of spheres only: pear branches, a north pole stretch); the examples
    include a shipped tube scene that loads."""
    from balloon_cg.app.cli import EXAMPLES
    from balloon_cg.scene import load_scene

    parser = build_parser()
    top = " ".join(parser.format_help().split())
    assert all(shape in top for shape in ("sphere", "spheroid", "capsule", "tube")), top
    for name in ("run", "solve", "inspect", "plot", "sweep", "critical", "continue"):
        text = " ".join(parser.subcommands[name].format_help().split())
        assert "tube" in text, name
    critical = " ".join(parser.subcommands["critical"].format_help().split())
    assert all(q in critical for q in ("M", "voltage", "axial_stretch")), critical  # the tube onset's parameters
    for name in ("run", "solve", "critical"):
        assert any("tube_spom1_L10" in line for line in EXAMPLES[name]), name
    assert load_scene("tube_spom1_L10").geometry.shape == "tube" and load_scene("tube_spom1_L10_coil").field.coils


def test_run_set_renames_and_writes_the_default_output(tmp_path, monkeypatch):
    scene = tmp_path / "small_M0.toml"
    scene.write_text(SMALL)
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(scene), "--set", "continuation.stop_stretch=1.5", "--set", "solver.degree=30",
                 "--primary-only", "--quiet"]) == 0
    run = read_run(tmp_path / "small_M0_stop_stretch1.5_degree30.h5")  # the scene keeps its name, the file shows all
    assert run["scene_name"] == "small_M0" and run["branches"]["primary"]["lam2_top"].max() == pytest.approx(1.5,
                                                                                                            abs=1e-12)
    assert "stop_stretch = 1.5" in run["attrs"]["scene_toml"] and "degree = 30" in run["attrs"]["scene_toml"]
    # --max-points 15 stops the up leg short: written, flagged, exit 1
    assert main(["run", str(scene), "--set", "M=0", "--set", "material.preset=TPOM1", "--max-points", "15",
                 "--primary-only", "--quiet"]) == 1
    run = read_run(tmp_path / "small_M0_tpom1_max_points15.h5")  # renamed after the material, named after the limit
    assert len(run["branches"]["primary"]["pressure"]) <= 2 * 15 + 1 and not run["attrs"]["complete"]
    assert sorted(p.name for p in tmp_path.glob("*.h5")) == ["small_M0_stop_stretch1.5_degree30.h5",
                                                             "small_M0_tpom1_max_points15.h5"]


def test_default_output_names_show_the_settings():
    from balloon_cg.scene.tables import output_stem

    assert output_stem("spom1", {"continuation.stop_stretch": 3.0}) == "spom1_stop_stretch3"
    assert output_stem("spom1_M0.002", {"field.M": 0.002, "solver.degree": 60}) == "spom1_M0.002_degree60"
    assert output_stem("spom1_M0.002", {"field.M": None}) == "spom1_Mdefault"
    assert output_stem("spom1_tpom1", {"material.preset": "TPOM1", "continuation.symmetry": "none"}) == \
        "spom1_tpom1_symmetrynone"
    assert output_stem("spom1", {"material.alpha[1]": 3}) == "spom1_alpha1=3"


@pytest.mark.parametrize("command, default", [
    (["critical", "spom1", "--parameter", "alpha1", "--set", "solver.degree=30"], "spom1_degree30_critical_alpha1.h5"),
    (["critical", "spom1_single_coil", "--parameter", "field.M"], "spom1_single_coil_critical_M.h5"),
    (["sweep", "spom1_two_coils_M0.002", "--vary", "M=0:0.003:num=4", "--vary", "field.coils[0].radius=2,3"],
     "spom1_two_coils_M0.002_sweep_M_radius.h5"),
    (["figure", "fig9", "--quick"], "fig9.pdf"),
    (["figure", "all", "--quick"], "paper-figures/fig2.pdf"),
    (["run", "spom1", "--stop-stretch", "3"], "spom1_stop_stretch3.h5"),
])
def test_every_writing_command_has_a_default_output_that_is_never_overwritten(tmp_path, monkeypatch, capsys,
                                                                              command, default):
    """-o is optional for run, critical, sweep and figure; the default name is checked by the one rule for outputs
    before anything is computed: a file already there (here a text file) is refused without --force (exit 2)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / default).parent.mkdir(exist_ok=True)
    (tmp_path / default).write_text("an earlier result")
    assert main(command) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and default in err[0] and "already exists (use --force" in err[0], err
    assert (tmp_path / default).read_text() == "an earlier result"


@pytest.mark.parametrize("setting, words", [
    ("field.M=-1", ("field.M = -1", "in [0, 1000]")),
    ("nope=1", ("--set nope", "not a scene key")),
    ("M=0:1:3", ("--set M=0:1:3", "one value")),
    ("continuation.max_points=abc", ("max_points", "abc")),
    ("field.M", ("--set field.M", "KEY=VALUE")),
    ("=3", ("KEY=VALUE",)),
])
def test_bad_set_is_one_line(tmp_path, capsys, setting, words):
    out = tmp_path / "x.h5"
    assert main(["run", str(SCENES / "spom1.toml"), "--set", setting, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("balloon-cg: error: ") and all(w in err for w in words), err
    assert not out.exists()


@pytest.mark.parametrize("command", [
    ["run", str(SCENES / "spom1.toml")],
    ["critical", str(SCENES / "spom1_two_coils_M0.002.toml"), "--parameter", "M"],
    ["sweep", str(SCENES / "spom1.toml"), "--vary", "M=0:0.001:2"],
])
def test_an_hdf5_output_with_another_suffix_is_refused_and_left_alone(tmp_path, capsys, command):
    """-o results.txt would write HDF5 under a text file's name (with --force: over the text file)."""
    out = tmp_path / "results.txt"
    out.write_text("my notes\n")
    assert main([*command, "-o", str(out), "--force"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--output {out}" in err and ".h5, .hdf5" in err, err
    assert out.read_text() == "my notes\n"


def test_shorthand_and_set_of_the_same_key_conflict(tmp_path, capsys):
    assert main(["run", "spom1", "--set", "continuation.max_points=4", "--max-points", "3",
                 "-o", str(tmp_path / "x.h5")]) == 2
    assert "given twice" in capsys.readouterr().err and not (tmp_path / "x.h5").exists()


def test_unset_restores_the_default_and_a_key_is_given_once(tmp_path, capsys):
    """--unset KEY gives the value a scene without that key parses to; a key given twice, in any spelling, or
    set and unset, is one line and exit 2 before any computation."""
    args = build_parser().parse_args(["run", "spom1", "--unset", "stop_stretch", "--set", "solver.degree=12"])
    scene = scene_of(args)
    default = parse_scene('[material]\npreset = "SPOM1"\n').continuation.stop_stretch
    assert scene.continuation.stop_stretch == default != load_scene("spom1").continuation.stop_stretch
    assert scene.solver.degree == 12
    out = tmp_path / "x.h5"
    for flags, words in ((["--set", "M=0", "--set", "field.M=0"], "given twice"),
                         (["--unset", "continuation.stop_stretch", "--stop-stretch", "3"], "also given a value"),
                         (["--unset", "nope"], "--unset nope: not a scene key")):
        assert main(["run", "spom1", *flags, "-o", str(out)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and words in err, err
    assert not out.exists()


def test_inspect_json_is_strict_for_run_sweep_and_curve_files(tmp_path, tmp_path_factory, capsys):
    """The run: the session's `run` of SMALL (shared_pictures.small_run_file)."""
    scene = tmp_path / "small.toml"
    scene.write_text(SMALL)
    run, sweep = small_run_file(tmp_path_factory), tmp_path / "sweep.h5"
    assert main(["sweep", str(scene), "--vary", "continuation.stop_stretch=1.5,1.6", "--primary-only",
                 "--workers", "1", "-o", str(sweep), "--quiet"]) == 0
    capsys.readouterr()
    for path, kind in ((run, None), (sweep, "sweep")):
        assert main(["inspect", str(path), "--json"]) == 0
        text = capsys.readouterr().out
        summary = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-standard JSON constant {c}"))
        assert summary.get("kind") == kind
        assert main(["inspect", str(path)]) == 0
        header = capsys.readouterr().out.split("\n\n")[0].splitlines()
        assert header[0].startswith("file ") and all(line[14] == " " != line[15] for line in header), header
    assert len(summary["members"]) == 2
    assert strict_json({"a": float("nan"), "b": [float("inf"), 1.0]}) == '{"a": null, "b": [null, 1.0]}'


def test_a_closed_stdout_ends_quietly():
    """`balloon-cg inspect FILE | head`: the reader goes away; no error line, the SIGPIPE status 141."""
    fixture = Path(__file__).parent / "data" / "spom1_format2.h5"
    process = subprocess.Popen([sys.executable, "-m", "balloon_cg", "inspect", str(fixture), "--json"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    process.stdout.close()
    assert process.wait(timeout=60) == 141
    assert process.stderr.read() == b""


def test_plot_several_kinds_at_once(tmp_path, tmp_path_factory, capsys):
    run = small_run_file(tmp_path_factory)  # the session's `run` of SMALL
    assert main(["plot", str(run), "--what", "pressure-pole,shapes", "-o", str(tmp_path / "fig.pdf")]) == 0
    assert capsys.readouterr().out.split() == [str(tmp_path / "fig_pressure-pole.pdf"), str(tmp_path / "fig_shapes.pdf")]
    with pytest.raises(SystemExit) as bad:
        main(["plot", str(run), "--what", "pressure-pole,nonsense"])
    assert bad.value.code == 2
    assert "not a plot kind" in capsys.readouterr().err


@pytest.mark.parametrize("command", [
    ["run", "SCENE", "--primary-only", "-o", "run.h5"],
    ["sweep", "SCENE", "--vary", "continuation.stop_stretch=1.3,1.4", "--primary-only", "--workers", "1",
     "-o", "sweep.h5"],
])
def test_progress_is_drawn_on_a_terminal_only(tmp_path, command):
    """stderr to a file or a pipe: no carriage returns or cursor codes (tqdm's disable=None: no bar on a
    non-TTY); the same command with stderr on a terminal (a pty) draws its bars."""
    scene = tmp_path / "small.toml"
    scene.write_text(SMALL.replace("2.0", "1.5"))
    args = [str(scene) if a == "SCENE" else a for a in command]
    piped = subprocess.run([sys.executable, "-m", "balloon_cg", *args], capture_output=True, cwd=tmp_path)  # bytes:
    assert piped.returncode == 0, piped.stderr  # text mode would turn a carriage return into a newline
    assert b"\r" not in piped.stderr + piped.stdout and b"\x1b" not in piped.stderr + piped.stdout, piped.stderr
    terminal = Terminal()
    process = terminal.start([sys.executable, "-m", "balloon_cg", *args, "--force"], cwd=tmp_path)
    shown = terminal.finish(process, 300)
    assert process.returncode == 0
    bar = "primary branch: " if command[0] == "run" else "sweep: "
    assert f"\r{bar}" in shown or f"\rsmall: {bar}" in shown, repr(shown)


class Terminal:
    """A pseudo-terminal of 100 columns for a child's stderr (a new pty has 0 columns: tqdm would draw empty
    bars); what the child writes there is read as it comes, so that the terminal's buffer never fills."""

    def __init__(self):
        import pty

        self.master, self.slave = pty.openpty()
        fcntl.ioctl(self.slave, termios.TIOCSWINSZ, struct.pack("HHHH", 30, 100, 0, 0))
        self.data = b""

    def start(self, command, **kw) -> subprocess.Popen:
        process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=self.slave,
                                   **kw)
        os.close(self.slave)
        return process

    def read(self, wait: float = 0.2) -> bytes:
        """All written so far, after waiting up to ``wait`` s for more."""
        if select.select([self.master], [], [], wait)[0]:
            try:
                self.data += os.read(self.master, 1 << 16)
            except OSError:  # EIO: the child closed its end
                pass
        return self.data

    def finish(self, process, timeout: float) -> str:
        """Read until ``process`` has ended and written all; its exit code is checked by the caller."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            before = len(self.data)
            if len(self.read()) == before and process.poll() is not None:
                break
        os.close(self.master)
        process.wait(timeout=10)
        return self.data.decode(errors="replace")


def cpu_seconds(pid: int) -> float:
    """User and system CPU time of a live process and of its children it has waited for (/proc/PID/stat)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    return sum(int(f) for f in fields[11:15]) / os.sysconf("SC_CLK_TCK")  # utime, stime, cutime, cstime


def children_cpu_seconds() -> float:
    import resource

    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def test_sigint_writes_a_readable_partial_file_and_exits_130(tmp_path):
    """A two-coil analysis takes ~20 s; interrupted after its primary branch started (its bar is drawn on the
    terminal), it writes what is finished. The work done after the signal is bounded in CPU time, which a loaded
    machine does not stretch (the wall clock is only a hang guard)."""
    out = tmp_path / "int.h5"
    terminal = Terminal()
    before = children_cpu_seconds()
    process = terminal.start([sys.executable, "-m", "balloon_cg", "run",
                              str(SCENES / "spom1_two_coils_M0.002.toml"), "-o", str(out)])
    deadline = time.monotonic() + 600
    while b"primary branch" not in terminal.read() and time.monotonic() < deadline:
        pass
    time.sleep(1.0)
    at_signal = cpu_seconds(process.pid)
    process.send_signal(signal.SIGINT)
    err = terminal.finish(process, 600)
    assert process.returncode == 130, err
    assert children_cpu_seconds() - before - at_signal < 30
    assert "Traceback" not in err and err.strip().splitlines()[-1].startswith("balloon-cg: interrupted")
    run = read_run(out)
    assert not run["attrs"]["complete"] and "interrupted" in run["attrs"]["incomplete_gaps"]
    assert len(run["branches"]["primary"]["pressure"]) > 0
    with h5py.File(out, "r") as f:
        assert f.attrs["format"].startswith("balloon-cg/")


def test_sigterm_on_critical_writes_the_partial_curve_and_exits_130(tmp_path, monkeypatch, capsys):
    """`critical` as `run`: a SIGTERM during the curve of pitchforks (raised for real, at its fifth point: the
    whole curve takes well under a second, too short to hit from outside) ends it at its next point; the curve so
    far is written (atomically, end interrupted), one line says so, exit 130."""
    from balloon_cg.analysis.critical import pitchfork_curve as codim2
    from balloon_cg.io.curve_file import read_curve

    follow = codim2.continue_branch_point

    def signalled(*args, progress, **kw):
        count = []

        def tick(point):
            count.append(point)
            if len(count) == 5:
                signal.raise_signal(signal.SIGTERM)  # goes to the handler critical installed
            progress(point)
        return follow(*args, progress=tick, **kw)

    monkeypatch.setattr(codim2, "continue_branch_point", signalled)
    out = tmp_path / "curve.h5"
    assert main(["critical", "spom1_single_coil", "--parameter", "M", "-o", str(out)]) == 130
    captured = capsys.readouterr()
    assert captured.out == "" and "Traceback" not in captured.err
    last = captured.err.splitlines()[-1]
    assert last.startswith(f"balloon-cg: interrupted: the curve is written to {out} (end: interrupted"), captured.err
    curve = read_curve(out)
    assert curve["attrs"]["end"] == curve["attrs"]["stop_code"] == "interrupted"
    assert 5 <= len(curve["q"]) <= 7 and np.isnan(curve["attrs"]["critical_q"])
    assert main(["inspect", str(out)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["curve.h5"]  # no temporary file left


def test_critical_interrupted_before_its_curve_leaves_the_output_alone(tmp_path, monkeypatch, capsys):
    """A signal during the primary branch: nothing to write; an existing output (--force) is left as it was."""
    from balloon_cg.analysis.branches import primary
    from balloon_cg.numerics import interrupt

    trace = primary.trace_primary

    def interrupted_trace(*args, **kw):
        interrupt.request()  # as the handler does: the trace stops at its first point
        return trace(*args, **kw)

    monkeypatch.setattr(primary, "trace_primary", interrupted_trace)
    out = tmp_path / "curve.h5"
    out.write_bytes(b"an earlier result")
    assert main(["critical", "spom1", "--parameter", "alpha1", "-o", str(out), "--force", "--quiet"]) == 130
    err = capsys.readouterr().err
    assert err == f"balloon-cg: interrupted: nothing is written to {out} (the curve had not started)\n"
    assert out.read_bytes() == b"an earlier result" and not interrupt.requested()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["curve.h5"]  # no temporary file left


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_sweep_abandons_its_running_members_and_resumes(tmp_path, sig):
    """Members of a few seconds each on 2 workers: the signal comes once the first member is stored; the
    running members are abandoned (workers terminated: none left), the stored ones kept, exit 130, and the same
    command resumes. How soon it stops is checked in CPU time, not here in wall time (a loaded machine stretches
    wall time at random): tests/test_interrupt_moments.py."""
    out = tmp_path / "sweep.h5"
    command = [sys.executable, "-m", "balloon_cg", "sweep", "spom1_two_coils_M0.002", "--vary",
               "M=0.001,0.0012,0.0014,0.0016,0.0018,0.002", "--no-pear", "--workers", "2", "-o", str(out), "--quiet"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    store = Path(f"{out}.members")
    deadline = time.monotonic() + 600
    while not any(store.glob("0*.h5")) and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.1)
    if process.poll() is not None:  # say how it ended (seen once under load: no diagnosis was printed)
        pytest.fail(f"the sweep ended (exit {process.returncode}) before it could be interrupted; stored "
                    f"{sorted(p.name for p in store.glob('*'))}; stderr: {process.communicate()[1][-3000:]}")
    process.send_signal(sig)
    _, err = process.communicate(timeout=600)
    assert process.returncode == 130, err
    assert "interrupted" in err and "Traceback" not in err
    stored = len(list(store.glob("0*.h5")))
    assert 1 <= stored < 6
    assert subprocess.run(["pgrep", "-f", "--", str(out)], capture_output=True).returncode == 1  # no worker left
    resumed = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    assert len(list(store.glob("0*.h5"))) == 6


@pytest.mark.parametrize("argv, suggestion", [
    (["rn", "spom1"], "'rn': not a command (did you mean run?)"),
    (["--debug", "plt", "x.h5"], "'plt': not a command (did you mean plot?)"),
    (["run", "spom1", "--set", "continuation.stop_strech=3"], "unknown key (did you mean stop_stretch?)"),
    (["run", "spom1", "--set", "material.preset=SPOM3"], "unknown preset (did you mean SPOM2?)"),
    (["run", "spom1_two_coil_M0.002"], "(did you mean spom1_two_coils_M0.002?)"),
    (["run", str(SCENES / "spom1.tml")], f"No such file or directory (did you mean {SCENES / 'spom1.toml'}?)"),
    (["plot", "x.h5", "--what", "presure-pole"], "not a plot kind (did you mean pressure-pole?)"),
    (["run", "spom1", "--stop-strech", "3"], "run: unrecognized arguments: --stop-strech 3 (did you mean "
                                             "--stop-stretch?; balloon-cg run -h lists its options)"),
    (["inspect", "x.h5", "--jsn=1"], "inspect: unrecognized arguments: --jsn=1 (did you mean --json?;"),
    (["run", "spom1", "--stop-stretch=3", "--set", "alpa1=1.4"], "not a scene key (did you mean alpha1?)"),
])
def test_a_near_miss_gets_a_suggestion(argv, suggestion, tmp_path, monkeypatch, capsys):
    """A mistyped subcommand, scene key, preset, shipped scene, file name or plot kind: the error line (exit 2)
    names the nearest allowed name."""
    monkeypatch.chdir(tmp_path)
    try:
        code = main(argv + ["-o", str(tmp_path / "out.h5")] * (argv[0] == "run"))
    except SystemExit as e:  # argparse's own errors (a bad --what)
        code = e.code
    err = capsys.readouterr().err
    assert code == 2 and suggestion in err.strip().splitlines()[-1], err  # the error line (after argparse's usage)


def test_every_subcommand_help_ends_with_examples_that_parse(capsys):
    parser = build_parser()
    for name in parser.commands:
        with pytest.raises(SystemExit):
            main([name, "--help"])
        help_text = capsys.readouterr().out
        examples = help_text.split("examples:\n", 1)[1].strip().splitlines()
        assert examples, name
        for example in examples:
            words = shlex.split(example.split(" > ")[0])  # the command, not where the shell writes its output
            assert words[:2] == ["balloon-cg", name]
            assert build_parser().parse_args(words[1:]).command == name


@pytest.mark.skipif(shutil.which("bash") is None, reason="needs bash")
def test_bash_completion_completes_commands_options_and_choices(tmp_path, capsys):
    """`balloon-cg completion bash` (shtab) is a script bash sources; its function completes a subcommand, an
    option of a subcommand and a choice."""
    assert main(["completion", "bash"]) == 0
    script = tmp_path / "balloon-cg.bash"
    script.write_text(capsys.readouterr().out)
    probe = ("source {script}; complete_line() {{ COMP_WORDS=(\"$@\"); COMP_CWORD=$(($# - 1)); COMPREPLY=(); "
             "_shtab_balloon_cg; echo \"${{COMPREPLY[*]}}\"; }}; complete_line balloon-cg pl; "
             "complete_line balloon-cg run --primary; complete_line balloon-cg completion ''").format(script=script)
    lines = subprocess.run(["bash", "-c", probe], capture_output=True, text=True, check=True).stdout.splitlines()
    assert lines == ["plot", "--primary-only", "bash zsh tcsh"]
