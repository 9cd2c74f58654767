"""How the suite shares out on pytest-xdist's workers (pyproject's addopts: ``-n 2 --dist loadfile
--no-loadscope-reorder``).

A file's tests run on one worker (``loadfile``), so its module-scoped fixtures are computed once, as in a serial
run; on the workers the files are collected, and so sent out, longest first (COST, seconds of a serial run: a hint
for the balance, which a stale value spoils a little, never the outcome), the others after them in the order of
collection. A serial run (``-n 0``) keeps the order of collection. (``--dist loadgroup`` with ``xdist_group`` marks
would let files share a worker, but xdist 3.8 marks a group by rewriting ``item._nodeid``, which pytest 9.2 no
longer reads: the marks are silently ignored and every test is scheduled on its own.)

A worker owns one core: its BLAS runs on one thread, and so do the processes it starts (tests that call the
numerics below the entry points that limit BLAS themselves, numerics/threads.py; two workers with two OpenBLAS
threads each on two cores spend their time waiting for one another).

Where Python writes no bytecode (PYTHONDONTWRITEBYTECODE, as in CI and the sandboxes), every process the suite starts
(the CLI and signal tests: a few hundred) compiled the ~130 modules of balloon_cg it imports from source again, ~0.3 s
of CPU each (18 % of a short `run`): the session byte-compiles this tree's src/, generated/ and codegen/ once, before
the workers start, and removes what it wrote at its end (``byte_compiled``), as Python would have written it.
"""
import importlib.util
import os
import py_compile
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
COMPILED = ("src", "generated", "codegen")  # the folders whose modules the suite's processes import

ONE_THREAD = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")

COST = {  # CPU seconds of each file in one run of the default suite on 2 workers (benchmarks/suite_cpu.py --cost, this
    # process and its children; only the order matters), files of 5 s or more. Session 23 (the machine loaded 5-13):
    "test_interrupt_moments": 125, "test_packaging": 43, "test_cli_conventions": 31,
    "test_plot_sizes": 25, "test_verdict": 24, "test_tube_interrupt": 24, "test_signal_moments": 22,
    # session 26 (s26-inproc; benchmarks/results/suite_cpu_session26_inproc.txt): the files it changed, from its
    # branch's run of them (2 workers, load 15-26), and every other file from its one run of the rest of the default
    # suite (2 workers, load 15-20), both scaled by 0.65 to the scale above (the session-23 values of test_paper,
    # test_restart, test_surface and test_capsule against main's in the same run: 179/275 s); files under 5 s left out
    "test_paper": 55, "test_restart": 46, "test_surface": 40, "test_capsule": 23, "test_graded_elements": 8,
    "test_shooting": 28, "test_crash": 25, "test_plotting": 23, "test_branch_points": 21, "test_damaged_fuzz": 20,
    "test_sweep": 19, "test_checked_reads": 15, "test_dynamics_shapes": 14, "test_capsule_frequencies": 14,
    "test_api_notebook": 13, "test_dynamics": 13, "test_surface_kernels": 12, "test_azimuthal_points": 10,
    "test_energies": 10, "test_formula": 10, "test_api": 10, "test_tube_electric": 10, "test_default_run": 10,
    "test_kernels_cmd": 9, "test_surface_store": 9, "test_tube_sweep": 9, "test_field": 8, "test_sphere_modes": 8,
    "test_damaged_files": 8, "test_dask_cluster": 8, "test_schema": 8, "test_tube_azimuthal": 8, "test_events": 7,
    "test_fold_meeting": 7, "test_cli": 7, "test_voltage_branches": 7, "test_off_equator": 7, "test_tube_surface": 6,
    "test_poles": 6, "test_stability_basis": 6, "test_tube_field": 6, "test_fold_curve": 6, "test_surface_free": 6,
    "test_tube": 6, "test_tube_maxwell": 6, "test_fuzz": 5, "test_two_parameter": 5, "test_surface_pitchforks": 5,
    "test_interval": 5, "test_hostile_memory": 5, "test_tube_cli": 5, "test_ownership": 5, "test_sweep_store": 5,
    "test_tube_switching": 5, "test_dynamics_surface": 5, "test_workers": 5, "test_surface_estimates": 7,
    # session 26 (s26-contracts): test_codegen checks generated/ from its headers (0.07x its CPU): under 5 s
    "test_interrupt": 8,
}


def byte_compiled() -> list[Path]:
    """The bytecode files written for this tree's modules that had none (``py_compile``, timestamp-checked as Python
    writes them), when Python itself writes none (``sys.dont_write_bytecode``) and balloon_cg is imported from this
    tree (an editable install: a wheel's install is compiled by pip); else nothing. A tree it cannot write (read-only)
    stops it: what it wrote until then is returned (removed at the session's end); a session killed before its end
    leaves them, as Python's own bytecode (timestamp-checked, gitignored)."""
    spec = importlib.util.find_spec("balloon_cg")
    if not sys.dont_write_bytecode or spec is None or not Path(spec.origin).is_relative_to(ROOT / "src"):
        return []
    written = []
    for source in sorted(path for folder in COMPILED for path in (ROOT / folder).rglob("*.py")):
        bytecode = Path(importlib.util.cache_from_source(source))
        if not bytecode.exists():
            try:
                py_compile.compile(str(source), cfile=str(bytecode), doraise=True,
                                   invalidation_mode=py_compile.PycInvalidationMode.TIMESTAMP)
            except OSError:  # a read-only tree: the processes compile as they did
                break
            written.append(bytecode)
    return written


def pytest_configure(config):
    if not hasattr(config, "workerinput"):  # the controller (or a serial run): before any worker starts
        config.stash[WRITTEN] = byte_compiled()
        return
    os.environ.update(dict.fromkeys(ONE_THREAD, "1"))  # before numpy loads its BLAS here, and for children
    from threadpoolctl import threadpool_limits

    threadpool_limits(1, user_api="blas")  # in case it was loaded already


WRITTEN = pytest.StashKey[list]()


def pytest_unconfigure(config):
    """The bytecode ``byte_compiled`` wrote removed, and the __pycache__ folders it left empty."""
    for bytecode in config.stash.get(WRITTEN, []):
        bytecode.unlink(missing_ok=True)
        try:
            bytecode.parent.rmdir()
        except OSError:  # other files in it, or already gone
            pass


def module_of(item) -> str:
    return item.module.__name__.rpartition(".")[2] if getattr(item, "module", None) else item.nodeid


def pytest_collection_modifyitems(config, items):
    if not hasattr(config, "workerinput"):  # the controller, or a serial run
        return
    files = {}
    for item in items:
        files.setdefault(module_of(item), []).append(item)
    order = sorted(files, key=lambda module: -COST.get(module, 0))  # stable: uncosted files keep collection order
    items[:] = [item for module in order for item in files[module]]


@pytest.fixture
def drawn_texts(monkeypatch):
    """Every matplotlib Text drawn while the test runs (tick labels of ticks outside the view are never drawn): the
    fit tests of figures (test_paper, test_plot_sizes)."""
    import matplotlib.text

    drawn = []
    draw = matplotlib.text.Text.draw

    def recording(text, renderer):
        drawn.append(text)
        return draw(text, renderer)

    monkeypatch.setattr(matplotlib.text.Text, "draw", recording)
    return drawn
