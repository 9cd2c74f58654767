"""A real dask.distributed cluster: `dask scheduler` and two `dask worker` processes on 127.0.0.1, a sweep sent
with --scheduler, one worker SIGKILLed mid-sweep: the sweep completes with every member bitwise equal to a
serial run."""
import importlib.util
import json
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

distributed = pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[1]
SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 3\n'
VARY = "material.alpha[0]=1.3:1.4:8"


def load_soak():
    spec = importlib.util.spec_from_file_location("crash_soak", ROOT / "benchmarks" / "crash_soak.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def dask_command() -> list[str]:
    script = Path(sys.executable).with_name("dask")
    found = str(script) if script.exists() else shutil.which("dask")
    if found is None:
        pytest.skip("the dask command line is not installed")
    return [found]


def wait_for(predicate, what: str, timeout: float = 300):  # generous: a loaded machine is slow, never wrong
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.05)


def scheduler_address(path: Path) -> str | None:
    """The address in dask's scheduler file, once the file is complete (the scheduler writes it in place: it can
    exist and be empty or half-written for a while on a loaded machine)."""
    try:
        return json.loads(path.read_text())["address"]
    except (FileNotFoundError, json.JSONDecodeError, KeyError, TypeError):
        return None


def test_sweep_on_a_real_cluster_survives_a_lost_worker(tmp_path):
    soak, dask = load_soak(), dask_command()
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE)
    serial = tmp_path / "serial.h5"
    subprocess.run(soak.cli("sweep", scene, "--vary", VARY, "-o", serial, "--primary-only", "--workers", 1,
                            "--quiet"), check=True)
    address_file = tmp_path / "scheduler.json"
    processes = []
    try:
        processes.append(subprocess.Popen([*dask, "scheduler", "--host", "127.0.0.1", "--port", "0",
                                           "--no-dashboard", "--scheduler-file", str(address_file)],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        wait_for(lambda: scheduler_address(address_file) is not None, "the scheduler", timeout=300)
        address = scheduler_address(address_file)
        assert address.startswith("tcp://127.0.0.1:")
        workers = [subprocess.Popen([*dask, "worker", address, "--host", "127.0.0.1", "--nworkers", "1",
                                     "--nthreads", "1", "--no-nanny", "--no-dashboard", "--name", f"w{i}"],
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for i in range(2)]
        processes += workers
        with distributed.Client(address, timeout="300s") as client:  # generous, as wait_for
            client.wait_for_workers(2, timeout=300)
        out = tmp_path / "cluster.h5"
        sweep = subprocess.Popen(soak.cli("sweep", scene, "--vary", VARY, "-o", out, "--primary-only",
                                          "--scheduler", address, "--quiet"), stderr=subprocess.PIPE, text=True)
        processes.append(sweep)
        store = out.with_name(out.name + ".members")
        members = lambda: sorted(store.glob("0*.h5")) if store.is_dir() else []  # noqa: E731
        wait_for(lambda: members() or sweep.poll() is not None, "the first member")
        assert sweep.poll() is None and len(members()) < 8, "the sweep ended before a worker could be lost"
        workers[1].send_signal(signal.SIGKILL)
        workers[1].wait()
        assert sweep.wait(timeout=300) == 0, sweep.stderr.read()
        assert soak.member_digests(out) == soak.member_digests(serial)
        assert len(soak.member_digests(out)) == 8
    finally:
        for p in reversed(processes):
            if p.poll() is None:
                p.send_signal(signal.SIGKILL)
                p.wait()
