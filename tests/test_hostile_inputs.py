"""What a scene or a command line from someone else can ask (issue 30, items 3, 5, 6, 8-11, 14, 15): a valid scene
never ends in an internal error, and a bad one, or a product of keys that would exhaust the machine, is one line
naming the key, the value and the allowed range (exit 2), before any work."""
import os
import time

import pytest

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.results import Kind
from balloon_cg.app.cli import main
from balloon_cg.app.sweep import cpu_count
from balloon_cg.scene import parse_scene

SPOM1 = '[material]\npreset = "SPOM1"\n'
COILS = ("[[field.coils]]\nradius = 1.7321\nheight = 1.0\ncurrent = 1.0\n"
         "[[field.coils]]\nradius = 1.7321\nheight = -1.0\ncurrent = -1.0\n")


def one_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("balloon-cg: error: ") and "internal error" not in err[0]
    return err[0]


def test_issue30_item3_zero_field_between_coils_without_symmetry_is_the_sphere_problem():
    """M = 0 leaves the axial translation free (the field energy is proportional to M): it is removed from the
    unknowns as without coils, so the general layout gives the symmetric layout's branch (it was a singular
    tangent matrix, 'internal error (LinAlgError: Singular matrix)')."""
    text = f'[material]\npreset = "TPOM1"\n[field]\nM = 0.0\n{COILS}[continuation]\nstop_stretch = 1.5\n'
    general = trace_primary(parse_scene(text + 'symmetry = "none"\n'))
    symmetric = trace_primary(parse_scene(text))
    assert general.disc.pin_translation and not general.disc.symmetric
    folds = [[s.X[-1] for s in b.special if s.kind == Kind.LP] for b in (general, symmetric)]
    assert len(folds[0]) == len(folds[1]) == 1
    assert folds[0][0] == pytest.approx(folds[1][0], rel=1e-8)


