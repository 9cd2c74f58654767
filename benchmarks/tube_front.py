"""The bulge branch resolved on spectral elements (tube/front.py): its convergence and what it costs (docs/tubes.md).

Part 1: Ogden's 1972 rubber on L = 30 (tests/test_tube_maxwell.py's scene), the bulge from the onset to V/V0 = 52 by
``front_bulge`` (solver.max_error): the refinement's rounds (layout, CPU, largest tail), then the resolved layout
against a much finer one (the same bounds, the order + 4: the same branch retraced there) — P − P_M at fixed
V/V0 (interpolated beyond the volume fold), the fold, P(V) on V/V0 ≥ 50 — and the Legendre series of degree 160
(today's "flag" trace) beside them. Part 2: scenes/tube_spom1_L10.toml, the primary branch and the bulge branch to
the scene's stop, "flag" (the Legendre series at solver.degree) against the resolved trace, CPU of each and their
ratio in this one run, with the load average.

    python benchmarks/tube_front.py [--skip-ogden] [--skip-spom1]
"""
import argparse
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from test_tube import symbolic_energy  # noqa: E402
from test_tube_maxwell import equal_area_pressure, ogden_1972_tube  # noqa: E402

from balloon_cg.analysis.branches.resolution import Resolution  # noqa: E402
from balloon_cg.analysis.results import Kind  # noqa: E402
from balloon_cg.galerkin.equilibrium import Equilibrium  # noqa: E402
from balloon_cg.scene import load_scene  # noqa: E402
from balloon_cg.tube import front  # noqa: E402
from balloon_cg.tube.bulge import bulge_branch  # noqa: E402
from balloon_cg.tube.primary import primary_branch  # noqa: E402

VOLUMES = (3, 10, 20, 30, 40, 50, 52)
STOP_VOLUME = 52.0 * np.pi * 30.0  # V/R0³: V/V0 = 52 on the tube of length 30


def fold_of(scene, branch) -> tuple:
    (fold,) = [s for s in branch.special if s.kind == Kind.LV]
    return fold.pressure, 2 * Equilibrium(scene, branch.disc).volume(fold.u) / branch.disc.length


def at_volumes(branch, maxwell):
    after = int(np.argmin(branch.volume)) + 1
    return np.interp(VOLUMES, branch.volume[after:], branch.pressure[after:]) - maxwell


def ogden() -> None:
    scene = ogden_1972_tube(24)
    maxwell = equal_area_pressure(symbolic_energy(scene.material))[0]
    print(f"Ogden 1972, L = 30, to V/V0 = 52: P_M = {maxwell!r} (equal areas), max_error {scene.solver.max_error:g}")
    primary = primary_branch(scene)
    onset = primary.branch_points()[0]
    rounds = []

    def traced(scene, primary, point, on, **trace):  # bulge_branch, each round's CPU and tail recorded
        start = time.process_time()
        branch = bulge_branch(scene, primary, point, on=on, **trace)
        rounds.append((on, time.process_time() - start, len(branch.volume), float(branch.tail.max())))
        return branch

    front.bulge_branch, plain = traced, front.bulge_branch
    start = time.process_time()
    policy = Resolution(scene.solver.max_error, 400)  # E p up to 400 per field (solver.max_degree's largest)
    resolved = front.front_bulge(scene, primary, onset, policy, stop_volume=STOP_VOLUME, step=0.02)
    total = time.process_time() - start
    front.bulge_branch = plain
    print(f"{'round':>5} {'elements':>8} {'order':>5} {'E p':>5} {'CPU s':>7} {'points':>6} {'largest tail':>12}")
    for k, (disc, cpu, points, tail) in enumerate(rounds):
        print(f"{k:5d} {disc.count:8d} {disc.order:5d} {disc.degree:5d} {cpu:7.1f} {points:6d} {tail:12.2e}")
    print(f"front_bulge: {total:.1f} s CPU; resolved layout's bounds in S: "
          + " ".join(f"{(b + 1) * 15:.3g}" for b in resolved.disc.edges))
    layout = resolved.disc
    finer = replace(layout, degree=layout.count * (layout.order + 4), order=layout.order + 4)
    start = time.process_time()
    fine = bulge_branch(scene, primary, onset, stop_volume=STOP_VOLUME, step=0.02, on=finer)
    fine_cpu = time.process_time() - start
    start = time.process_time()
    legendre_primary = primary_branch(scene, 160)
    legendre = bulge_branch(scene, legendre_primary, legendre_primary.branch_points()[0], stop_volume=STOP_VOLUME,
                            step=0.02)
    legendre_cpu = time.process_time() - start
    print(f"\n{'basis':>28} {'unknowns':>8} {'CPU s':>7} {'largest tail':>12} {'P at LV':>18} {'V/V0 at LV':>16}")
    rows = (("resolved elements", resolved, total), (f"order {finer.order}, same bounds", fine, fine_cpu),
            ("Legendre degree 160 (flag)", legendre, legendre_cpu))
    for name, branch, cpu in rows:
        pressure, volume = fold_of(scene, branch)
        print(f"{name:>28} {branch.disc.size:8d} {cpu:7.1f} {branch.tail.max():12.2e} {pressure:18.13f} {volume:16.12f}")
    print("\nP - P_M at V/V0 = " + ", ".join(map(str, VOLUMES)))
    for name, branch, _ in rows:
        print(f"{name:>28} " + " ".join(f"{v:10.2e}" for v in at_volumes(branch, maxwell)))
    for name, branch, _ in rows:
        plateau = branch.volume >= 50
        gap = np.abs(branch.pressure[plateau] - np.interp(branch.volume[plateau], fine.volume, fine.pressure)).max()
        print(f"{name}: max |P - P_M| on V/V0 >= 50: {np.abs(branch.pressure[plateau] - maxwell).max():.2e}, "
              f"max |P - P_finer(V)|: {gap:.2e}")


def spom1() -> None:
    scene = load_scene(ROOT / "scenes" / "tube_spom1_L10.toml")
    print(f"\nscenes/tube_spom1_L10.toml (degree {scene.solver.degree}, to a hoop stretch of "
          f"{scene.continuation.stop_stretch:g}), max_error {scene.solver.max_error:g}; load average "
          f"{os.getloadavg()[0]:.1f} at the start")
    stop = scene.continuation.stop_stretch
    start = time.process_time()
    primary = primary_branch(scene)
    onset = primary.branch_points()[0]
    flagged = bulge_branch(scene, primary, onset, stop_stretch=stop)
    flag_cpu = time.process_time() - start
    start = time.process_time()
    primary = primary_branch(scene)
    resolved = front.front_bulge(scene, primary, primary.branch_points()[0], stop_stretch=stop)
    resolved_cpu = time.process_time() - start
    print(f"{'trace':>9} {'unknowns':>8} {'points':>6} {'largest tail':>12} {'stop':>14} {'CPU s':>7}")
    for name, branch, cpu in (("flag", flagged, flag_cpu), ("resolved", resolved, resolved_cpu)):
        print(f"{name:>9} {branch.disc.size:8d} {len(branch.volume):6d} {branch.tail.max():12.2e} "
              f"{branch.stop.code:>14} {cpu:7.1f}")
    print(f"resolved / flag CPU: {resolved_cpu / flag_cpu:.1f}x; load average {os.getloadavg()[0]:.1f} at the end")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-ogden", action="store_true")
    parser.add_argument("--skip-spom1", action="store_true")
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f} at the start")
    if not args.skip_ogden:
        ogden()
    if not args.skip_spom1:
        spom1()


if __name__ == "__main__":
    main()
