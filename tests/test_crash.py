"""SIGKILL at random instants: a sweep's process group killed 6 times (20 under -m slow), every state readable, every
resume complete and bitwise equal to an uninterrupted serial sweep, no debris; concurrent runs on one output never
both write it.
The same code with more kills is benchmarks/crash_soak.py (figures in the closing note)."""
import importlib.util
from pathlib import Path

import pytest

SOAK = Path(__file__).resolve().parents[1] / "benchmarks" / "crash_soak.py"


@pytest.fixture(scope="module")
def crash_soak():
    spec = importlib.util.spec_from_file_location("crash_soak", SOAK)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("kills", [6, pytest.param(20, marks=pytest.mark.slow)])
def test_sweep_survives_sigkill_at_random_instants(crash_soak, tmp_path, kills):
    """benchmarks/crash_soak.py's kills (6 in the default suite, 20 under ``-m slow``, 200 in the benchmark)."""
    figures = crash_soak.soak(kills, tmp_path, seed=13)
    assert figures["kills"] == kills
    assert figures["unrecoverable"] == [] and figures["failed_resumes"] == []
    assert figures["lost"] == 0 and figures["debris"] == []
    assert figures["recovered"] >= 1


def test_concurrent_runs_on_one_output_never_both_write_it(crash_soak, tmp_path):
    figures = crash_soak.collide(3, tmp_path)
    assert figures["lost"] == 0 and figures["other"] == []
    assert figures["refused_in_use"] >= 1  # the pairs overlapped (on a loaded machine one may not: "sequential")
