"""Does a plugged tube's mirror-symmetric branch bifurcate into a non-symmetric one? The lowest eigenvalue of its odd
block along the branch, against the degree.

A closed tube (SPOM1 or ``--preset``) with plugged ends (ρ = 1 there; optionally held at ``--axial-stretch``) is traced in P on its
mirror-symmetric states (tube/primary.primary_branch) at each degree. At every point the odd block of the second
variation is solved against the membrane's mass, H_odd q = ν M_odd q (M: uᵀMu = ∫(δρ² + δη²) dS, dynamics/tube.py's
``tube_mass``), so that ν is a property of the continuous problem (the raw eigenvalues of H depend on the basis's
scaling) and converges in the degree where the state does; a branch point of the odd block (a bifurcation into
non-symmetric states: a bulge shifted towards one plug) is where ν changes sign. Printed per degree: the fold in P,
the odd branch points primary_branch reports, the smallest ν along the branch and where (P, V/V0, its state's tail,
first-integral spread and smallest principal stress: negative is compression, tube/stability.py), and ν at fixed
V/V0 (the branch point nearest each target corrected onto V = target by Newton on (R_even, V − target)): the
convergence table.

    python benchmarks/plugged_odd_block.py [--preset SPOM1] [--length 20] [--axial-stretch 1.5] [--stop-stretch 4] [--degrees 40 60 80 120 160 200]
"""
import argparse
import os
import time

import numpy as np
from scipy import linalg

from balloon_cg.dynamics.tube import tube_mass
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.galerkin.interval import Mirror
from balloon_cg.scene import parse_scene
from balloon_cg.tube.accuracy import first_integral_spread
from balloon_cg.tube.primary import primary_branch, volume_ratio
from balloon_cg.tube.stability import smallest_stress

SCENE = ('[material]\npreset = "{preset}"\n[geometry]\nshape = "tube"\nlength = {length}\nends = "plugged"\n{held}'
         "[solver]\ndegree = {degree}\n[continuation]\nstop_stretch = {stop}\nstep_max = {step}\nmax_points = 5000\n")


def odd_eigenvalue(eq, mass, Y, params) -> float:
    """The lowest ν of H_odd q = ν M_odd q at Y = (u, P)."""
    odd = eq.disc.block(Mirror.ODD)
    H = eq.jacobian(Y[:-1], params.with_value("P", Y[-1]))[np.ix_(odd, odd)]
    return float(linalg.eigh(H, mass[np.ix_(odd, odd)], eigvals_only=True, subset_by_index=[0, 0])[0])


def at_volume(eq, params, Y, target, tol=1e-12, iterations=30):
    """Y = (u, P) on the mirror-symmetric branch with V/V0 = ``target``, by Newton on (R_even(u, P), V/V0 − target)
    from Y (the held λ̄ fixed)."""
    disc = eq.disc
    index = disc.block(Mirror.EVEN)
    if disc.held:
        index = index[index != disc.axial_index]
    Y = Y.copy()
    for _ in range(iterations):
        at = params.with_value("P", Y[-1])
        R = eq.residual(Y[:-1], at)[index]
        dP = eq.parameter_derivative(Y[:-1], at, "P")
        F = np.append(R, volume_ratio(eq, Y) - target)
        if np.abs(F).max() < tol:
            return Y
        J = np.zeros((index.size + 1, index.size + 1))
        J[:-1, :-1] = eq.jacobian(Y[:-1], at)[np.ix_(index, index)]
        J[:-1, -1] = dP[index]
        J[-1, :-1] = -2 * dP[index] / disc.length  # V/V0 = 2 Ṽ/L, ∇Ṽ = −∂R/∂P
        step = np.linalg.solve(J, -F)
        Y[index] += step[:-1]
        Y[-1] += step[-1]
    raise ArithmeticError(f"no state at V/V0 = {target:g}: |F| = {np.abs(F).max():.2e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="SPOM1")
    parser.add_argument("--length", type=float, default=20.0)
    parser.add_argument("--axial-stretch", type=float, default=None)
    parser.add_argument("--stop-stretch", type=float, default=4.0)
    parser.add_argument("--step-max", type=float, default=0.1)
    parser.add_argument("--degrees", type=int, nargs="+", default=[40, 60, 80, 120, 160, 200])
    parser.add_argument("--volumes", type=float, nargs="+", default=[1.5, 2.0, 3.0, 4.0, 6.0, 8.0])
    args = parser.parse_args()
    held = "" if args.axial_stretch is None else f"axial_stretch = {args.axial_stretch}\n"
    print(f"{args.preset} tube, plugged, L = {args.length:g}, {'closed' if not held else f'held at {args.axial_stretch:g}'}, "
          f"to a hoop stretch of {args.stop_stretch:g} (step_max {args.step_max:g}); load {os.getloadavg()}")
    table = {}
    for degree in args.degrees:
        start = time.process_time()
        scene = parse_scene(SCENE.format(preset=args.preset, length=args.length, held=held, degree=degree, stop=args.stop_stretch,
                                         step=args.step_max))
        branch = primary_branch(scene, degree)
        eq = Equilibrium(scene, branch.disc)
        mass = tube_mass(eq)
        Ys = [np.append(u, P) for u, P in zip(branch.states, branch.pressure)]
        nu = np.array([odd_eigenvalue(eq, mass, Y, branch.params) for Y in Ys])
        low = int(np.argmin(nu))
        folds = [f"{s.pressure:.10f}" for s in branch.special if s.kind.value == "LP"]
        odd = [f"P {s.pressure:.6f} V/V0 {volume_ratio(eq, np.append(s.u, s.pressure)):.4f}"
               for s in branch.branch_points(Mirror.ODD)]
        print(f"\ndegree {degree}: {len(Ys)} points, stop: {branch.stop.message}; LP at P = {', '.join(folds)}; "
              f"odd BPs reported: {'; '.join(odd) or 'none'}; sign changes of nu: {int(np.sum(np.diff(np.sign(nu)) != 0))}")
        Y = Ys[low]
        print(f"  smallest nu {nu[low]:.6e} at point {low}: P {Y[-1]:.6f}, V/V0 {branch.volume[low]:.4f}, tail "
              f"{branch.disc.tail(Y[:-1]):.1e}, H spread {first_integral_spread(eq, Y[:-1]):.1e}, smallest stress "
              f"{smallest_stress(eq, Y[:-1]):.3g}")
        row = {}
        for target in args.volumes:
            if not branch.volume.min() <= target <= branch.volume.max():
                continue
            near = int(np.argmin(np.abs(branch.volume - target)))
            Yv = at_volume(eq, branch.params, Ys[near], target)
            row[target] = (Yv[-1], odd_eigenvalue(eq, mass, Yv, branch.params), branch.disc.tail(Yv[:-1]),
                           smallest_stress(eq, Yv[:-1]), first_integral_spread(eq, Yv[:-1]))
        table[degree] = row
        print(f"  CPU {time.process_time() - start:.1f} s")
    print("\nnu_odd (mass-normalised lowest odd eigenvalue) at fixed V/V0: P | nu | tail | smallest stress | H spread")
    for target in args.volumes:
        cells = [f"{degree}: " + ("-" if target not in row else
                                  f"P {row[target][0]:.9f} nu {row[target][1]:+.6e} tail {row[target][2]:.0e} "
                                  f"stress {row[target][3]:.2g} H {row[target][4]:.0e}")
                 for degree, row in table.items()]
        print(f"V/V0 {target:g}:\n    " + "\n    ".join(cells))


if __name__ == "__main__":
    main()
