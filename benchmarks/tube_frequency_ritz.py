"""The m = 0 frequencies of tube_spom1_L10's bulge on its spectral elements (the default "elements" layout, 14
elements of order 16, 449 unknowns): the dense solve (numerics.eigen.lowest, main's reading) against the Ritz values
of its eigenvectors (eigen.lowest_ritz, dynamics/tube's), one run.

1. The fold's volume-block Ω² and its spread under six perturbations of the fold's state by 1e-15 relative (seeded),
   each read both ways, beside ε ν_max (ν_max the pencil's largest eigenvalue: a dense solve's error scale) and the
   linear change vᵀδK v/(2 vᵀMv) of the Ritz vector v (what the state's rounding itself moves).
2. CPU of the whole bulge's frequencies (tube_branch_frequencies, count 6) each way, best of 2 rounds, one BLAS
   thread, with the load average.

    python benchmarks/tube_frequency_ritz.py
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from scipy import linalg  # noqa: E402

import balloon_cg.dynamics.tube as tube  # noqa: E402
from balloon_cg.analysis.results import Kind  # noqa: E402
from balloon_cg.galerkin.equilibrium import Equilibrium  # noqa: E402
from balloon_cg.numerics import eigen  # noqa: E402
from balloon_cg.scene import load_scene  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from shared_pictures import first_bulge_picture  # noqa: E402

READINGS = {"dense (lowest)": eigen.lowest, "Ritz (lowest_ritz)": eigen.lowest_ritz}


def fold_spread(scene, branch):
    fold = next(s for s in branch.special if s.kind == Kind.LV)
    eq = Equilibrium(scene, branch.disc)
    free = branch.disc.free
    factor = eigen.GramFactor(tube.tube_mass(eq)[np.ix_(free, free)])
    params = branch.params.with_value("P", float(fold.pressure))

    def pencil(u):
        H = eq.jacobian(u, params)
        return H, -eq.parameter_derivative(u, params, "P")[free][None, :]

    H, g = pencil(fold.u)
    null = linalg.null_space(g)
    values, vectors = linalg.eigh(null.T @ H[np.ix_(free, free)] @ null, null.T @ factor.gram @ null)
    v = null @ vectors[:, 0]
    print(f"fold P = {fold.pressure!r}, {branch.disc.count} elements, {free.size} unknowns; ν_max = {values[-1]:.3g}, "
          f"ε ν_max / 2 = {eigen.EPS * values[-1] / 2:.2g} (Ω²)")
    rng = np.random.default_rng(0)
    states = [fold.u] + [fold.u * (1 + 1e-15 * rng.standard_normal(fold.u.size)) for _ in range(6)]
    print(f"{'state':>10} " + " ".join(f"{name:>20}" for name in READINGS) + f" {'vᵀδKv/(2vᵀMv)':>15}")
    for n, u in enumerate(states):
        Hu, gu = pencil(u)
        readings = [read(Hu, factor, 1, gu, free)[0] / 2 for read in READINGS.values()]
        dK = (Hu - H)[np.ix_(free, free)]
        linear = (v @ dK @ v) / (v @ factor.gram @ v) / 2
        print(f"{'fold' if n == 0 else f'perturbed {n}':>10} " + " ".join(f"{r:20.3e}" for r in readings)
              + f" {linear:15.2e}")


def branch_cost(scene, branch):
    print(f"\nCPU s of tube_branch_frequencies (bulge, {len(branch.pressure)} points, count 6), best of 2, "
          f"load average {os.getloadavg()[0]:.1f}")
    times = {}
    for name, read in READINGS.items():
        tube.eigen = _Reading(read)
        rounds = []
        for _ in range(2):
            t0 = time.process_time()
            tube.tube_branch_frequencies(scene, branch, 6)
            rounds.append(time.process_time() - t0)
        times[name] = min(rounds)
    tube.eigen = eigen
    dense, ritz = times.values()
    print(f"{'dense':>8} {'Ritz':>8} {'Ritz/dense':>11}\n{dense:8.2f} {ritz:8.2f} {ritz / dense:11.2f}  "
          f"(load average after: {os.getloadavg()[0]:.1f})")


class _Reading:
    """numerics.eigen with ``lowest_ritz`` read as ``read`` (dynamics/tube's one call)."""

    def __init__(self, read):
        self.lowest_ritz, self.GramFactor, self.NO_CONSTRAINT = read, eigen.GramFactor, eigen.NO_CONSTRAINT


def main():
    scene = load_scene("tube_spom1_L10").with_overrides({"stability.m_max": 0})
    branch = first_bulge_picture(scene).branches["bulge"]
    print(f"tube_spom1_L10's bulge, load average {os.getloadavg()[0]:.1f} on the 2 cores")
    fold_spread(scene, branch)
    branch_cost(scene, branch)


if __name__ == "__main__":
    main()
