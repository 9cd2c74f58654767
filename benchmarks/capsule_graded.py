"""A long capsule's bulge at the default max_error: one degree shared by the cylinder's elements against a degree per
element (``geometry.element_degrees = "graded"``, analysis/branches/graded.py), one run each in this process.

SPOM1 capsule of length L, its cylinder cut into elements of at most ``--element`` radii, its primary branch traced
in P (``trace_primary``: the trace and its folds, not the stability assessment) with step_max 1 to pole stretch 3 at
the default [solver] (degree 40, max_error 1e-9, max_degree 320). Per basis: points, wall and CPU seconds, the
stop, the highest
V/V0, the fold's P against the long tube's pressure maximum P* and a sliding tube's onset at L (model/tube), the
largest stored error estimate, and max |P − P_M| (model/tube.maxwell_pressure) over windows of V/V0; the load
average before and after.

    python benchmarks/capsule_graded.py [--length 40] [--element 10] [--bases shared graded]
"""
import argparse
import os
import time

import numpy as np

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.model import tube
from balloon_cg.scene import parse_scene

WINDOWS = ((2, 10), (10, 50), (50, 100), (100, 200), (200, 300), (300, 400), (400, 500), (500, 600), (600, 700),
           (700, 900))


def scene_text(length: float, element: float, basis: str) -> str:
    graded = 'element_degrees = "graded"\n' if basis == "graded" else ""
    return ('[material]\npreset = "SPOM1"\n[geometry]\nshape = "capsule"\n'
            f"length = {length!r}\nelement_length = {element!r}\n{graded}[stability]\nm_max = 0\n"
            "[continuation]\nstop_stretch = 3.0\nstep_max = 1.0\nmax_points = 3000\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=40.0)
    parser.add_argument("--element", type=float, default=10.0)
    parser.add_argument("--bases", nargs="+", default=["shared", "graded"])
    args = parser.parse_args()
    print(f"SPOM1 capsule, length {args.length:g}, element_length {args.element:g}, default [solver]; "
          f"load average before {os.getloadavg()}")
    rows, windows = [], {}
    for basis in args.bases:
        scene = parse_scene(scene_text(args.length, args.element, basis))
        wall, cpu = time.perf_counter(), time.process_time()
        branch = trace_primary(scene)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        eq = Equilibrium(scene, branch.disc)
        volume = np.array([2 * np.pi * eq.volume(x[:-1]) for x in branch.X]) / (args.length * np.pi + 4 * np.pi / 3)
        maxwell = tube.maxwell_pressure(scene.material)[0]
        folds = [p.X[-1] for p in branch.special if p.kind.value == "LP"]
        up = branch.stop_reason
        rows.append((basis, len(branch.X), wall, cpu, f"N {branch.disc.degree} {branch.disc.element_degrees or ''}",
                     volume.max(), folds[0] if folds else np.nan, float(branch.error_estimate.max()), up))
        windows[basis] = [np.abs(branch.X[(volume >= lo) & (volume < hi), -1] - maxwell).max()
                          if ((volume >= lo) & (volume < hi)).any() else np.nan for lo, hi in WINDOWS]
    material = parse_scene(scene_text(args.length, args.element, "shared")).material
    peak, onset = tube.pressure_maximum(material).pressure, tube.bulge_onset(material, args.length).pressure
    print(f"P* = {peak:.13f}, sliding tube's onset at L = {args.length:g}: {onset:.13f}, "
          f"P_M = {tube.maxwell_pressure(material)[0]:.12f}")
    print("| basis | points | wall s | CPU s | storage basis | max V/V0 | fold P | fold − P* | fold − onset | "
          "max stored error | stop |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for basis, points, wall, cpu, storage, top, fold, error, up in rows:
        print(f"| {basis} | {points} | {wall:.0f} | {cpu:.0f} | {storage} | {top:.1f} | {fold:.13f} | "
              f"{fold - peak:.3e} | {fold - onset:.3e} | {error:.1e} | {up} |")
    print("max |P − P_M| over V/V0 windows:")
    print("| basis | " + " | ".join(f"{lo}–{hi}" for lo, hi in WINDOWS) + " |")
    print("|---|" + "---|" * len(WINDOWS))
    for basis, values in windows.items():
        print(f"| {basis} | " + " | ".join("—" if np.isnan(v) else f"{v:.1e}" for v in values) + " |")
    if len(rows) == 2:
        print(f"graded/shared: points {rows[1][1] / rows[0][1]:.2f}, wall {rows[1][2] / rows[0][2]:.2f}, "
              f"CPU {rows[1][3] / rows[0][3]:.2f}")
    print(f"load average after {os.getloadavg()}")


if __name__ == "__main__":
    main()
