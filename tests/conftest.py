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

COST = {  # seconds of each file in a serial --durations=0 run on a loaded 2-core machine (issue 37); the files whose
    # child processes take more CPU than that (codegen, crash, cli_conventions) by their CPU seconds
    "test_restart": 182, "test_surface": 168, "test_verdict": 103, "test_paper": 101, "test_formula": 68,
    "test_events": 67, "test_poles": 49, "test_shooting": 43, "test_sweep": 42, "test_crash": 65,
    "test_plotting": 37, "test_two_parameter": 35, "test_surface_kernels": 33, "test_codegen": 75,
    "test_cli_conventions": 50, "test_packaging": 30, "test_voltage_branches": 30, "test_field": 29,
    "test_bifurcation": 28, "test_surface_pitchforks": 25, "test_coordinate_map": 23, "test_surface_primary": 22,
    "test_surface_store": 19, "test_labels": 18, "test_sphere_modes": 18, "test_damaged_fuzz": 18,
    "test_azimuthal_points": 17, "test_api": 17, "test_dielectric": 16, "test_energies": 15, "test_quadrature": 15,
    "test_branch_points": 13, "test_fold_meeting": 13, "test_terms": 12, "test_formula_bounds": 11,
    "test_api_notebook": 11, "test_pear_points": 10, "test_free_pitchfork": 10, "test_sweep_store": 9,
    "test_fold_curve": 8, "test_plot_sizes": 40, "test_parameter_names": 15, "test_dynamics": 60,
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
