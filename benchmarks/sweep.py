"""Benchmark: a 21-member sweep over M, each member the full analysis (primary branch, stability, branch points,
pear branches). Three studies (``--study``): ``single-coil`` (default), M = 0 .. 0.005 on the single-coil SPOM1
scene (stop_stretch 3, about 0.5-1 s per member); ``two-coils``, M = 0 .. 0.003 on the paper's two-coil SPOM1
scene (issue 14's sweep; the largest fields bring the membrane close to the wires); ``two-coils-axisymmetric``, the
same without the non-axisymmetric branches (``[surface] branches = "none"``: the members of that sweep's first rows).

Runs the command ``balloon-cg sweep`` in a fresh interpreter each time (worker start-up and numba cache loading
included; the time of importing balloon_cg in the parent is shown separately) serially (--workers 1) and on 2
local worker processes, then the same members on a dask LocalCluster of 2 single-threaded worker processes
started with balloon-cg's DASK_WORKER_CONFIG (cluster start-up excluded; dask's default malloc setting made its
members 1.4x slower: benchmarks/dask_worker.py). Prints a table with the speed-up
over serial (floor: >= 1.7x for 2 workers on an otherwise idle 2-core machine) and checks that every run stored
the same members. Besides wall times (which a loaded machine stretches), each run's CPU seconds: the process with its workers, each
member's own (its process's CPU over ``compute_member``, printed by the child) added up, and the busiest worker's
members added up: on an otherwise idle machine a run takes at least that long. ``--no-serial`` leaves the serial
run out (then no speed-up column: compare the CPU columns), ``--no-warm`` the warm-up (a sweep over each range's two
ends, which loads or compiles every kernel the members use). Run:
python benchmarks/sweep.py [--study two-coils] [--count N] [--no-warm] [--no-serial] [--no-dask] [--note TEXT]
(output also in benchmarks/results/sweep.txt, or sweep_two_coils.txt)
"""
import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from balloon_cg.scene import load_scene
from balloon_cg.app.sweep import DASK_WORKER_CONFIG, run_sweep
from balloon_cg.io.sweep_file import read_sweep

ROOT = Path(__file__).resolve().parents[1]
# study -> (scene, --vary arguments, results file)
STUDIES = {
    "single-coil": (ROOT / "scenes" / "spom1_single_coil.toml", ["M=0:0.005:21", "stop_stretch=3"], "sweep.txt"),
    "two-coils": (ROOT / "scenes" / "spom1_two_coils_M0.002.toml", ["M=0:0.003:21"], "sweep_two_coils.txt"),
    "two-coils-axisymmetric": (ROOT / "scenes" / "spom1_two_coils_M0.002.toml", ["M=0:0.003:21"],
                               "sweep_two_coils_axisymmetric.txt"),
}
# a study's scene with these lines added (its copy in the run's temporary folder, the same name): the two-coil
# members without their non-axisymmetric branches, the kind of member sweep_two_coils.txt's 2026-12-02 rows held
ADDED = {"two-coils-axisymmetric": '\n[surface]\nbranches = "none"\n'}
MODE_FLAG = None  # full analysis
# the sweep command in a fresh interpreter, each member's CPU seconds printed to stderr (the local pool's forked
# workers look the patched function up by name in this __main__)
CHILD = """
import os, sys, time
from balloon_cg.app import sweep
member = sweep.compute_member
def timed(*args):
    cpu = time.process_time()
    result = member(*args)
    print("member", args[0], os.getpid(), time.process_time() - cpu, file=sys.stderr, flush=True)
    return result
sweep.compute_member = timed
from balloon_cg.app.cli import main
t = time.perf_counter()
main(sys.argv[1:])
print(time.perf_counter() - t)
"""


def children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def cli_run(scene: Path, vary: list, out: Path, workers: int) -> dict:
    """The sweep command's wall time after import, the whole process's wall and CPU time (its workers included),
    and each member's CPU seconds with the process that computed it."""
    argv = [sys.executable, "-c", CHILD, "sweep", str(scene), *sum((["--vary", v] for v in vary), []),
            "-o", str(out), *([MODE_FLAG] if MODE_FLAG else []), "--workers", str(workers), "--quiet"]
    start, cpu = time.perf_counter(), children_cpu()
    done = subprocess.run(argv, check=True, capture_output=True, text=True)
    members = [line.split()[1:] for line in done.stderr.splitlines() if line.startswith("member ")]
    return {"sweep": float(done.stdout.split()[-1]), "process": time.perf_counter() - start,
            "cpu": children_cpu() - cpu, "members": {int(i): (pid, float(c)) for i, pid, c in members}}


def dask_run(scene: Path, vary: list, out: Path) -> float | None:
    try:
        import dask
        from distributed import LocalCluster
    except ImportError:
        return None
    with dask.config.set(DASK_WORKER_CONFIG), LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                                           host="127.0.0.1", dashboard_address=None) as cluster:
        start = time.perf_counter()
        run_sweep(load_scene(scene), vary, out, mode="analysis", scheduler=cluster.scheduler_address)
        t = time.perf_counter() - start
        return {"sweep": t, "process": t, "cpu": None, "members": {}}


