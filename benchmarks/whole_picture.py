"""Benchmark: the whole picture of a field scene against the M = 0 scene's, per phase (issue 37's floors).

For each scene (spom1, spom1_two_coils_M0.002, spom1_paper_coil, and the off-equator coil of
tests/data/off_equator.toml) one fresh process per install runs ``analysis.picture.analyse`` on it twice (the first
loads the numba kernels; with ``--first`` once: a user's ``run`` with the kernels compiled, the cached kernels loaded
and every basis, plan and table built for the first time, where a second run finds the first's bases in their
caches) and reports the measured run's wall time (what a user waits for: the points of a branch are
assessed on every core, ``numerics.workers``), its CPU time (this process and its workers) and per phase the CPU
seconds of this process (BLAS is single-threaded, so on a shared machine it is the steady number; a phase whose
points went to workers shows only its share here), each phase measured by wrapping the functions ``analyse`` calls
for it, the same in every install (then this process's CPU outside them, ``untimed``, and its workers', ``workers``):

    trace: primary.trace_primary   stability: stability.assess_branch   branch points: bifurcation.locate, classify
    pear branches: switching.trace_pear, broken_symmetry.broken_pear (the off-equator coil's disconnected pear
    branch: its homotopy in the coil heights and trace; untimed before session 22)   m >= 1 crossings: azimuthal_points.find
    surface branches: surface_branches.trace_surface (its stability and secondary points included)

A call inside a timed one (the broken pear's seed assesses a branch and locates its pitchfork) counts in the
outer one's phase only.

Then the floors as ratios of one run, in wall time: the two-coil picture ≤ 10× the spom1 picture, the paper coil
and the off-equator coil ≤ 20× it; also in CPU time. Installs are given as interpreters (``--python``, default this
one) and run in alternation, scene by scene; with several, the ratios of each install's seconds to the first's, wall,
CPU and per phase. An interpreter may carry scene keys to set, ``PYTHON::KEY=VALUE[,KEY=VALUE]`` (one install
against itself with another setting).

    python benchmarks/whole_picture.py --python /path/to/main/venv/bin/python --python python
    python benchmarks/whole_picture.py --python python --python python::stability.basis=mapped
    BALLOON_CG_WORKERS=1 python benchmarks/whole_picture.py --first --python /main/venv/bin/python --python python
"""
import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENES = ("spom1", "spom1_two_coils_M0.002", "spom1_paper_coil", "off_equator")
FLOORS = {"spom1_two_coils_M0.002": 10.0, "spom1_paper_coil": 20.0, "off_equator": 20.0}
PATHS = {"off_equator": ROOT / "tests" / "data" / "off_equator.toml"}
PHASES = ("trace", "stability", "branch points", "pear branches", "m >= 1 crossings", "surface branches", "untimed",
          "workers")  # untimed: this process's CPU outside the phases; workers: the CPU of its worker processes

MEASURE = """
import json, resource, sys, time
from balloon_cg.analysis import picture
try:
    from balloon_cg.analysis.points import azimuthal_points, branch_points as bifurcation
    from balloon_cg.analysis.surface import branches as surface_branches
except ImportError:  # an install from before analysis/ was regrouped (session 21)
    from balloon_cg.analysis import azimuthal_points, bifurcation, surface_branches
from balloon_cg.scene import load_scene
seconds = {}

running = []  # the timed call in progress: a timed call inside it counts in its phase (module docstring)

def timed(phase, f):
    def wrapper(*args, **kwargs):
        if running:
            return f(*args, **kwargs)
        start = time.process_time()
        running.append(phase)
        try:
            return f(*args, **kwargs)
        finally:
            running.pop()
            seconds[phase] = seconds.get(phase, 0.0) + time.process_time() - start
    return wrapper

for module, name, phase in ((picture, "trace_primary", "trace"), (picture, "assess_branch", "stability"),
                            (bifurcation, "locate", "branch points"), (bifurcation, "classify", "branch points"),
                            (picture, "trace_pear", "pear branches"),
                            (picture.broken_symmetry, "broken_pear", "pear branches"),
                            (azimuthal_points, "find", "m >= 1 crossings"),
                            (surface_branches, "trace_surface", "surface branches")):
    setattr(module, name, timed(phase, getattr(module, name)))
scene = load_scene(sys.argv[1])
overrides = json.loads(sys.argv[2])
if overrides:
    scene = scene.with_overrides(overrides, name=scene.name)

def cpu():
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime, children.ru_utime + children.ru_stime

if not json.loads(sys.argv[3]):
    picture.analyse(scene)
seconds.clear()
start, (own, children) = time.perf_counter(), cpu()
found = picture.analyse(scene)
wall, (own, children) = time.perf_counter() - start, [now - then for now, then in zip(cpu(), (own, children))]
seconds["untimed"], seconds["workers"] = own - sum(seconds.values()), children
print(json.dumps({"wall": wall, "total": own + children, "phases": seconds,
                  "points": int(sum(len(b.X) for b in found.branches)),
                  "surface_points": int(sum(len(b.values) for b in found.surface_branches))}))
"""


