"""Benchmark: the whole picture of a field scene against the M = 0 scene's, per phase (issue 28's floors).

For each scene (spom1, spom1_two_coils_M0.002, spom1_paper_coil) one fresh process per install runs
``analysis.picture.analyse`` on it twice (the first loads the numba kernels) and reports the second's CPU time
(process time: BLAS is single-threaded, so on a shared machine it is the steady number) per phase, each phase
measured by wrapping the functions ``analyse`` calls for it, the same in every install:

    trace: primary.trace_primary   stability: stability.assess_branch   branch points: bifurcation.locate, classify
    pear branches: switching.trace_pear   m >= 1 crossings: azimuthal_points.find
    surface branches: surface_branches.trace_surface (its stability and secondary points included)

Then the floors as ratios of one run: the two-coil picture ≤ 2× the spom1 picture, paper_coil ≤ 5× it; also without
the surface branches (the axisymmetric analysis the issue measured when it was filed). Installs are given as
interpreters (``--python``, default this one) and run in alternation, scene by scene; an interpreter may carry scene
keys to set, ``PYTHON::KEY=VALUE[,KEY=VALUE]`` (one install against itself with another setting).

    python benchmarks/whole_picture.py --python /path/to/main/venv/bin/python --python python
    python benchmarks/whole_picture.py --python python --python python::stability.basis=mapped
"""
import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENES = ("spom1", "spom1_two_coils_M0.002", "spom1_paper_coil")
FLOORS = {"spom1_two_coils_M0.002": 2.0, "spom1_paper_coil": 5.0}
PHASES = ("trace", "stability", "branch points", "pear branches", "m >= 1 crossings", "surface branches")

MEASURE = """
import json, sys, time
from balloon_cg.analysis import azimuthal_points, bifurcation, picture, surface_branches
from balloon_cg.scene import load_scene
seconds = {}

def timed(phase, f):
    def wrapper(*args, **kwargs):
        start = time.process_time()
        try:
            return f(*args, **kwargs)
        finally:
            seconds[phase] = seconds.get(phase, 0.0) + time.process_time() - start
    return wrapper

for module, name, phase in ((picture, "trace_primary", "trace"), (picture, "assess_branch", "stability"),
                            (bifurcation, "locate", "branch points"), (bifurcation, "classify", "branch points"),
                            (picture, "trace_pear", "pear branches"), (azimuthal_points, "find", "m >= 1 crossings"),
                            (surface_branches, "trace_surface", "surface branches")):
    setattr(module, name, timed(phase, getattr(module, name)))
scene = load_scene(sys.argv[1])
overrides = json.loads(sys.argv[2])
if overrides:
    scene = scene.with_overrides(overrides, name=scene.name)
picture.analyse(scene)
seconds.clear()
start = time.process_time()
found = picture.analyse(scene)
total = time.process_time() - start
print(json.dumps({"total": total, "phases": seconds, "points": int(sum(len(b.X) for b in found.branches))}))
"""


def measure(python: str, scene: str) -> dict:
    """One fresh process of ``python`` (``PYTHON::KEY=VALUE,...``: with those scene keys set) on ``scene``."""
    python, _, settings = python.partition("::")
    overrides = {key: _value(value) for key, value in (item.split("=", 1) for item in settings.split(",") if item)}
    out = subprocess.run([python, "-c", MEASURE, str(ROOT / "scenes" / f"{scene}.toml"), json.dumps(overrides)],
                         capture_output=True,
                         text=True, check=True, cwd=ROOT.parent)
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
    args = parser.parse_args(argv)
    pythons = args.python or [sys.executable]
    results = {python: {} for python in pythons}
    for scene in args.scenes:
        for python in pythons:
            results[python][scene] = measure(python, scene)
    for python, found in results.items():
        print(f"\n{python} (CPU seconds of the second analyse in a fresh process)")
        print(f"  {'scene':<24}{'total':>9}" + "".join(f"{p:>18}" for p in PHASES))
        for scene, r in found.items():
            print(f"  {scene:<24}{r['total']:9.2f}" + "".join(f"{r['phases'].get(p, 0.0):18.2f}" for p in PHASES))
        base = found.get("spom1")
        if base is None:
            continue
        for scene, floor in FLOORS.items():
            if scene in found:
                r = found[scene]
                whole = r["total"] / base["total"]
                axisymmetric = ((r["total"] - r["phases"].get("surface branches", 0.0))
                                / (base["total"] - base["phases"].get("surface branches", 0.0)))
                print(f"  {scene} / spom1: whole picture {whole:.1f}x (floor <= {floor:g}x: "
                      f"{'met' if whole <= floor else 'NOT met'}), without the surface branches {axisymmetric:.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
