"""Benchmark: a 30-length tube's uniform branch, onset and bulge branch to V/V0 = 50 against spom1's whole picture
(issue 38's speed item: ≤ 10× in one run).

The tube is scenes/tube_spom1_L10.toml at ``length = 30`` (SPOM1, sliding closed ends) and ``--degree`` (default 90:
there the bulge branch's volume fold is within 3e-12 of degree 150's and its P at V/V0 = 49.5 within 1.4e-7,
benchmarks/results/tube_picture.txt); its work is what
``balloon-cg run`` does with it (tube/picture.py), with the bulge branch stopped at V/V0 = 50: Maxwell's pressure of
the uniform closed tube (model/tube.maxwell_pressure), the primary branch to the hoop stretch ``--stop-stretch``
(default 4.6: the uniform V/V0 = λθ²λz passes 50 at λθ = 4.327) with its folds, branch points and stability, and
the bulge branch switched at its first odd branch point (the onset) to ``stop_volume = 50`` (its point past 50 is
computed, not kept: the last kept point is just below). The sphere is scenes/spom1.toml,
``analysis.picture.analyse`` (its whole picture).

One fresh process per measurement, the two scenes in alternation; each runs its work twice (the first loads the
numba kernels) and reports the second's wall time and CPU time (this process and its workers), and per stage the
CPU seconds of this process (the tube's stages: maxwell, primary, bulge). Then the ratio tube/spom1 in wall and in
CPU time, against the floor of 10×.

    python benchmarks/tube_picture.py [--degree 90] [--repeat 1]
"""
import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FLOOR = 10.0
STOP_VOLUME = 50.0

MEASURE = """
import json, resource, sys, time
from balloon_cg.scene import load_scene
seconds = {}

def cpu():
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime

def stage(name, f, *args, **kwargs):
    start = time.process_time()
    try:
        return f(*args, **kwargs)
    finally:
        seconds[name] = seconds.get(name, 0.0) + time.process_time() - start

kind, path, settings = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
scene = load_scene(path)
if settings["overrides"]:
    scene = scene.with_overrides(settings["overrides"], name=scene.name)
if kind == "sphere":
    from balloon_cg.analysis import picture

    def work():
        found = stage("analyse", picture.analyse, scene)
        return {"points": int(sum(len(b.X) for b in found.branches))}
else:
    from balloon_cg.galerkin.interval import Mirror
    from balloon_cg.tube.bulge import bulge_branch
    from balloon_cg.tube.picture import maxwell
    from balloon_cg.tube.primary import primary_branch

    def work():
        pm = stage("maxwell", maxwell, scene)
        primary = stage("primary", primary_branch, scene)
        onset = primary.branch_points(Mirror.ODD)[0]
        bulge = stage("bulge", bulge_branch, scene, primary, onset,
                      stop_volume=settings["stop_volume"] * 3.141592653589793 * scene.geometry.length)  # V/R0³
        return {"points": len(primary.pressure) + len(bulge.pressure), "onset_pressure": onset.pressure, "maxwell": pm,
                "bulge_points": len(bulge.pressure), "last_volume": float(bulge.volume[-1]),
                "last_pressure": float(bulge.pressure[-1]), "stop": str(bulge.stop.code)}

work()
seconds.clear()
start, used = time.perf_counter(), cpu()
found = work()
wall, total = time.perf_counter() - start, cpu() - used
print(json.dumps({"wall": wall, "total": total, "stages": seconds, **found}))
"""


def measure(kind: str, path: Path, settings: dict) -> dict:
    """One fresh process on ``path`` (``kind``: "sphere" or "tube"), its second run's seconds."""
    out = subprocess.run([sys.executable, "-c", MEASURE, kind, str(path), json.dumps(settings)], capture_output=True,
                         text=True, check=True, cwd=ROOT.parent)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--degree", type=int, default=90, help="the tube's Legendre degree (default %(default)s)")
    parser.add_argument("--length", type=float, default=30.0, help="the tube's length L/R (default %(default)s)")
    parser.add_argument("--stop-stretch", type=float, default=4.6,
                        help="the primary branch's largest hoop stretch (default %(default)s)")
    parser.add_argument("--repeat", type=int, default=1, help="measurements of each scene (default %(default)s)")
    args = parser.parse_args(argv)
    tube = {"overrides": {"geometry.length": args.length, "solver.degree": args.degree,
                          "continuation.stop_stretch": args.stop_stretch}, "stop_volume": STOP_VOLUME}
    rows = []
    for _ in range(args.repeat):
        sphere = measure("sphere", ROOT / "scenes" / "spom1.toml", {"overrides": {}})
        found = measure("tube", ROOT / "scenes" / "tube_spom1_L10.toml", tube)
        rows.append((sphere, found))
    print(f"tube: SPOM1, L = {args.length:g}, degree {args.degree}, sliding closed ends; primary branch to hoop "
          f"stretch {args.stop_stretch:g}, bulge branch to V/V0 = {STOP_VOLUME:g}")
    print("(the second run in a fresh process: wall s, CPU s with workers, per stage CPU s of the process)")
    print(f"  {'run':<5}{'spom1 wall':>12}{'CPU':>8}{'tube wall':>11}{'CPU':>8}{'maxwell':>9}{'primary':>9}"
          f"{'bulge':>8}{'ratio wall':>12}{'ratio CPU':>11}")
    for k, (s, t) in enumerate(rows):
        st = t["stages"]
        print(f"  {k:<5}{s['wall']:12.2f}{s['total']:8.2f}{t['wall']:11.2f}{t['total']:8.2f}"
              f"{st.get('maxwell', 0):9.2f}{st.get('primary', 0):9.2f}{st.get('bulge', 0):8.2f}"
              f"{t['wall'] / s['wall']:11.1f}x{t['total'] / s['total']:10.1f}x")
    s, t = rows[-1]
    ratio = t["wall"] / s["wall"]
    print(f"  tube: {t['points']} points (bulge {t['bulge_points']}), onset P = {t['onset_pressure']:.10f}, "
          f"P_M = {t['maxwell']:.10f}, bulge stopped ({t['stop']}) at V/V0 = {t['last_volume']:.3f}, "
          f"P = {t['last_pressure']:.10f}")
    print(f"  tube / spom1 whole picture: {ratio:.1f}x in wall time (floor <= {FLOOR:g}x: "
          f"{'met' if ratio <= FLOOR else 'NOT met'}), {t['total'] / s['total']:.1f}x in CPU time")
    return 0


if __name__ == "__main__":
    sys.exit(main())
