"""Benchmark: where the default test suite's work goes, per test file, in CPU seconds (issue 37's suite floor).

A wall clock on a shared machine measures the other processes; a file's CPU does not. As a pytest plugin
(``-p suite_cpu`` with benchmarks/ on PYTHONPATH) it records, in each worker, every test file's CPU seconds from
its first test's setup to its last test's teardown (this process's and its waited-for children's: the subprocesses
of the CLI tests, the pools of the sweeps) and its wall seconds, and writes them to ``$SUITE_CPU_OUT/<worker>.json``
as each file ends. As a script it runs the default suite that way (pyproject's addopts: 2 workers, loadfile),
or reads the records of such runs, and prints per file the CPU seconds (one column per run), their ratio to the
first run's, and the sums: the suite's CPU, each worker's CPU (the wall time of an idle 2-core machine is about the
larger of the two, since a file runs whole on one worker) and the files' wall seconds on each worker.

    python benchmarks/suite_cpu.py --out /tmp/suite_main -- [PYTEST ARGS]     # run the suite, keep its records
    python benchmarks/suite_cpu.py --read /tmp/suite_main /tmp/suite_branch   # compare runs (from any tree)
    python benchmarks/suite_cpu.py --read /tmp/suite_branch --cost            # tests/conftest.py's COST from a run
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def cpu() -> float:
    """CPU seconds of this process and its waited-for children (user + system)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


FILES: dict = {}  # file -> [cpu, wall]
TESTS: dict = {}  # test id -> cpu


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    start_cpu, start_wall = cpu(), time.monotonic()
    yield
    spent = FILES.setdefault(item.location[0], [0.0, 0.0])
    TESTS[item.nodeid] = cpu() - start_cpu
    spent[0] += TESTS[item.nodeid]
    spent[1] += time.monotonic() - start_wall
    if nextitem is None or nextitem.location[0] != item.location[0]:
        write()  # a file done: a run stopped early keeps what it measured


def write():
    folder = os.environ.get("SUITE_CPU_OUT")
    if not folder or not FILES:
        return
    worker = os.environ.get("PYTEST_XDIST_WORKER", "serial")
    Path(folder).mkdir(parents=True, exist_ok=True)
    (Path(folder) / f"{worker}.json").write_text(json.dumps(FILES, indent=1))
    (Path(folder) / f"{worker}.tests").write_text(json.dumps(TESTS, indent=1))


def read(folder: Path) -> dict:
    """{file: (cpu, wall, worker)} of one run's records."""
    files = {}
    for record in sorted(folder.glob("*.json")):
        for name, (spent, wall) in json.loads(record.read_text()).items():
            files[name] = (spent, wall, record.stem)
    return files


def table(runs: list[dict], names: list[str]) -> None:
    files = sorted(set().union(*runs), key=lambda f: -max(run.get(f, (0,))[0] for run in runs))
    print("| file | " + " | ".join(f"CPU s, {n}" for n in names)
          + "".join(f" | ×, {n}" for n in names[1:]) + " |")
    print("|---|" + "---|" * (2 * len(runs) - 1))
    for f in files:
        spent = [run[f][0] if f in run else None for run in runs]
        cells = [f"{s:.1f}" if s is not None else "–" for s in spent]
        ratios = [f"{s / spent[0]:.2f}" if s is not None and spent[0] else "–" for s in spent[1:]]
        print(f"| {Path(f).stem} | " + " | ".join(cells + ratios) + " |")
    for run, name in zip(runs, names):
        workers = {}
        for spent, wall, worker in run.values():
            w = workers.setdefault(worker, [0.0, 0.0])
            w[0] += spent
            w[1] += wall
        print(f"{name}: {len(run)} files, CPU {sum(w[0] for w in workers.values()):.0f} s; per worker "
              + ", ".join(f"{k} CPU {c:.0f} s wall {t:.0f} s" for k, (c, t) in sorted(workers.items())))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, help="run the suite, recording into this folder")
    parser.add_argument("--read", type=Path, nargs="+", default=[], help="folders of earlier runs to compare")
    parser.add_argument("--cost", action="store_true", help="print COST (tests/conftest.py) from the first run")
    parser.add_argument("--tests", type=int, default=0, help="also list the first run's N costliest tests")
    parser.add_argument("pytest", nargs="*", help="arguments for pytest (after --)")
    args = parser.parse_args(argv)
    folders = list(args.read)
    if args.out:
        env = {**os.environ, "SUITE_CPU_OUT": str(args.out),
               "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT / "benchmarks"), os.environ.get("PYTHONPATH")]))}
        start = time.monotonic()
        done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "suite_cpu", *args.pytest], cwd=ROOT, env=env)
        print(f"pytest exit {done.returncode}, wall {time.monotonic() - start:.0f} s")
        folders.insert(0, args.out)
    runs = [read(f) for f in folders]
    if args.cost and runs:
        cost = sorted(((Path(f).stem, spent) for f, (spent, _, _) in runs[0].items()), key=lambda c: -c[1])
        print(", ".join(f'"{name}": {spent:.0f}' for name, spent in cost if spent >= 5))
    if runs:
        table(runs, [f.name for f in folders])
    if args.tests and folders:
        tests = {k: v for record in folders[0].glob("*.tests") for k, v in json.loads(record.read_text()).items()}
        for name, spent in sorted(tests.items(), key=lambda t: -t[1])[:args.tests]:
            print(f"{spent:7.1f} s  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