BAD = {  # scene text -> words of the one line
    "mu = [1e308]": ('[material]\nmu = [1e308]\nalpha = [2.0]\n', "material.mu[0] = 1e+308"),
    "mu tiny, alpha huge": ('[material]\nmu = [1e-300]\nalpha = [1e300]\n', "material.alpha[0] = 1e+300"),
    "alpha 200": ('[material]\nmu = [0.01]\nalpha = [200.0]\n', "within ±100"),
    "formula parameter": ('[material]\nenergy = "c*(I1 - 3)"\n[material.parameters]\nc = 1e308\n',
                          "material.parameters.c = 1e+308"),
    "M": (f'{SPOM1}[field]\nM = 1e308\n{COILS}', "field.M = 1e+308: must be in [0, 1000]"),  # one bound, quoted once
    "M = 2000": (f"{SPOM1}[field]\nM = 2000.0\n{COILS}", "field.M = 2000.0: must be in [0, 1000]"),
    "coil current": (f'{SPOM1}[field]\nM = 0.001\n{COILS.replace("current = 1.0", "current = 1e308")}',
                     "field.coils[0].current = 1e+308"),
    "coil radius": (f'{SPOM1}[field]\nM = 0.001\n{COILS.replace("radius = 1.7321", "radius = 1e5", 1)}',
                    "field.coils[0].radius = 100000.0: must be in (0, 1000]"),
    "stop_stretch": (f'{SPOM1}[continuation]\nstop_stretch = 1e5\n', "continuation.stop_stretch"),
    "tol": (f'{SPOM1}[solver]\ntol = 1e-300\n', "solver.tol = 1e-300"),
    "voltage": (f'{SPOM1}[electric]\nvoltage = 1e6\n', "electric.voltage"),
    "product of keys": (f'{SPOM1}[output]\ntheta_points = 100001\n[continuation]\nmax_points = 100000\n'
                        'step = 1e-4\nstep_max = 1e-4\nstop_stretch = 5\n', "output.memory_limit"),
    "many coils": (SPOM1 + "[field]\nM = 0.001\n" + "".join(
        f"[[field.coils]]\nradius = {2 + i}\nheight = 0.0\ncurrent = 1.0\n" for i in range(10_000)),
        "10000 coils; at most 64"),
    "huge scene": (SPOM1 + "# " + "x" * (1 << 20) + "\n", "larger than 1024 KiB"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_magnitudes_and_products_are_one_line_before_any_work(case, tmp_path, capsys):
    text, words = BAD[case]
    scene = tmp_path / "s.toml"
    scene.write_text(text)
    start = time.process_time()  # CPU time: a loaded machine stretches the wall clock, not the work
    assert main(["run", str(scene), "-o", str(tmp_path / "x.h5"), "--quiet"]) == 2
    assert time.process_time() - start < 60  # validation only (10^4 coils took 53 s to be refused)
    assert words in one_line(capsys) and not (tmp_path / "x.h5").exists()


def test_memory_limit_raises_the_product_bound():
    text = f'{SPOM1}[output]\ntheta_points = 2001\n[continuation]\nmax_points = 100000\n'
    with pytest.raises(Exception, match="output.memory_limit"):
        parse_scene(text)
    scene = parse_scene(text.replace("[output]\n", "[output]\nmemory_limit = 30.0\n"))
    assert scene.output.memory_limit == 30.0 and "memory_limit = 30.0" in scene.to_toml()
    assert "memory_limit" not in parse_scene(SPOM1).to_toml()  # the default keeps older scene texts (and hashes)


@pytest.mark.parametrize("argv, words", [
    (["--workers", "100000"], "--workers 100000: must be in [1, "),
    (["--workers", "100000", "--oversubscribe"], "--workers 100000: must be in [1, "),
    (["--workers", "0"], "--workers 0"),
    (["--scheduler", "not a url"], "not a scheduler address"),
    (["--scheduler", "tcp://127.0.0.1:8786", "--workers", "1"], "give one of the two"),
    (["--vary", "M=0:inf:3"], "must be finite"),
])
def test_sweep_command_line_bounds(argv, words, tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(f'{SPOM1}[field]\nM = 0.001\n{COILS}')
    vary = [] if "--vary" in argv else ["--vary", "M=0.001,0.002"]
    assert main(["sweep", str(scene), *vary, *argv, "-o", str(tmp_path / "x.h5"), "--quiet"]) == 2
    assert words in one_line(capsys)
    assert not list(tmp_path.glob("x.h5*"))


def test_workers_up_to_the_cpu_count_are_accepted():
    from balloon_cg.app.cli import check_workers

    check_workers(cpu_count(), False, None)
    check_workers(cpu_count() + 1, True, None)


def test_oversubscribe_is_bounded_by_the_available_memory(monkeypatch):
    """--oversubscribe starts no more workers than the available memory holds at WORKER_MEMORY each (64 workers of
    ~140 MB on a 23 GB machine were allowed up to 256), and at most MAX_WORKERS where memory is plenty or unknown."""
    from balloon_cg.app import sweep
    from balloon_cg.app.cli import MAX_WORKERS, UsageError, check_workers

    monkeypatch.setattr(sweep, "available_memory", lambda: 10 * sweep.WORKER_MEMORY + 1)
    check_workers(10, True, None)
    with pytest.raises(UsageError, match=r"--workers 11: must be in \[1, 10\] \(with --oversubscribe: the workers of "
                                         r"~160 MiB each that the available memory, 1.56 GiB, holds\)"):
        check_workers(11, True, None)
    for plenty in (None, 1000 * sweep.WORKER_MEMORY):
        monkeypatch.setattr(sweep, "available_memory", lambda: plenty)
        check_workers(MAX_WORKERS, True, None)
        with pytest.raises(UsageError, match=rf"must be in \[1, {MAX_WORKERS}\]$"):
            check_workers(MAX_WORKERS + 1, True, None)


def test_the_default_worker_count_is_the_affinity_not_the_machine(monkeypatch):
    """A process allowed one CPU of 64 (a cluster job's cgroup, taskset) runs one worker by default, as --workers
    is capped at (it forked os.cpu_count() workers before)."""
    import os

    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {3}, raising=False)
    monkeypatch.setattr(os, "cpu_count", lambda: 64)
    assert cpu_count() == 1


@pytest.mark.parametrize("kind", ["empty", "directory", "fifo", "device"])
def test_a_scene_path_that_is_not_a_regular_file_is_one_line(kind, tmp_path, capsys):
    path = {"empty": "", "directory": str(tmp_path), "fifo": str(tmp_path / "s.toml"), "device": "/dev/zero"}[kind]
    if kind == "fifo":
        os.mkfifo(path)  # nobody writes it: reading it would block forever
    if kind == "device" and not os.path.exists(path):
        pytest.skip("no /dev/zero")
    assert main(["run", path, "-o", str(tmp_path / "x.h5"), "--quiet"]) == 2
    line = one_line(capsys)
    assert {"empty": "empty scene path", "directory": "Is a directory", "fifo": "not a regular file",
            "device": "not a regular file"}[kind] in line


def test_figure_width_is_checked_before_any_run(tmp_path, capsys):
    assert main(["figure", "fig2", "-o", str(tmp_path / "f.pdf"), "--width", "1e6", "--quick"]) == 2
    assert "--width 1e+06: must be in [1, 40]" in one_line(capsys)
    assert not (tmp_path / "runs").exists()


def test_an_unused_formula_parameter_names_its_scene_key(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text('[material]\nenergy = "I1 - 3"\n[material.parameters]\nc = 1.0\n')
    assert main(["run", str(scene), "-o", str(tmp_path / "x.h5"), "--quiet"]) == 2
    assert "material.parameters.c: not used by the formula" in one_line(capsys)


def test_main_restores_the_sigterm_handler_it_installs():
    import signal

    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(SystemExit):
        main(["--version"])
    assert main(["inspect", "/nonexistent/x.h5"]) == 2
    assert signal.getsignal(signal.SIGTERM) is before


@pytest.mark.parametrize("command", ["inspect", "plot"])
def test_a_fifo_to_read_is_one_line(command, tmp_path, capsys):
    fifo = tmp_path / "f.h5"
    os.mkfifo(fifo)  # nobody writes it: opening it for reading would block forever
    argv = [command, str(fifo)] + (["--what", "pressure-pole", "-o", str(tmp_path / "p.png")] if command == "plot" else [])
    assert main(argv) == 2
    assert "not a regular file" in one_line(capsys)
