"""Benchmark: what a command costs beyond its computation (warm numba cache). Issue 12's targets: ``--help`` and
``--version`` ≤ 0.3 s, ``inspect`` ≤ 0.8 s, a warm ``run scenes/spom1.toml`` ≤ 2× its compute time.

For each command: the wall time and the CPU time (user + system) of the whole process, the median of REPEATS
runs in alternating rounds (a noisy moment hits every command alike), against its **compute time**: the
median time of the command's computation alone, repeated in one process that has run it once already (imports
done, numba kernels loaded), writing nothing. That is the part a faster start-up cannot remove:

    inspect: summarise_file(run file)    solve: trace_primary to λ2(0) = 3    run: the whole picture (api.computed)

The ratios are wall / compute wall and CPU / compute CPU (the CPU ratio is the steadier one on a loaded
machine: another process's share of the cores stretches wall times, not CPU times). Then,
for ``run``, where the rest goes, measured inside one fresh process doing what the CLI does: imports, the first
computation (numba loads its cached kernels on first call), the write. Last, the **floor** no package that calls
numba kernels from a fresh process can go below: a bare interpreter that imports numpy and numba and calls one
trivial cached kernel (and the same with scipy.linalg and h5py, the rest of a run's third-party stack), against
the 2x-compute budget of ``run``. The load average is printed before and after: on a loaded machine every number
grows, the ratios less so.

    python benchmarks/startup.py                       # the installed balloon-cg of this interpreter
    python benchmarks/startup.py --python A --python B # several installs, interleaved in the same rounds
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPEATS = 5
ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "scenes" / "spom1.toml"
TARGETS = {"--help": "<= 0.3 s", "--version": "<= 0.3 s", "inspect": "<= 0.8 s", "run": "<= 2x compute",
           "run (quiet)": "<= 2x compute"}

# imports, first computation and write of one fresh process, then the steady compute of every command
MEASURE = """
import json, statistics, sys, time
clocks = (time.perf_counter, time.process_time)
t0 = [c() for c in clocks]
try:
    from balloon_cg.analysis.branches.primary import trace_primary
except ImportError:  # an install from before analysis/ was regrouped (session 21)
    from balloon_cg.analysis.primary import trace_primary
from balloon_cg.app.api import computed
from balloon_cg.app.summaries import summarise_file
from balloon_cg.io.run_file import write_run
from balloon_cg.scene import load_scene
scene = load_scene(sys.argv[1])
t1 = [c() for c in clocks]
branches, snaps, found, _, _ = computed(scene)
t2 = [c() for c in clocks]
write_run(sys.argv[2], scene, branches, force=True, snaps=snaps, found=found)
t3 = [c() for c in clocks]
work = {"inspect": lambda: summarise_file(sys.argv[2]), "solve": lambda: trace_primary(scene, stop_stretch=3.0,
        down=False), "run": lambda: computed(scene)}
steady = {}
for name, f in work.items():
    f()
    times = []
    for _ in range(int(sys.argv[3])):
        t = [c() for c in clocks]; f(); times.append([c() - s for c, s in zip(clocks, t)])
    steady[name] = [statistics.median(column) for column in zip(*times)]
print(json.dumps({"steady": steady, "imports": [b - a for a, b in zip(t0, t1)],
                  "first": [b - a for a, b in zip(t1, t2)], "write": [b - a for a, b in zip(t2, t3)]}))
"""

# a trivial cached numba kernel, called once from a fresh interpreter (the floor of any numba-calling process)
FLOOR_KERNEL = """
from numba import njit


@njit(cache=True)
def total(x):
    s = 0.0
    for i in range(x.shape[0]):
        s += x[i]
    return s
