"""A scene's formula cannot hang or exhaust the machine (issue 30, item 2): bounds on the checked tree before
SymPy sees it (scene/formula), kernel generation in a child under a time budget and a memory bound, stopped by
Ctrl-C (model/kernel_cache); the kernel cache is verified on load."""
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pytest
from hypothesis import HealthCheck, Phase, given, seed, settings, strategies as st

from balloon_cg.app.cli import main
from balloon_cg.model import kernel_cache
from balloon_cg.model.kernels import PLAIN
from balloon_cg.scene import SceneError
from balloon_cg.scene.formula import MAX_EXPONENT, MAX_NODES, parse_formula

HANGING = {  # the formulas, and others past each bound: refused in parsing, before any SymPy
    "I1 - 3 + 0*(1/3)**(10**9)": "exponent 10**9 is beyond",
    "I1 - 3 + (1/3)**(10**9)*(I1 - 3)**2": "exponent 10**9 is beyond",
    "sinh(sinh(sinh(sinh(sinh(sinh(sinh(sinh(I1 - 3))))))))": "nested 4 deep",
    "I1 - 3 + (I1 - 3)**1e308": "number 1e308 is beyond",
    "((I1 - 3)**8)**8": "exponent of 64",
    "I1 - 3 + 1/(2 - 2)": "division by zero",
    "I1 - 3 + exp(10**3)": "not a finite number",
    " + ".join(["(I1 + I2 + I1 + I2)"] * 45): "terms",
}


def one_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


