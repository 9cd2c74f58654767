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
"""
import os

import pytest

ONE_THREAD = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")

COST = {  # seconds of each file on one worker of an idle 2-core run (issue 37): from a survey of the whole suite under
    # load (session 20), the mean of its CPU and wall shares scaled to the suite's ~780 worker-seconds; files added
    # since by their own runs' times, halved for the load they ran under; test_codegen and test_paper scaled by the
    # CPU ratios of their serial runs after the faster derivation and the figures drawn once (0.54x, 0.82x);
    # `python benchmarks/suite_cpu.py --out DIR --cost` measures each file's CPU in a run and prints these entries
    "test_interrupt_moments": 118, "test_paper": 43, "test_codegen": 22, "test_surface": 37,
    "test_cli_conventions": 29, "test_packaging": 27, "test_restart": 26, "test_crash": 20, "test_damaged_fuzz": 19,
    "test_branch_points": 18, "test_verdict": 17, "test_signal_moments": 17, "test_tube_field": 15,
    "test_azimuthal_points": 15, "test_plot_sizes": 13, "test_kernels_cmd": 13, "test_tuning": 12, "test_poles": 12,
    "test_energies": 12, "test_api": 11, "test_fold_meeting": 11, "test_shooting": 10, "test_interval": 10,
    "test_formula": 9, "test_dynamics": 9, "test_bifurcation": 9, "test_sweep": 9, "test_surface_store": 9,
    "test_surface_kernels": 8, "test_events": 8, "test_checked_reads": 8, "test_stability_basis": 8,
    "test_dynamics_surface": 8, "test_plotting": 7, "test_sphere_modes": 7, "test_api_notebook": 7,
    "test_hostile_memory": 7, "test_tube": 7, "test_surface_pitchforks": 6, "test_dask_cluster": 6,
}


def pytest_configure(config):
    if not hasattr(config, "workerinput"):
        return
    os.environ.update(dict.fromkeys(ONE_THREAD, "1"))  # before numpy loads its BLAS here, and for children
    from threadpoolctl import threadpool_limits

    threadpool_limits(1, user_api="blas")  # in case it was loaded already


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