"""
FLOOR = {"python + numpy + numba + one cached kernel": "import numpy, numba, floor_kernel; "
                                                       "floor_kernel.total(numpy.ones(3))",
         "the same + scipy.linalg + h5py": "import numpy, numba, scipy.linalg, h5py, floor_kernel; "
                                           "floor_kernel.total(numpy.ones(3))"}


def timed(args, **options) -> tuple[float, float]:
    """(wall, CPU) seconds of one child process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(args, check=True, capture_output=True, **options)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def load() -> str:
    one, five, _ = os.getloadavg()
    return f"load average {one:.2f} (1 min), {five:.2f} (5 min) on {os.cpu_count()} CPUs"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--python", action="append", help="an interpreter with balloon-cg installed (repeatable; "
                                                          "default: this one)")
    parser.add_argument("--repeats", type=int, default=REPEATS)
    options = parser.parse_args()
    pythons = options.python or [sys.executable]
    print(f"start: {load()}; {options.repeats} repetitions, medians\n")
    with tempfile.TemporaryDirectory() as tmp:
        runs = {py: Path(tmp) / f"run{i}.h5" for i, py in enumerate(pythons)}
        commands = {py: {"--help": ["--help"], "--version": ["--version"], "inspect": ["inspect", runs[py]],
                         "solve": ["solve", SCENE, "--pole-stretch", "3.0"],
                         "run": ["run", SCENE, "-o", runs[py], "--force"],
                         "run (quiet)": ["run", SCENE, "-o", runs[py], "--quiet", "--force"]} for py in pythons}
        cli = {py: [py, "-m", "balloon_cg"] for py in pythons}
        for py in pythons:  # warms numba's cache and writes the file inspect reads
            timed([*cli[py], "run", SCENE, "-o", runs[py], "--quiet", "--force"])
        (Path(tmp) / "floor_kernel.py").write_text(FLOOR_KERNEL)
        floor_env = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / "numba")}
        floor_run = {name: [pythons[0], "-c", code] for name, code in FLOOR.items()}
        for args in floor_run.values():  # compiles the kernel into its cache
            timed(args, cwd=tmp, env=floor_env)
        floors = {name: [] for name in FLOOR}
        measured = {py: [] for py in pythons}
        walls = {py: {name: [] for name in commands[py]} for py in pythons}
        for _ in range(options.repeats):
            for py in pythons:
                for name, args in commands[py].items():
                    walls[py][name].append(timed([*cli[py], *map(str, args)]))
            for py in pythons:
                out = subprocess.run([py, "-c", MEASURE, str(SCENE), str(Path(tmp) / "measure.h5"), "3"],
                                     check=True, capture_output=True, text=True).stdout
                measured[py].append(json.loads(out))
            for name, args in floor_run.items():
                floors[name].append(timed(args, cwd=tmp, env=floor_env))
    for py in pythons:
        steady = {name: [statistics.median(m["steady"][name][k] for m in measured[py]) for k in (0, 1)]
                  for name in ("inspect", "solve", "run")}
        steady["run (quiet)"] = steady["run"]
        print(f"{py}\n{'command':<34} {'wall (s)':>9} {'CPU (s)':>8} {'compute wall':>13} {'compute CPU':>12} "
              f"{'wall ratio':>11} {'CPU ratio':>10}  target")
        for name, args in commands[py].items():
            wall = statistics.median(w for w, _ in walls[py][name])
            cpu = statistics.median(c for _, c in walls[py][name])
            label = " ".join(a.name if isinstance(a, Path) else str(a) for a in args)[:34]
            if name in steady:
                c_wall, c_cpu = steady[name]
                numbers = f"{c_wall:13.3f} {c_cpu:12.3f} {wall / c_wall:11.2f} {cpu / c_cpu:10.2f}"
            else:
                numbers = f"{'-':>13} {'-':>12} {'-':>11} {'-':>10}"
            print(f"{label:<34} {wall:9.3f} {cpu:8.3f} {numbers}  {TARGETS.get(name, '')}")
        parts = {k: [statistics.median(m[k][i] for m in measured[py]) for i in (0, 1)]
                 for k in ("imports", "first", "write")}
        print("run, inside one fresh process (wall / CPU s): imports {:.3f} / {:.3f}, first computation {:.3f} / "
              "{:.3f} (of which beyond the steady compute, numba loading its kernels and first-call work: {:.3f} / "
              "{:.3f}), write {:.3f} / {:.3f}\n".format(
                  *parts["imports"], *parts["first"], parts["first"][0] - steady["run"][0],
                  parts["first"][1] - steady["run"][1], *parts["write"]))
    run = [statistics.median(m["steady"]["run"][k] for m in measured[pythons[0]]) for k in (0, 1)]
    print(f"floor of a fresh process (warm numba cache; {pythons[0]}), against run's budget 2x compute = "
          f"{2 * run[0]:.3f} s wall, {2 * run[1]:.3f} s CPU; 'floor + compute' is the smallest ratio a run can reach"
          f"\n{'process':<44} {'wall (s)':>9} {'CPU (s)':>8} {'floor+compute wall ratio':>25} {'CPU ratio':>10}")
    for name, times in floors.items():
        wall, cpu = (statistics.median(t[k] for t in times) for k in (0, 1))
        print(f"{name:<44} {wall:9.3f} {cpu:8.3f} {(wall + run[0]) / run[0]:25.2f} {(cpu + run[1]) / run[1]:10.2f}")
    print(f"\nend: {load()}")


if __name__ == "__main__":
    main()
