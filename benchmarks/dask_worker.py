"""Benchmark: one sweep member on a dask worker vs in a local pool worker, and why a dask worker is slower.

The member: M = 0.0015 of the two-coil SPOM1 scene, full analysis (about 9 s; the members of
``benchmarks/sweep.py --study two-coils`` added up to 1.6x more on dask workers than serially).
``compute_member`` runs in a fresh worker process per variant and round (the member once to load the numba
cache, then timed): a local pool worker (main thread, a second thread, glibc malloc variables set before the
worker starts) and a 1-worker dask LocalCluster (dask's defaults, the profiler off, ``DASK_WORKER_CONFIG``).
One worker at a time: one core. Prints per variant the best wall time of the rounds, its ratio to the pool's,
the member thread's user and system CPU time and minor page faults (getrusage RUSAGE_THREAD).
Run: python benchmarks/dask_worker.py [ROUNDS]   (output also in benchmarks/results/dask_worker.txt)
"""
import multiprocessing
import os
import resource
import sys
import threading
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import dask

from balloon_cg.app.sweep import DASK_WORKER_CONFIG, compute_member, overridden
from balloon_cg.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
SCENE, M = ROOT / "scenes" / "spom1_two_coils_M0.002.toml", 0.0015
MALLOC = ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_")


def member_job() -> tuple:
    scene = overridden(load_scene(SCENE), {"field.M": M})
    return 0, scene.to_toml(), scene.name, "analysis"


def timed(job, in_thread: bool = False) -> dict:
    """compute_member(*job) with the CPU time and page faults of the thread computing it."""
    def run(out):
        before = resource.getrusage(resource.RUSAGE_THREAD)
        wall = compute_member(*job).wall_time
        after = resource.getrusage(resource.RUSAGE_THREAD)
        out.update(wall=wall, user=after.ru_utime - before.ru_utime, sys=after.ru_stime - before.ru_stime,
                   faults=after.ru_minflt - before.ru_minflt)
    out = {}
    if in_thread:
        thread = threading.Thread(target=run, args=(out,))
        thread.start()
        thread.join()
    else:
        run(out)
    return out


def clean_malloc_environ(**values) -> None:
    """This process's environment without the glibc malloc variables (a nanny writes its pre-spawn variables
    into the process that starts it), plus ``values``: what a worker started next inherits."""
    for name in MALLOC:
        os.environ.pop(name, None)
    os.environ.update(values)


def pool(in_thread: bool = False, **malloc):
    def run(job):
        clean_malloc_environ(**malloc)
        with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as executor:
            executor.submit(timed, job, in_thread).result()
            return executor.submit(timed, job, in_thread).result()
    return run


def dask_worker(config: dict):
    def run(job):
        from distributed import Client, LocalCluster
        clean_malloc_environ()
        with dask.config.set(config), LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                                   host="127.0.0.1", dashboard_address=None) as cluster:
            with Client(cluster) as client:
                client.submit(timed, job, pure=False).result()
                return client.submit(timed, job, pure=False).result()
    return run


VARIANTS = {
    "pool worker": pool(),
    "pool worker, in a second thread": pool(in_thread=True),
    "pool, MALLOC_TRIM_THRESHOLD_=65536": pool(MALLOC_TRIM_THRESHOLD_="65536"),
    "pool, MALLOC_TRIM_THRESHOLD_=2**30": pool(MALLOC_TRIM_THRESHOLD_=str(2**30)),
    "pool, TRIM=65536, MMAP_THRESHOLD=32M": pool(MALLOC_TRIM_THRESHOLD_="65536",
                                                 MALLOC_MMAP_THRESHOLD_=str(2**25)),
    "dask worker, dask defaults": dask_worker({}),
    "dask worker, profiler off": dask_worker({"distributed.worker.profile.enabled": False}),
    "dask worker, DASK_WORKER_CONFIG": dask_worker(DASK_WORKER_CONFIG),
}


def main():
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    job, runs = member_job(), {name: [] for name in VARIANTS}
    for _ in range(rounds):
        for name, variant in VARIANTS.items():
            runs[name].append(variant(job))
    base = min(r["wall"] for r in runs["pool worker"])
    lines = [f"one sweep member: {SCENE.name} with M = {M}, full analysis; best of {rounds} rounds (variants "
             "alternate within a round); ratio: to the best pool worker; CPU and faults: the member's thread",
             f"load average after: {os.getloadavg()[0]:.2f} (2 cores, shared)", "",
             f"{'variant':<38} {'wall [s]':>9} {'ratio':>6} {'user [s]':>9} {'sys [s]':>8} {'minor faults':>13}"
             "  every round [s]"]
    for name, rs in runs.items():
        best = min(rs, key=lambda r: r["wall"])
        lines.append(f"{name:<38} {best['wall']:>9.2f} {best['wall'] / base:>6.2f} {best['user']:>9.2f} "
                     f"{best['sys']:>8.2f} {best['faults']:>13}  " + " ".join(f"{r['wall']:.2f}" for r in rs))
    text = "\n".join(lines)
    print(text)
    (ROOT / "benchmarks" / "results" / "dask_worker.txt").write_text(text + "\n")


if __name__ == "__main__":
    main()
