"""Benchmark: the default run's tail in its main process (``make run``, issue 37): what it does once its own run
file is written and its child is done, the figures of the last scene, the combined figures and the summary table.

    old  as main e5dc1e8 did it: each file read for each use (its figures, the combined figures, the summary row:
         the two-coil file three times, spom1's twice), through a plain h5py.File (every ``group[name]`` opens
         the object again), the figures drawn one after another in this process
    new  app/default_run.py now: each file read once, through io.layout.opened's file (each member opened once),
         the figures drawn on the cores (numerics.workers.spread)

Both draw the same figures into two folders, compared byte for byte. Wall and CPU seconds (this process and the
workers it waited for), the variants alternating, the load before and after.

    python benchmarks/default_run_tail.py RUNS_DIR [--rounds 3]

RUNS_DIR holds spom1.h5 and spom1_two_coils_M0.002.h5 of a default run (``make run`` writes them to out/).
"""
import argparse
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

import h5py

from balloon_cg.app import default_run
from balloon_cg.io import layout
from balloon_cg.io.run_file import read_run
from balloon_cg.numerics.workers import serial


def old(paths: list[Path], outdir: Path) -> None:
    reader = layout._ReadFile
    layout._ReadFile = h5py.File
    try:
        with serial():
            default_run.draw_figures(paths[-1:], outdir, default_run.SCENES[-1])
            default_run.draw_figures(paths, outdir, "all", default_run.COMBINED)
        [default_run.summary_row(read_run(path)) for path in paths]
    finally:
        layout._ReadFile = reader


def new(paths: list[Path], outdir: Path) -> None:
    runs = [read_run(path) for path in paths]
    default_run.drawn(default_run.figures(runs[-1:], outdir, default_run.SCENES[-1])
                      + default_run.figures(runs, outdir, "all", default_run.COMBINED))
    [default_run.summary_row(run) for run in runs]


def timed(variant, paths, outdir) -> tuple[float, float]:
    """(wall, CPU) seconds of one call: this process's CPU and its waited-for children's."""
    def cpu():
        own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime

    start, before = time.perf_counter(), cpu()
    variant(paths, outdir)
    return time.perf_counter() - start, cpu() - before


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", help="folder with the default run's run files")
    parser.add_argument("--rounds", type=int, default=3)
    options = parser.parse_args()
    paths = [Path(options.runs) / f"{name}.h5" for name in default_run.SCENES]
    missing = [str(p) for p in paths if not p.is_file()]
    if missing:
        sys.exit(f"runs: {', '.join(missing)} missing (the run files of a default run: make run writes them to out/)")
    print(f"{os.cpu_count()} CPUs; load {os.getloadavg()[0]:.1f} (1 min), {os.getloadavg()[1]:.1f} (5 min) before")
    new(paths, Path(tempfile.mkdtemp()))  # the figures' and the reader's imports, matplotlib's font cache
    results = {"old": [], "new": []}
    with tempfile.TemporaryDirectory(prefix="tail_") as tmp:
        folders = {side: Path(tmp) / side for side in results}
        for folder in folders.values():
            folder.mkdir()
        for r in range(options.rounds):
            for side in ("old", "new") if r % 2 == 0 else ("new", "old"):
                results[side].append(timed(old if side == "old" else new, paths, folders[side]))
        images = sorted(p.name for p in folders["old"].iterdir())
        differ = [name for name in images
                  if (folders["old"] / name).read_bytes() != (folders["new"] / name).read_bytes()]
        assert images == sorted(p.name for p in folders["new"].iterdir())
    print(f"load {os.getloadavg()[0]:.1f} (1 min), {os.getloadavg()[1]:.1f} (5 min) after; {len(images)} figures, "
          f"{'all byte for byte the same' if not differ else 'DIFFERENT: ' + ', '.join(differ)}")
    print(f"\n{'round':<6} {'old wall':>9} {'new wall':>9} {'ratio':>6} {'old CPU':>8} {'new CPU':>8} {'ratio':>6}")
    for r, ((ow, oc), (nw, nc)) in enumerate(zip(results["old"], results["new"])):
        print(f"{r + 1:<6} {ow:9.2f} {nw:9.2f} {nw / ow:6.2f} {oc:8.2f} {nc:8.2f} {nc / oc:6.2f}")


if __name__ == "__main__":
    main()