def measure(python: str, scene: str, first: bool = False) -> dict:
    """One fresh process of ``python`` (``PYTHON::KEY=VALUE,...``: with those scene keys set) on ``scene``; ``first``:
    its first analyse measured (module docstring)."""
    python, _, settings = python.partition("::")
    overrides = {key: _value(value) for key, value in (item.split("=", 1) for item in settings.split(",") if item)}
    path = PATHS.get(scene, ROOT / "scenes" / f"{scene}.toml")
    out = subprocess.run([python, "-c", MEASURE, str(path), json.dumps(overrides), json.dumps(first)],
                         capture_output=True, text=True, check=True, cwd=ROOT.parent)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _value(text: str):
    """A number or boolean as such (JSON), anything else as the string it is."""
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--python", action="append", help="an interpreter with balloon-cg installed (repeatable)")
    parser.add_argument("--scenes", nargs="+", default=list(SCENES), help="default: %(default)s")
    parser.add_argument("--first", action="store_true", help="measure each process' first analyse, not its second")
    args = parser.parse_args(argv)
    pythons = args.python or [sys.executable]
    results = {python: {} for python in pythons}
    for scene in args.scenes:
        for python in pythons:
            results[python][scene] = measure(python, scene, args.first)
    for python, found in results.items():
        print(f"\n{python} (the {'first' if args.first else 'second'} analyse in a fresh process: wall s, CPU s with "
              "its workers, per phase CPU s of this process)")
        print(f"  {'scene':<24}{'wall':>9}{'CPU':>9}" + "".join(f"{p:>18}" for p in PHASES))
        for scene, r in found.items():
            print(f"  {scene:<24}{r['wall']:9.2f}{r['total']:9.2f}"
                  + "".join(f"{r['phases'].get(p, 0.0):18.2f}" for p in PHASES))
        for scene, r in found.items():  # issue 37's "whole analysis per point" (against a solve_bvp point)
            points = r["points"] + r.get("surface_points", 0)
            print(f"  {scene}: {points} points ({r.get('surface_points', 0)} on surface branches), "
                  f"{1e3 * r['total'] / points:.1f} ms of CPU and {1e3 * r['wall'] / points:.1f} ms of wall per point")
        base = found.get("spom1")
        if base is None:
            continue
        for scene, floor in FLOORS.items():
            if scene in found:
                r = found[scene]
                whole, cpu = r["wall"] / base["wall"], r["total"] / base["total"]
                print(f"  {scene} / spom1: whole picture {whole:.1f}x in wall time (floor <= {floor:g}x: "
                      f"{'met' if whole <= floor else 'NOT met'}), {cpu:.1f}x in CPU time")
    first = pythons[0]
    for python in pythons[1:]:
        print(f"\n{python} / {first} (ratios of one run: wall, CPU with workers, per phase CPU of the process)")
        print(f"  {'scene':<24}{'wall':>9}{'CPU':>9}" + "".join(f"{p:>18}" for p in PHASES))
        for scene, r in results[python].items():
            r0 = results[first][scene]
            ratios = [_ratio(r["phases"].get(p), r0["phases"].get(p)) for p in PHASES]
            print(f"  {scene:<24}{_ratio(r['wall'], r0['wall']):>9}{_ratio(r['total'], r0['total']):>9}"
                  + "".join(f"{q:>18}" for q in ratios))
    return 0


def _ratio(new: float | None, old: float | None) -> str:
    """new/old to two decimals, '–' where a phase did not run or took no measurable time."""
    return "–" if not new or not old or old < 0.005 else f"{new / old:.2f}"


if __name__ == "__main__":
    sys.exit(main())
