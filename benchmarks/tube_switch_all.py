"""Benchmark: what switching at every branch point costs ``balloon-cg run`` on a tube (tube/picture.py), against
switching at the first odd one alone (``run`` before it), in one process and one run.

scenes/tube_spom1_L10.toml as shipped (SPOM1, L = 10, degree 40, to a hoop stretch of 9, m = 1 assessed). The primary
branch is traced once (and once before, to load the numba kernels); then ``bulge_picture`` with the first odd label
alone and with every label ``switchable`` gives, each with the m = 1 blocks and their located zeros of every branch
(``with_modes``). Prints the CPU seconds (this process: one BLAS thread, as the traces) of each, the ratio, the
branches and points, and the load average.

    python benchmarks/tube_switch_all.py
"""
import os
import time
from pathlib import Path

from balloon_cg.analysis.results import Kind
from balloon_cg.galerkin.interval import Mirror
from balloon_cg.scene import load_scene
from balloon_cg.tube.picture import bulge_picture, maxwell, switchable
from balloon_cg.tube.primary import primary_branch

SCENE = Path(__file__).resolve().parents[1] / "scenes" / "tube_spom1_L10.toml"


def main() -> None:
    scene = load_scene(SCENE)
    primary_branch(scene)  # the kernels loaded
    start = time.process_time()
    primary = primary_branch(scene)
    primary_cpu = time.process_time() - start
    pm = maxwell(scene)
    first = next(k for k, s in enumerate(primary.special) if s.kind == Kind.BP and s.block == Mirror.ODD)
    rows = []
    for what, labels in (("first odd BP (before)", [first]), ("every BP (now)", switchable(scene, primary))):
        start = time.process_time()
        picture = bulge_picture(scene, primary, labels, pm)
        cpu = time.process_time() - start
        switched = {n: b for n, b in picture.branches.items() if n != "primary"}
        rows.append((what, cpu, len(switched), sum(len(b.pressure) for b in switched.values())))
    print(f"{SCENE.name}: primary branch {primary_cpu:.2f} s CPU, {len(primary.pressure)} points; load average "
          + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    print("| switched at | CPU s (branches + m = 1 blocks) | branches | points | ratio |")
    print("|---|---|---|---|---|")
    for what, cpu, count, points in rows:
        print(f"| {what} | {cpu:.2f} | {count} | {points} | {cpu / rows[0][1]:.2f} |")


if __name__ == "__main__":
    main()