@pytest.mark.parametrize("formula", list(HANGING))
def test_formulas_past_a_bound_are_one_line_at_once(formula, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv(kernel_cache.CACHE_ENV, str(tmp_path / "cache"))
    scene = tmp_path / "s.toml"
    scene.write_text(f'[material]\nenergy = "{formula}"\n[continuation]\nstop_stretch = 1.5\n')
    start = time.process_time()  # CPU time: a loaded machine stretches the wall clock, not the work
    assert main(["run", str(scene), "-o", str(tmp_path / "x.h5"), "--quiet"]) == 2
    assert time.process_time() - start < 60  # refused in parsing: milliseconds (the bound is for a stuck machine)
    line = one_line(capsys)
    assert "material.energy" in line and HANGING[formula] in line
    assert not (tmp_path / "cache").exists() and not (tmp_path / "x.h5").exists()


def test_formulas_within_the_bounds_parse():
    for formula in ("I1 - 3 + 0.1*(I1 - 3)**2", f"(I1 - 3)**{MAX_EXPONENT}", "log(1 - (I1 - 3)/30)",
                    "exp(sinh(tanh(I1 - 3))) - 1", "(-8)**(1/3)*(I1 - 3)", "lambda1**1.3 + lambda2**1.3 - 2",
                    " + ".join(["(I1 + I2 + I1 + I2)"] * (MAX_NODES // 8)) + f" - {MAX_NODES // 8}*12"):
        parse_formula(formula)


operands = st.sampled_from(["I1", "I2", "lambda1", "lambda2", "lambda3", "3", "0", "1/3", "10**9", "1e308", "2.5",
                            "-1", "0.0"])


def formulas(depth: int = 0):
    if depth >= 4:
        return operands
    inner = st.deferred(lambda: formulas(depth + 1))
    return st.one_of(
        operands,
        st.tuples(inner, st.sampled_from(["+", "-", "*", "/", "**", "^"]), inner).map(lambda t: f"({t[0]}{t[1]}{t[2]})"),
        st.tuples(st.sampled_from(["exp", "log", "sqrt", "sinh", "cosh", "tanh", "atan"]), inner).map(
            lambda t: f"{t[0]}({t[1]})"))


def _parse_fuzzed(text: str) -> None:
    start = time.process_time()  # CPU time: a loaded machine stretches the wall clock, not the work
    try:
        parse_formula(text)
    except SceneError as e:
        assert "\n" not in str(e)
    assert time.process_time() - start < 5  # a parse is milliseconds: seconds would mean work grows with the input


@seed(30)
@settings(max_examples=200, deadline=None, phases=(Phase.explicit, Phase.reuse, Phase.generate),
          suppress_health_check=list(HealthCheck))
@given(formulas())
def test_fuzzed_formulas_parse_or_are_one_scene_error(text):
    _parse_fuzzed(text)


@pytest.mark.slow
@seed(3030)
@settings(max_examples=1000, deadline=None, phases=(Phase.explicit, Phase.reuse, Phase.generate),
          suppress_health_check=list(HealthCheck))
@given(formulas())
def test_fuzzed_formulas_1000(text):
    _parse_fuzzed(text)


SCENE = '[material]\nenergy = "I1 - 3 + 0.2*(I1 - 3)**2 + 0.01*(I2 - 3)"\n[continuation]\nstop_stretch = 1.3\n'


def test_generation_past_its_time_budget_is_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv(kernel_cache.CACHE_ENV, str(tmp_path / "cache"))
    monkeypatch.setenv(kernel_cache.TIMEOUT_ENV, "0.001")  # no Python starts in a millisecond
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE)
    assert main(["kernels", str(scene)]) == 2
    line = one_line(capsys)
    assert "material.energy" in line and "time budget" in line and kernel_cache.TIMEOUT_ENV in line
    assert not list((tmp_path / "cache").glob("*.py"))
    monkeypatch.setenv(kernel_cache.TIMEOUT_ENV, "soon")
    assert main(["kernels", str(scene)]) == 2
    assert kernel_cache.TIMEOUT_ENV in one_line(capsys)


def _children(pid: int) -> list[int]:
    """The generating children of ``pid`` (python -m balloon_cg.model.kernel_cache), not other short-lived helpers
    a library may spawn (ldconfig from ctypes.util)."""
    path = Path(f"/proc/{pid}/task/{pid}/children")
    found = []
    for child in (path.read_text().split() if path.exists() else []):
        try:
            if b"balloon_cg.model.kernel_cache" in Path(f"/proc/{child}/cmdline").read_bytes():
                found.append(int(child))
        except FileNotFoundError:
            pass
    return found


def _state(pid: int) -> str:
    """The one-letter process state of /proc/PID/stat ('' when gone)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return ""


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs /proc")
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_ctrl_c_stops_kernel_generation(tmp_path, signum):
    """The signal goes to balloon-cg only (not its process group): it kills the generating child and exits 130.
    The generating child (found by its command line) is frozen (SIGSTOP) before the signal, so the signal surely
    arrives while it generates (on a busy machine the test could otherwise signal a child that has just finished); a
    child that had finished before it was frozen makes the attempt void and it is repeated."""
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE.replace("0.01", "0.0125" if signum == signal.SIGINT else "0.015"))
    env = {**os.environ, kernel_cache.CACHE_ENV: str(tmp_path / "cache")}
    for _ in range(3):
        proc = subprocess.Popen([sys.executable, "-m", "balloon_cg", "run", str(scene), "-o", str(tmp_path / "x.h5"),
                                 "--quiet"], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            deadline = time.monotonic() + 300
            while not _children(proc.pid) and proc.poll() is None and time.monotonic() < deadline:
                time.sleep(0.05)
            children = _children(proc.pid)
            assert children, "the generating child never started"
            for child in children:
                os.kill(child, signal.SIGSTOP)
            settle = time.monotonic() + 30
            while any(_state(c) not in ("T", "Z", "") for c in children) and time.monotonic() < settle:
                time.sleep(0.01)  # a stop signal takes effect when the child is next scheduled
            if any(_state(child) != "T" for child in children):  # finished before it was frozen: void
                proc.kill()
                proc.communicate()
                for path in (tmp_path / "cache").glob("*.py"):
                    path.unlink()
                continue
            proc.send_signal(signum)
            _, err = proc.communicate(timeout=300)
        finally:
            proc.kill()
        break
    else:
        pytest.fail("the generating child finished before it could be frozen, three times")
    assert proc.returncode == 130, err
    assert "interrupted" in err and "Traceback" not in err
    assert not list((tmp_path / "cache").glob("*.py")) and not (tmp_path / "x.h5").exists()
    for child in children:
        assert not Path(f"/proc/{child}").exists() or "zombie" in Path(f"/proc/{child}/status").read_text()


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_the_child_is_spawned_is_held_until_it_can_be_killed(signum):
    """A signal between the handlers' installation and the child's existence is not lost (a lost one left
    balloon-cg waiting for a frozen child): ``arm()``, called once the child exists, raises it."""
    with kernel_cache._signals_raise() as arm:
        os.kill(os.getpid(), signum)
        time.sleep(0.01)  # the handler runs at the next bytecode boundary
        with pytest.raises(KeyboardInterrupt):
            arm()
    with kernel_cache._signals_raise() as arm:
        arm()
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signum)
            time.sleep(1)


@pytest.mark.parametrize("damage", ["empty", "truncated", "garbled", "null bytes"])
def test_a_damaged_cached_module_is_regenerated_with_a_warning(damage, tmp_path, monkeypatch):
    from balloon_cg.scene.formula import parse_formula as parse

    monkeypatch.setenv(kernel_cache.CACHE_ENV, str(tmp_path))
    formula = parse("I1 - 3 + 0.5*(I2 - 3)")
    path = kernel_cache.module_path(formula, PLAIN)
    text = kernel_cache.sealed("INPUTS = ()\nKERNELS = {}\n")
    monkeypatch.setattr(kernel_cache, "bounded_generate", lambda *args, **kwargs: "INPUTS = ()\nKERNELS = {}\n")
    damaged = {"empty": "", "truncated": text[: len(text) // 2], "garbled": text.replace("KERNELS", "KERNELZ"),
               "null bytes": text.replace("INPUTS", "\0\0\0\0\0\0")}[damage]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(damaged)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        module = kernel_cache.load(formula, PLAIN)
    sys.modules.pop(path.stem, None)
    assert [w.category for w in caught] == [kernel_cache.KernelCacheWarning] and str(path) in str(caught[0].message)
    assert module.KERNELS == {} and path.read_text() == text
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a whole module loads without a word
        kernel_cache.load(formula, PLAIN)
    sys.modules.pop(path.stem, None)


def test_processes_missing_the_same_module_generate_it_once(tmp_path, monkeypatch):
    """Two loaders of one missing class at once (test or sweep workers; threads here, each with its own lock file
    handle as a process has): one generates, the other waits for the lock and imports the module written."""
    import threading

    from balloon_cg.scene.formula import parse_formula as parse

    monkeypatch.setenv(kernel_cache.CACHE_ENV, str(tmp_path))
    formula = parse("I1 - 3 + 0.25*(I2 - 3)")
    path = kernel_cache.module_path(formula, PLAIN)
    both_looked, generations = threading.Barrier(2), []

    def slow_generate(*args, **kwargs):
        generations.append(threading.get_ident())
        time.sleep(0.5)  # the other loader is waiting on the lock by now, or arrives to a written module
        return "INPUTS = ()\nKERNELS = {}\n"

    monkeypatch.setattr(kernel_cache, "bounded_generate", slow_generate)
    modules, errors = [], []

    def loader():
        try:
            both_looked.wait(timeout=60)
            modules.append(kernel_cache.load(formula, PLAIN))
        except BaseException as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    threads = [threading.Thread(target=loader) for _ in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=120)
    sys.modules.pop(path.stem, None)
    assert not errors and len(modules) == 2 and all(m.KERNELS == {} for m in modules)
    assert len(generations) == 1 and kernel_cache._damage(path) is None
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no lock file or temporary file left


def test_a_generated_module_past_its_size_bound_is_one_line(monkeypatch):
    monkeypatch.setattr(kernel_cache, "MAX_MODULE_CHARS", 1000)
    assert kernel_cache.checked_size("x" * 1000, "f") == "x" * 1000
    with pytest.raises(SceneError, match="material.energy = 'I1': its kernels would be 0.001 MB of code"):
        kernel_cache.checked_size("x" * 1001, "material.energy = 'I1'")
