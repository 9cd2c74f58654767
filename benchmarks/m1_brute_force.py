"""The m = 1 claim (docs/paper.md): is the held m = 1 eigenvalue negative on the traced pear points in a field?

For the pear branches of SPOM1 with one coil of radius 2 (M = 0.001), the inferred paper coil (a = 1.961,
M = 0.001) and the paper's two coils (M = 0.001, 0.002, 0.003), computed with the whole analysis (the runs are
kept in paper-figures/runs and shared with `make paper`), prints per branch how many stored points have a negative
held m = 1 eigenvalue (the run file's lowest_m1_held, at each point's stability degree), and at a few points the
lowest held value from the generated second variation (analysis.stability.azimuthal) and from the brute-force second method
(analysis.stability.brute_force: the directly integrated 3D energy differenced numerically) at the same perturbation degrees
N, with the share of the brute-force mode that is the rigid tilt e_y × x0.
Run: python benchmarks/m1_brute_force.py [RUNS_FOLDER]  (output kept in benchmarks/results/m1_brute_force.txt)
"""
import sys
import time
from pathlib import Path

import numpy as np

from balloon_cg.analysis.stability import azimuthal as az, brute_force as bf
from balloon_cg.app.figures import run_for
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.post.paper import SINGLE_COIL_M0001, SINGLE_COIL_REACH, Case
from balloon_cg.io.run_file import stored_scene
from balloon_cg.post.quantities import branch_discretisation

CASES = {
    "one coil a = 2, M = 0.001": Case("spom1_single_coil", (("field.M", 0.001), ("field.coils[0].radius", 2.0),
                                                            ("continuation.wire_gap", 0.05)) + SINGLE_COIL_REACH),
    "one coil a = 1.961, M = 0.001": SINGLE_COIL_M0001,
    **{f"two coils, M = {M}": Case(f"spom1_two_coils_M{M}") for M in ("0.001", "0.002", "0.003")},
}
DEGREES = (12, 24)
POINTS = 5  # evenly spaced along each pear branch


def rows(label: str, run: dict):
    scene = stored_scene(run)
    for name, branch in run["branches"].items():
        if not name.startswith("pear") or name.endswith("_mirror"):
            continue
        stored = branch["stability"]["lowest_m1_held"][:, 0]
        print(f"\n{label}: {name}, {len(stored)} points, {int((stored < 0).sum())} with a negative stored held m = 1 "
              f"eigenvalue (min {stored.min():.4g}, max {stored.max():.4g}); equilibrium degree "
              f"{branch['attrs']['degree']}")
        print(f"{'i':>4} {'P':>8} {'λ2(0)':>7} {'stored':>10}" + "".join(
            f" {'gen N=' + str(N):>11} {'brute N=' + str(N):>11} {'tilt':>5}" for N in DEGREES) + f" {'s':>5}")
        disc = branch_discretisation(branch)
        eq = Equilibrium(scene, disc)
        for i in np.unique(np.linspace(0, len(stored) - 1, POINTS).round().astype(int)):
            start = time.perf_counter()
            u, P = branch["unknowns"][i][:disc.size], branch["pressure"][i]
            params = Parameters(P, branch["attrs"]["M"], branch["attrs"]["chi"])
            line = f"{i:>4} {P:>8.5f} {branch['lam2_top'][i]:>7.4f} {stored[i]:>10.5g}"
            for N in DEGREES:
                generated = az.spectrum(eq, u, params, 1, N, 1, held=True)[0]
                block = bf.m1_block(disc, scene, u, params, N, bf.Grid(2 * (N + disc.degree) + 20, 12))
                values, vectors = block.lowest(1, held=True, vectors=True)
                line += f" {generated:>11.6g} {values[0]:>11.6g} {block.rotation_share(vectors[:, 0]):>5.2f}"
            print(line + f" {time.perf_counter() - start:>5.1f}", flush=True)


def main(runs: Path):
    print("held m = 1: lowest eigenvalue of the m = 1 block, relabelling mode removed, translation constrained; "
          "'gen': analysis.stability.azimuthal, 'brute': analysis.stability.brute_force, same N; 'tilt': |<mode, e_y × x0>| / norms")
    for label, case in CASES.items():
        rows(label, run_for(case, runs, progress=False))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("paper-figures/runs"))
