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

COST = {  # CPU seconds of each file in one run of the default suite on 2 workers (benchmarks/suite_cpu.py --cost, this
    # process and its children; session 23, the machine loaded 5-13: only the order matters), files of 5 s or more
    "test_interrupt_moments": 125, "test_spheroid_voltage": 28, "test_plugged_bifurcation": 20,
    "test_tube_surface_branch": 6, "test_paper": 62, "test_restart": 47, "test_surface": 47, "test_codegen": 45,
    "test_packaging": 43, "test_cli_conventions": 31, "test_plot_sizes": 25, "test_verdict": 24,
    "test_tube_interrupt": 24, "test_capsule": 23, "test_signal_moments": 22, "test_tube_surface": 20, "test_crash": 18,
    "test_damaged_fuzz": 17, "test_plotting": 15, "test_shooting": 15, "test_sweep": 15, "test_branch_points": 14,
    "test_checked_reads": 13, "test_api_notebook": 13, "test_azimuthal_points": 12, "test_surface_kernels": 11,
    "test_poles": 11, "test_events": 11, "test_dynamics": 10, "test_energies": 9, "test_formula": 9, "test_api": 8,
    "test_fold_meeting": 8, "test_kernels_cmd": 8, "test_tube_electric": 8, "test_stability_basis": 8,
    "test_dynamics_shapes": 8, "test_cli": 8, "test_field": 7, "test_surface_store": 7, "test_sphere_modes": 7,
    "test_fuzz": 6, "test_damaged_files": 6, "test_dask_cluster": 6, "test_tube_field": 6, "test_two_parameter": 6,
    "test_surface_pitchforks": 5, "test_fold_curve": 5, "test_interval": 5, "test_schema": 5,
    "test_hostile_memory": 5,
    # session 24's new files, from their helpers' serial runs at load ~20 (rough: only the order matters)
    "test_graded_elements": 20, "test_capsule_frequencies": 10,
    # session 25: the tube files it changed, measured on 2 workers at load 17-25 with a fresh numba cache (the first
    # file on a worker carries the compile): test_tube_cli 33, test_tube_control 24, test_dynamics_tube 10,
    # test_tube_resolution 9, test_tube_result 8, test_tube_continue 7, here divided by 2.5 (that run's load inflated
    # CPU: test_interrupt_moments 313 s against the 125 above) and kept where 5 s or more; test_tube_bulge_m1
    # measured at 3 s in the default suite, so dropped (was 35)
    "test_tube_cli": 13, "test_tube_control": 10,
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
