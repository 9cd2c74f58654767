"""Benchmark: where the wall time of one whole picture goes, as a timeline (issue 37: what idles on 2 cores).

One fresh process of this interpreter runs ``analysis.picture.analyse`` on a scene twice (the first loads the numba
kernels) and prints, for the second, each timed call's start and end in wall seconds from the analysis's start,
its duration, and the CPU seconds of this process and of the worker processes it collected meanwhile
(``RUSAGE_CHILDREN``: a worker counts once it has ended): the phases of benchmarks/whole_picture.py and, nested in
them, each ``numerics.workers.spread`` (its items, total cost and the workers it used). A line that starts after the previous one
ended and overlaps nothing is time this process ran alone; wall time against own + workers' CPU says how many cores
were busy on average.

    python benchmarks/picture_timeline.py scenes/spom1_paper_coil.toml
    /path/to/main/venv/bin/python benchmarks/picture_timeline.py scenes/spom1_paper_coil.toml
"""
import resource
import sys
import time

from balloon_cg.analysis import picture
from balloon_cg.analysis.points import azimuthal_points, branch_points as bifurcation
from balloon_cg.analysis.surface import branches as surface_branches
from balloon_cg.numerics import workers
from balloon_cg.scene import load_scene

events = []  # (start, end, depth, label, own CPU, workers' CPU, detail)
clock = {"start": 0.0, "depth": 0}


def cpu() -> tuple:
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime, children.ru_utime + children.ru_stime


def timed(label, f, detail=None):
    def wrapper(*args, **kwargs):
        start, (own, children) = time.perf_counter(), cpu()
        clock["depth"] += 1
        try:
            return f(*args, **kwargs)
        finally:
            clock["depth"] -= 1
            end, (own_end, children_end) = time.perf_counter(), cpu()
            events.append((start - clock["start"], end - clock["start"], clock["depth"], label, own_end - own,
                           children_end - children, detail(*args, **kwargs) if detail else ""))
    return wrapper


def spread_detail(work, items, costs=None, *args, **kwargs) -> str:
    costs = [1.0] * len(items) if costs is None else list(costs)
    return f"{len(items)} items, cost {sum(costs):.3g}, {workers.sharing(len(items), sum(costs))} workers"


def main(path: str) -> None:
    for module, name, label in ((picture, "trace_primary", "trace"), (picture, "assess_branch", "stability"),
                                (picture, "_branch_points", "branch points"), (picture, "trace_pear", "pear trace"),
                                (picture.mirror, "reflection", "mirror"),
                                (picture.broken_symmetry, "broken_pear", "broken pear"),
                                (azimuthal_points, "find", "m >= 1 crossings"),
                                (surface_branches, "trace_surface", "surface branch"),
                                (picture, "snap_throughs", "snap-throughs")):
        setattr(module, name, timed(label, getattr(module, name)))
    workers.spread = timed("spread", workers.spread, spread_detail)
    scene = load_scene(path)
    picture.analyse(scene)
    events.clear()
    (own, children), clock["start"] = cpu(), time.perf_counter()
    picture.analyse(scene)
    wall, (own_end, children_end) = time.perf_counter() - clock["start"], cpu()
    with open("/proc/loadavg") as f:
        load = " ".join(f.read().split()[:3])
    print(f"{path}: wall {wall:.2f} s, CPU {own_end - own:.2f} s here and {children_end - children:.2f} s in workers "
          f"(load {load}; {sys.executable})")
    print(f"  {'start':>7}{'end':>8}{'wall':>7}  {'call':<36}{'own CPU':>8}{'workers':>8}")
    for start, end, depth, label, own_cpu, workers_cpu, detail in sorted(events, key=lambda e: (e[0], e[2])):
        print(f"  {start:7.2f}{end:8.2f}{end - start:7.2f}  {'  ' * depth + label:<36}{own_cpu:8.2f}"
              f"{workers_cpu:8.2f}  {detail}")


if __name__ == "__main__":
    main(sys.argv[1])
