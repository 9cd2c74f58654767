"""Does a plugged tube's mirror-symmetric branch bifurcate into a non-symmetric one? The lowest eigenvalue of its odd
block along the branch, against the degree.

A closed tube (SPOM1 or ``--preset``) with plugged ends (ρ = 1 there; held apart with ``--axial-stretch``) is traced
in P on its mirror-symmetric states (tube/primary.primary_branch) at each degree. At every point the odd block of the
second variation is solved against the membrane's mass, H_odd q = ν M_odd q (M: uᵀMu = ∫(δρ² + δη²) dS,
dynamics/tube.py's ``tube_mass``), so that ν is a property of the continuous problem (the raw eigenvalues of H depend
on the basis's scaling) and converges in the degree where the state does; a branch point of the odd block (a
bifurcation into non-symmetric states: a bulge shifted towards one plug) is where ν changes sign. Printed per degree:
the fold in P, the odd branch points primary_branch reports, the smallest ν along the branch and where (P, V/V0, its
state's tail, first-integral spread and smallest principal stress: negative is compression, tube/stability.py), and
ν where the middle's hoop stretch ρ(L/2) (the bulge's amplitude, past the fold) takes given values (the point of the
branch before each corrected onto it by Newton on (R_even, ρ(L/2) − target)): the convergence table, and across
lengths the bulge's distance from the plugs.

    python benchmarks/plugged_odd_block.py [--preset SPOM1] [--length 20] [--axial-stretch 1.5] [--stop-stretch 6]
        [--degrees 40 60 80 120 160 200] [--middle 2 3 4 5 6]
"""
import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from balloon_cg.dynamics.tube import tube_mass
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.galerkin.interval import Mirror
from balloon_cg.scene import parse_scene
from balloon_cg.tube.accuracy import first_integral_spread
from balloon_cg.tube.primary import primary_branch, volume_ratio
from balloon_cg.tube.stability import smallest_stress

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_plugged_bifurcation import SCENE, odd_eigenvalue, past_the_fold  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="SPOM1")
    parser.add_argument("--length", type=float, default=20.0)
    parser.add_argument("--axial-stretch", type=float, default=None)
    parser.add_argument("--stop-stretch", type=float, default=6.0)
    parser.add_argument("--step-max", type=float, default=0.1)
    parser.add_argument("--degrees", type=int, nargs="+", default=[40, 60, 80, 120, 160, 200])
    parser.add_argument("--middle", type=float, nargs="+", default=[2.0, 3.0, 4.0, 5.0, 6.0])
    args = parser.parse_args()
    held = "" if args.axial_stretch is None else f"axial_stretch = {args.axial_stretch}\n"
    ends = "closed" if not held else f"held at {args.axial_stretch:g}"
    print(f"{args.preset} tube, plugged, L = {args.length:g}, {ends}, to a hoop stretch of {args.stop_stretch:g} "
          f"(step_max {args.step_max:g}); load {os.getloadavg()}")
    table = {}
    for degree in args.degrees:
        start = time.process_time()
        scene = parse_scene(SCENE.format(preset=args.preset, length=args.length, held=held, degree=degree,
                                         stop=args.stop_stretch, step=args.step_max))
        branch = primary_branch(scene, degree)
        eq = Equilibrium(scene, branch.disc)
        mass = tube_mass(eq)
        Ys = [np.append(u, P) for u, P in zip(branch.states, branch.pressure)]
        nu = np.array([odd_eigenvalue(eq, mass, Y, branch.params) for Y in Ys])
        low = int(np.argmin(nu))
        folds = [f"{s.pressure:.10f}" for s in branch.special if s.kind.value == "LP"]
        odd = [f"P {s.pressure:.6f} V/V0 {volume_ratio(eq, np.append(s.u, s.pressure)):.4f} (stress "
               f"{s.smallest_stress:.2g}, tail {branch.disc.tail(s.u):.0e}, H {first_integral_spread(eq, s.u):.0e})"
               for s in branch.branch_points(Mirror.ODD)]
        print(f"\ndegree {degree}: {len(Ys)} points, stop: {branch.stop.message}; LP at P = {', '.join(folds)}; "
              f"odd BPs reported: {'; '.join(odd) or 'none'}; sign changes of nu: "
              f"{int(np.sum(np.diff(np.sign(nu)) != 0))}")
        Y = Ys[low]
        print(f"  smallest nu {nu[low]:.6e} at point {low}: P {Y[-1]:.6f}, V/V0 {branch.volume[low]:.4f}, tail "
              f"{branch.disc.tail(Y[:-1]):.1e}, H spread {first_integral_spread(eq, Y[:-1]):.1e}, smallest stress "
              f"{smallest_stress(eq, Y[:-1]):.3g}")
        row = {}
        for target in args.middle:
            Yv = past_the_fold(eq, branch, target)
            if Yv is None:
                continue
            row[target] = (Yv[-1], volume_ratio(eq, Yv), odd_eigenvalue(eq, mass, Yv, branch.params),
                           branch.disc.tail(Yv[:-1]), smallest_stress(eq, Yv[:-1]), first_integral_spread(eq, Yv[:-1]))
        table[degree] = row
        for target, values in row.items():
            print(f"  rho(L/2) = {target:g}: " + "P {:.10f}  V/V0 {:.6f}  nu {:+.6e}  tail {:.0e}  stress {:.3g}  "
                  "H {:.0e}".format(*values))
        print(f"  CPU {time.process_time() - start:.1f} s")
    print("\nnu_odd (the lowest odd eigenvalue against the mass) past the fold where the middle's hoop stretch is "
          "rho(L/2): P | V/V0 | nu | tail | smallest stress | H spread")
    for target in args.middle:
        cells = [f"{degree:4d}: " + ("-" if target not in row else
                                     "P {:.10f}  V/V0 {:.6f}  nu {:+.6e}  tail {:.0e}  stress {:.3g}  H {:.0e}".format(
                                         *row[target])) for degree, row in table.items()]
        print(f"rho(L/2) = {target:g}:\n    " + "\n    ".join(cells))


if __name__ == "__main__":
    main()
