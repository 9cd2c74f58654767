"""Benchmark: a 21-member sweep over M, each member the full analysis (primary branch, stability, branch points,
pear branches). Two studies (``--study``): ``single-coil`` (default), M = 0 .. 0.005 on the single-coil SPOM1
scene (stop_stretch 3, about 0.5-1 s per member); ``two-coils``, M = 0 .. 0.003 on the paper's two-coil SPOM1
scene (issue 14's sweep; the largest fields bring the membrane close to the wires).

Runs the command ``balloon-cg sweep`` in a fresh interpreter each time (worker start-up and numba cache loading
included; the time of importing balloon_cg in the parent is shown separately) serially (--workers 1) and on 2
local worker processes, then the same members on a dask LocalCluster of 2 single-threaded worker processes
started with balloon-cg's DASK_WORKER_CONFIG (cluster start-up excluded; dask's default malloc setting made its
members 1.4x slower: benchmarks/dask_worker.py). Prints a table with the speed-up
over serial (floor: >= 1.7x for 2 workers on an otherwise idle 2-core machine) and checks that every run stored
the same members. The numba cache is warmed first by a sweep over each range's two ends. Per run the table also shows the busiest
worker's members added up (its members' own compute times: the least the run could take with that assignment) and
the rest of the run's wall time (start-up, writing, the view, the idle tail). Run:
python benchmarks/sweep.py [--study two-coils] [--no-dask] [--note TEXT]
(output also in benchmarks/results/sweep.txt, or sweep_two_coils.txt)
"""
import argparse
import os
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
}
MODE_FLAG = None  # full analysis
CHILD = "import sys, time; from balloon_cg.app.cli import main; t = time.perf_counter(); main(sys.argv[1:]); print(time.perf_counter() - t)"


def cli_run(scene: Path, vary: list, out: Path, workers: int) -> tuple[float, float]:
    """(wall time of the sweep command after import, wall time of the whole process)."""
    argv = [sys.executable, "-c", CHILD, "sweep", str(scene), *sum((["--vary", v] for v in vary), []),
            "-o", str(out), *([MODE_FLAG] if MODE_FLAG else []), "--workers", str(workers), "--quiet"]
    start = time.perf_counter()
    done = subprocess.run(argv, check=True, capture_output=True, text=True)
    return float(done.stdout.split()[-1]), time.perf_counter() - start


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
        return t, t


def same(a: Path, b: Path) -> bool:
    ra, rb = read_sweep(a)["members"], read_sweep(b)["members"]
    return sorted(ra) == sorted(rb) and all(
        np.allclose(ra[i]["branches"]["primary"]["unknowns"], rb[i]["branches"]["primary"]["unknowns"],
                    rtol=1e-12, atol=1e-14) for i in ra)


def member_sum(path: Path) -> float:
    return sum(m["attrs"]["wall_time"] for m in read_sweep(path)["members"].values())


def busiest_worker(path: Path) -> float:
    """The largest sum of the members' compute times over the worker processes that computed them."""
    by_worker = {}
    for m in read_sweep(path)["members"].values():
        by_worker[m["attrs"]["worker_pid"]] = by_worker.get(m["attrs"]["worker_pid"], 0.0) + m["attrs"]["wall_time"]
    return max(by_worker.values())


def ends(spec: str) -> str:
    """A --vary range START:STOP:COUNT as its two ends (the warm-up: every kernel the members load); else as given."""
    key, _, text = spec.partition("=")
    parts = text.split(":")
    return f"{key}={parts[0]}:{parts[1]}:2" if len(parts) == 3 else spec


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--study", choices=sorted(STUDIES), default="single-coil")
    parser.add_argument("--no-dask", action="store_true", help="leave out the dask LocalCluster row")
    parser.add_argument("--note", default="", help="a first line naming the install and the machine's state")
    args = parser.parse_args()
    scene, vary, result_name = STUDIES[args.study]
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        cli_run(scene, [ends(v) for v in vary], tmp / "warm.h5", 1)  # numba cache warm for every run below
        rows = [("serial (--workers 1)", cli_run(scene, vary, tmp / "serial.h5", 1), tmp / "serial.h5"),
                ("local pool, 2 workers", cli_run(scene, vary, tmp / "pool.h5", 2), tmp / "pool.h5")]
        t = None if args.no_dask else dask_run(scene, vary, tmp / "dask.h5")
        if t is not None:
            rows.append(("dask LocalCluster, 2 workers", t, tmp / "dask.h5"))
        members = read_sweep(tmp / "serial.h5")["members"]
        member_time = [m["attrs"]["wall_time"] for m in members.values()]
        serial = rows[0][1][0]
        lines = [args.note] if args.note else []
        lines += [
            f"sweep benchmark: {scene.name}, --vary {' --vary '.join(vary)}, {MODE_FLAG or 'full analysis'}: "
            f"{len(members)} members",
            f"per-member compute time (serial run): mean {np.mean(member_time):.2f} s, "
            f"min {min(member_time):.2f} s, max {max(member_time):.2f} s",
            f"cores: {os.cpu_count()}; load average before: {load[0]:.2f}, after: {os.getloadavg()[0]:.2f} "
            "(other processes share the cores)",
            "",
            f"{'run':<30} {'sweep [s]':>10} {'speed-up':>9} {'process [s]':>12} {'speed-up':>9} {'Σ member [s]':>13} {'busiest [s]':>12} {'rest [s]':>9}  same as serial",
        ]
        for name, (wall, total), path in rows:
            lines.append(f"{name:<30} {wall:>10.2f} {serial / wall:>8.2f}x {total:>12.2f} "
                         f"{rows[0][1][1] / total:>8.2f}x {member_sum(path):>13.2f} {busiest_worker(path):>12.2f} "
                         f"{wall - busiest_worker(path):>9.2f}  {same(rows[0][2], path)}")
        lines += ["", "sweep: the sweep command after `import balloon_cg` (includes starting the local workers and "
                  "their numba cache loading); process: the whole `python -c ...` run including imports. The dask "
                  "row excludes the cluster start-up (the cluster exists before the sweep); its workers run with "
                  "DASK_WORKER_CONFIG.",
                  "Σ member: the members' own compute times added up; larger than the serial one means the workers "
                  "competed for the cores with other processes. busiest: the largest sum of member times over the worker "
                  "processes (the run's least wall time with that assignment); rest: sweep − busiest (start-up, "
                  "writing, the view and table, a worker idle while the last member runs)."]
    text = "\n".join(lines)
    print(text)
    out = ROOT / "benchmarks" / "results" / result_name
    out.write_text(text + "\n")


if __name__ == "__main__":
    main()
