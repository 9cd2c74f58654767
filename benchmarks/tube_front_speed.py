"""Benchmark: what a tube's bulge branch costs, flagged (one Legendre series) and resolved (spectral elements,
tube/front.py), against spom1's whole picture (issue 38's speed acceptance), for one or more installs in one run.

Each measurement runs in a fresh process per install (installs alternate, measurement by measurement), after a warm-up
in that process (the scene's primary branch: its kernels loaded, its tables built), and reports the process's CPU
seconds of the measured call (BLAS held to one thread, as the traces hold it: the steady number on a shared machine):

    spom1 picture      analysis.picture.analyse(scenes/spom1.toml), its second call (whole_picture.py's measure)
    L10 flag           scenes/tube_spom1_L10.toml: primary branch, onset, bulge at solver.degree 40 to a hoop stretch of 9
    L10 elements       the same, the bulge by front_bulge (refined until every point's tail ≤ solver.max_error 1e-9)
    L30 flag           Ogden's 1972 rubber, L = 30 (tests/test_tube_maxwell.py): primary, onset, bulge at degree 120 to
                       V/V0 = 50 (the degree at which the acceptance's |P − P_M| ≤ 1e-6 holds: docs/tubes.md)
    L30 elements       the same, the bulge by front_bulge (E p up to 400 per field)

Then, per install, each measurement over spom1's picture (the acceptance: L30 ≤ 10×) and elements over flag; with
several installs, each install's seconds over the first's. The load average is printed before and after.

    python benchmarks/tube_front_speed.py --python /path/to/main/venv/bin/python --python python
"""
import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MEASUREMENTS = ("spom1 picture", "L10 flag", "L10 elements", "L30 flag", "L30 elements")

MEASURE = """
import json, math, sys, time
from pathlib import Path
ROOT = Path(sys.argv[1])
sys.path.insert(0, str(ROOT / "tests"))
from balloon_cg.numerics.threads import limited_blas
which = sys.argv[2]
if which == "spom1 picture":
    from balloon_cg.analysis import picture
    from balloon_cg.scene import load_scene
    scene = load_scene(ROOT / "scenes" / "spom1.toml")
    picture.analyse(scene)
    run = lambda: picture.analyse(scene)
else:
    from balloon_cg.analysis.branches.resolution import Resolution
    from balloon_cg.tube.bulge import bulge_branch
    from balloon_cg.tube.front import front_bulge
    from balloon_cg.tube.primary import primary_branch
    if which.startswith("L10"):
        from balloon_cg.scene import load_scene
        scene = load_scene(ROOT / "scenes" / "tube_spom1_L10.toml")
        trace = dict(stop_stretch=scene.continuation.stop_stretch)
    else:
        from test_tube_maxwell import LENGTH, ogden_1972_tube
        scene = ogden_1972_tube(120)
        trace = dict(stop_volume=50.0 * math.pi * LENGTH, step=0.02)  # V/R0³ for V/V0 = 50 (bulge_branch's key)
    primary_branch(scene)

    def run():
        primary = primary_branch(scene)
        onset = primary.branch_points()[0]
        if which.endswith("flag"):
            return bulge_branch(scene, primary, onset, **trace)
        return front_bulge(scene, primary, onset, Resolution(scene.solver.max_error, 400), **trace)
start = time.process_time()
found = limited_blas(run)()
seconds = time.process_time() - start
facts = {}
if hasattr(found, "tail"):
    facts = {"points": len(found.volume), "unknowns": int(found.disc.size), "tail": float(found.tail.max()),
             "stop": str(found.stop.code), "P_end": float(found.pressure[-1]), "V_end": float(found.volume[-1])}
print(json.dumps({"cpu": seconds, **facts}))
"""


def measure(python: str, which: str) -> dict:
    """One fresh process of ``python`` measuring ``which`` (module docstring)."""
    done = subprocess.run([python, "-c", MEASURE, str(ROOT), which], capture_output=True, text=True,
                          env=os.environ | {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"})
    if done.returncode != 0:
        raise RuntimeError(f"{python} {which}: {done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--python", action="append", help="an install's interpreter (default: this one)")
    parser.add_argument("--only", action="append", choices=MEASUREMENTS, help="measure these only")
    args = parser.parse_args()
    pythons = args.python or [sys.executable]
    which = args.only or list(MEASUREMENTS)
    print(f"load average {os.getloadavg()[0]:.1f} {os.getloadavg()[1]:.1f} at the start (2 cores)")
    results = {python: {} for python in pythons}
    for name in which:
        for python in pythons:
            results[python][name] = found = measure(python, name)
            print(f"  {name:>13} {python}: {json.dumps(found)}", flush=True)
    print(f"load average {os.getloadavg()[0]:.1f} {os.getloadavg()[1]:.1f} at the end")
    for python in pythons:
        cpu = {name: results[python][name]["cpu"] for name in which}
        print(f"\n{python}: CPU s (points, unknowns, largest tail, stop)")
        for name in which:
            r = results[python][name]
            extra = (f"  {r['points']:4d} pts {r['unknowns']:5d} unknowns tail {r['tail']:.2e} {r['stop']}"
                     if "points" in r else "")
            print(f"  {name:>13} {cpu[name]:8.2f}{extra}")
        if "spom1 picture" in cpu:
            print("  over spom1's picture: " + ", ".join(f"{name} {cpu[name] / cpu['spom1 picture']:.1f}x"
                                                     for name in which if name != "spom1 picture"))
        for tube in ("L10", "L30"):
            if f"{tube} flag" in cpu and f"{tube} elements" in cpu:
                print(f"  {tube} elements / flag: {cpu[f'{tube} elements'] / cpu[f'{tube} flag']:.1f}x")
    for python in pythons[1:]:
        print(f"\n{python} over {pythons[0]}: " + ", ".join(
            f"{name} {results[python][name]['cpu'] / results[pythons[0]][name]['cpu']:.2f}x" for name in which))


if __name__ == "__main__":
    main()
