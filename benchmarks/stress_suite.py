"""Stress: the default test suite (``python -m pytest -q``, as ``make test`` runs it: in parallel on the pytest-xdist
workers of pyproject's addopts) N times in a row beside K CPU-bound processes, to show that no test depends on an
idle machine (issue 37: a test that fails under load or in parallel is a defect).

The load: K Python interpreters each running a numeric loop (numpy matrix products, single-threaded) for as long as
the suite runs; they are started in their own process group and ended, by that group's id, when the runs are done
or interrupted. One line per run (pass or fail, pytest's exit code, wall seconds, the last line of pytest's
summary, the load average at the end), then a summary (passes, median and worst wall time). A failing run's output
is kept in ``stress_suite_run{I}.log`` in the output folder (default: the current folder) for its diagnosis.

Run: python benchmarks/stress_suite.py [--runs N] [--load K] [--out FOLDER] [-- PYTEST ARGS]
     (defaults N = 3, K = 4; PYTEST ARGS are appended to ``python -m pytest -q``, e.g. ``-- -n 2 -x``)
Exit status: 0 when every run passed, 1 otherwise.
"""
import argparse
import os
import signal
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LOAD = ("import os\n"
        "os.environ['OMP_NUM_THREADS'] = os.environ['OPENBLAS_NUM_THREADS'] = os.environ['MKL_NUM_THREADS'] = '1'\n"
        "import numpy as np\n"
        "a = np.random.default_rng(0).random((200, 200))\n"
        "while True:\n"
        "    a = np.tanh(a @ a.T / 200.0)\n")


def start_load(count: int) -> list[subprocess.Popen]:
    """``count`` busy interpreters, each in a new process group (ended by stop_load)."""
    return [subprocess.Popen([sys.executable, "-c", LOAD], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                             start_new_session=True) for _ in range(count)]


def stop_load(load: list[subprocess.Popen]) -> None:
    for process in load:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
        process.wait()


def one_run(index: int, pytest_args: list[str], out: Path) -> dict:
    """The suite once from the repository root; its outcome, wall time and summary line."""
    start = time.monotonic()
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", *pytest_args], cwd=ROOT, capture_output=True,
                          text=True)
    seconds = time.monotonic() - start
    lines = [line for line in (done.stdout + done.stderr).strip().splitlines() if line.strip()]
    summary = lines[-1].strip("= ") if lines else "(no output)"
    if done.returncode != 0:
        (out / f"stress_suite_run{index}.log").write_text(done.stdout + done.stderr)
    return {"passed": done.returncode == 0, "code": done.returncode, "seconds": seconds, "summary": summary,
            "load": os.getloadavg()[0]}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="N: runs of the suite, one after the other (3)")
    parser.add_argument("--load", type=int, default=4, help="K: CPU-bound processes beside them (4)")
    parser.add_argument("--out", type=Path, default=Path.cwd(), help="folder for the logs of failed runs")
    parser.add_argument("pytest_args", nargs="*", help="after --: appended to python -m pytest -q")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    print(f"suite: python -m pytest -q {' '.join(args.pytest_args)} in {ROOT}; {args.runs} runs beside "
          f"{args.load} busy processes on {os.cpu_count()} cores", flush=True)
    load = start_load(args.load)
    results = []
    try:
        for index in range(1, args.runs + 1):
            result = one_run(index, args.pytest_args, args.out)
            results.append(result)
            print(f"run {index}: {'pass' if result['passed'] else 'FAIL'} (exit {result['code']}) "
                  f"{result['seconds']:7.1f} s  load {result['load']:.1f}  {result['summary']}", flush=True)
    finally:
        stop_load(load)
    seconds = [r["seconds"] for r in results]
    passed = sum(r["passed"] for r in results)
    print(f"summary: {passed}/{len(results)} passed beside {args.load} busy processes; wall time median "
          f"{statistics.median(seconds):.1f} s, worst {max(seconds):.1f} s" if results else "summary: no run")
    return 0 if results and passed == len(results) else 1


if __name__ == "__main__":
    sys.exit(main())
