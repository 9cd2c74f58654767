"""The Ogden tube's propagation plateau against the degree, and the bulge branch's accuracy measures (docs/tubes.md).

Part 1: Ogden's 1972 rubber on L = 30 (tests/test_tube_maxwell.py's ``traced``: the primary branch, the bulge
switched at its first odd branch point, to V/V0 = 60): Maxwell's pressure by the test's equal-area rule, the volume
fold, P − P_M at fixed V/V0 (interpolated along the branch beyond its fold), the Legendre tail and the first integral's
spread (tube/accuracy.py) at the nearest point, the spurious folds in P on the plateau, the CPU time, and P(V) of each
degree against the finest on V/V0 ≥ 50. Part 2: SPOM1, L = 10, to V/V0 = 20: the tail and H's spread at the located
volume fold and at V/V0 = 4, 10, 20 against the degree.

    python benchmarks/tube_maxwell_plateau.py [--degrees 80 120 160] [--spom1-degrees 30 40 60]
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_tube import symbolic_energy  # noqa: E402
from test_tube_maxwell import equal_area_pressure, ogden_1972_tube, traced  # noqa: E402

VOLUMES = (10, 20, 30, 40, 45, 50, 55, 60)


def ogden_plateau(degrees) -> None:
    maxwell = equal_area_pressure(symbolic_energy(ogden_1972_tube(20).material))[0]
    print(f"Ogden 1972, L = 30: P_M = {maxwell!r} (equal areas)")
    print(f"{'N':>4} {'CPU s':>6} {'points':>6} {'P at LV':>18} {'spurious LPs':>12} {'from V/V0':>9}")
    branches = {}
    for degree in degrees:
        start = time.process_time()
        _, _, branch = traced(degree, 60.0)
        cpu = time.process_time() - start
        (fold,) = [s for s in branch.special if s.kind == "LV"]
        folds = [s.index for s in branch.special if s.kind == "LP"]
        first = f"{branch.volume[min(folds)]:.1f}" if folds else ""
        print(f"{degree:4d} {cpu:6.1f} {len(branch.volume):6d} {fold.pressure:18.13f} {len(folds):12d} {first:>9}")
        branches[degree] = (branch, fold.index + 1)
    for label in ("P - P_M", "tail", "H spread"):
        print(f"\n{label} at V/V0 = " + ", ".join(map(str, VOLUMES)))
        for degree, (branch, after) in branches.items():
            near = [int(np.argmin(abs(branch.volume - v))) for v in VOLUMES]
            values = (np.interp(VOLUMES, branch.volume[after:], branch.pressure[after:]) - maxwell
                      if label == "P - P_M" else branch.tail[near] if label == "tail" else branch.first_integral[near])
            print(f"{degree:4d} " + " ".join(f"{v:10.2e}" for v in values))
    finest, _ = branches[max(degrees)]
    for degree, (branch, _) in branches.items():
        plateau = branch.volume >= 50
        if degree != max(degrees):
            gap = np.abs(branch.pressure[plateau] - np.interp(branch.volume[plateau], finest.volume, finest.pressure))
            print(f"degree {degree}: max |P - P_{max(degrees)}| on V/V0 >= 50: {gap.max():.2e}")
        print(f"degree {degree}: max |P - P_M| on V/V0 >= 50: {np.abs(branch.pressure[plateau] - maxwell).max():.2e}")


def spom1_measures(degrees) -> None:
    from balloon_cg.galerkin.equilibrium import Equilibrium
    from balloon_cg.tube.accuracy import first_integral_spread
    from balloon_cg.tube.bulge import bulge_branch
    from balloon_cg.tube.primary import primary_branch
    from test_tube_resolution import spom1_l10

    print("\nSPOM1, L = 10: tail and H spread at the volume fold and at V/V0 = 4, 10, 20")
    for degree in degrees:
        scene = spom1_l10(degree)
        primary = primary_branch(scene)
        branch = bulge_branch(scene, primary, primary.branch_points()[0], stop_volume=20.0 * np.pi * 10.0, step=0.02)
        (fold,) = [s for s in branch.special if s.kind == "LV"]
        row = [branch.disc.tail(fold.u), first_integral_spread(Equilibrium(scene, branch.disc), fold.u)]
        for v in (4, 10, 20):
            i = int(np.argmin(abs(branch.volume - v)))
            row += [branch.tail[i], branch.first_integral[i]]
        print(f"{degree:4d} " + " ".join(f"{v:9.2e}" for v in row))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--degrees", type=int, nargs="+", default=[80, 120, 160])
    parser.add_argument("--spom1-degrees", type=int, nargs="+", default=[30, 40, 60])
    args = parser.parse_args()
    ogden_plateau(args.degrees)
    spom1_measures(args.spom1_degrees)


if __name__ == "__main__":
    main()