def same(a: Path, b: Path) -> bool:
    ra, rb = read_sweep(a)["members"], read_sweep(b)["members"]
    return sorted(ra) == sorted(rb) and all(
        np.allclose(ra[i]["branches"]["primary"]["unknowns"], rb[i]["branches"]["primary"]["unknowns"],
                    rtol=1e-12, atol=1e-14) for i in ra)


def member_sum(path: Path) -> float:
    return sum(m["attrs"]["wall_time"] for m in read_sweep(path)["members"].values())


def busiest(members: dict) -> float:
    """The largest sum of members' CPU seconds over the processes that computed them."""
    by_process = {}
    for pid, cpu in members.values():
        by_process[pid] = by_process.get(pid, 0.0) + cpu
    return max(by_process.values())


def ends(spec: str) -> str:
    """A --vary range START:STOP:COUNT as its two ends (the warm-up); anything else as given."""
    key, _, text = spec.partition("=")
    parts = text.split(":")
    return f"{key}={parts[0]}:{parts[1]}:2" if len(parts) == 3 else spec


def cells(run: dict, path: Path, serial: dict | None, reference: Path) -> str:
    """One row of the table after the run's name."""
    def seconds(x):
        return f"{x:>9.2f}" if x is not None else f"{'–':>9}"

    def ratio(key):
        return f"{serial[key] / run[key]:>7.2f}x" if serial is not None else f"{'–':>8}"

    member_cpu = [c for _, c in run["members"].values()]
    return (f"{seconds(run['sweep'])} {ratio('sweep')} {seconds(run['process'])} {ratio('process')} "
            f"{seconds(run['cpu'])} {seconds(sum(member_cpu) if member_cpu else None)} "
            f"{seconds(busiest(run['members']) if member_cpu else None)} {seconds(member_sum(path))}  "
            f"{same(reference, path)}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--study", choices=sorted(STUDIES), default="single-coil")
    parser.add_argument("--count", type=int, help="the members of each range (default: the study's)")
    parser.add_argument("--no-warm", action="store_true", help="no warm-up (the numba cache is warm already)")
    parser.add_argument("--no-serial", action="store_true", help="leave out the serial run")
    parser.add_argument("--no-dask", action="store_true", help="leave out the dask LocalCluster run")
    parser.add_argument("--note", default="", help="a first line naming the install and the machine's state")
    args = parser.parse_args()
    scene, vary, result_name = STUDIES[args.study]
    if args.count:
        vary = [ends(v).removesuffix(":2") + f":{args.count}" if v != ends(v) else v for v in vary]
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        if args.study in ADDED:
            (tmp / "scene").mkdir()
            scene = (tmp / "scene" / scene.name).resolve()
            scene.write_text(STUDIES[args.study][0].read_text() + ADDED[args.study])
        if not args.no_warm:
            cli_run(scene, [ends(v) for v in vary], tmp / "warm.h5", 1)  # numba cache warm for every run below
        rows = [] if args.no_serial else [("serial (--workers 1)", cli_run(scene, vary, tmp / "serial.h5", 1),
                                           tmp / "serial.h5")]
        rows.append(("local pool, 2 workers", cli_run(scene, vary, tmp / "pool.h5", 2), tmp / "pool.h5"))
        if not args.no_dask:
            t = dask_run(scene, vary, tmp / "dask.h5")
            if t is not None:
                rows.append(("dask LocalCluster, 2 workers", t, tmp / "dask.h5"))
        serial = None if args.no_serial else rows[0][1]
        first = rows[0][1]["members"]
        member_cpu = [c for _, c in first.values()]
        lines = [args.note] if args.note else []
        lines += [
            f"sweep benchmark: {scene.name}, --vary {' --vary '.join(vary)}, {MODE_FLAG or 'full analysis'}: "
            f"{len(first)} members",
            f"per-member CPU ({rows[0][0]}): mean {np.mean(member_cpu):.2f} s, min {min(member_cpu):.2f} s, "
            f"max {max(member_cpu):.2f} s; by member: " + ", ".join(f"{first[i][1]:.1f}" for i in sorted(first)),
            f"cores: {os.cpu_count()}; load average before: {load[0]:.2f}, after: {os.getloadavg()[0]:.2f} "
            "(other processes share the cores)",
            "",
            f"{'run':<30} {'sweep [s]':>9} {'speed-up':>8} {'proc [s]':>9} {'speed-up':>8} {'CPU [s]':>9} "
            f"{'Σ m. CPU':>9} {'busiest':>9} {'Σ m. wall':>9}  same as {rows[0][0]}",
        ]
        lines += [f"{name:<30} {cells(run, path, serial, rows[0][2])}" for name, run, path in rows]
        lines += ["", "sweep: the sweep command after `import balloon_cg` (includes starting the local workers and "
                  "their numba cache loading); proc: the whole `python -c ...` run including imports (wall). The dask "
                  "row excludes the cluster start-up (the cluster exists before the sweep); its workers run with "
                  "DASK_WORKER_CONFIG. CPU: the process's and its workers' CPU seconds. Σ m. CPU: the members' own "
                  "CPU seconds added up; busiest: the largest such sum over the worker processes (on an idle machine "
                  "the run's least wall time with that assignment); Σ m. wall: the members' wall times added up "
                  "(larger than their CPU when other processes shared the cores)."]
    text = "\n".join(lines)
    print(text)
    out = ROOT / "benchmarks" / "results" / result_name
    out.write_text(text + "\n")


if __name__ == "__main__":
    main()
