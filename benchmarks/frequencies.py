"""Benchmark and study: the natural frequencies of a run ([dynamics], docs/dynamics.md).

1. Cost: the run's phases (analysis.timing, stored in the run file) with frequencies on; the factor frequencies add
   to the run's time is total / (total − frequencies phase) (one run; the machine's load is printed with it).
2. Convergence in the perturbation degree: at points spread along the primary branch, the lowest Ω² of every block
   at the stored degree N (the point's stability degree) and at 1.5N and 2N; the table prints the largest change
   per block, |Ω²(N) − Ω²(2N)| and |Ω²(1.5N) − Ω²(2N)|.

Run: python benchmarks/frequencies.py [SCENE] [--points K]   (default: the two-coil scene spom1_two_coils_M0.002)
"""
import argparse
import os

import numpy as np

import balloon_cg as bc
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.dynamics.frequencies import frequencies
from balloon_cg.dynamics.pencil import mass_variation


def cost(result) -> None:
    attrs = result.run["attrs"]
    phases = dict(zip(attrs["phase_names"], attrs["phase_seconds"]))
    total = float(attrs["total_seconds"])
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; one run")
    for name, seconds in phases.items():
        print(f"  {name:<20} {seconds:9.2f} s")
    print(f"  {'total':<20} {total:9.2f} s")
    spent = phases.get("frequencies", 0.0)
    print(f"frequencies add x{total / (total - spent):.3f} to the run's time")


def convergence(result, points: int) -> None:
    primary = next(b for b in result.picture.branches if b.name == "primary")
    scene = primary.scene
    eq = equilibrium_of(primary)
    chosen = np.unique(np.linspace(0, len(primary.X) - 1, points).round().astype(int))
    print(f"\nconvergence in the perturbation degree, primary branch, {len(chosen)} points, m_max = "
          f"{scene.dynamics.m_max}")
    worst = {}
    for n in chosen:
        X = primary.X[n]
        N = int(primary.frequencies.degree[n])
        values = [frequencies(mass_variation(eq, d), X[:-1], primary.params_at(X), primary.disc.symmetric,
                              scene.dynamics.m_max, scene.dynamics.count) for d in (N, int(1.5 * N), 2 * N)]
        for block in values[0]:
            coarse, middle, fine = (v[block] for v in values)
            k = min(coarse.size, middle.size, fine.size)
            change = (np.abs(coarse[:k] - fine[:k]).max(), np.abs(middle[:k] - fine[:k]).max())
            old = worst.get(block, (0.0, 0.0, N, n))
            worst[block] = max(old, (*change, N, n), key=lambda row: row[0])
    print(f"  {'block':<18} {'|Ω²(N) − Ω²(2N)|':>18} {'|Ω²(1.5N) − Ω²(2N)|':>20} {'N':>5} {'at point':>9}")
    for block, (a, b, N, n) in worst.items():
        print(f"  {block:<18} {a:18.3e} {b:20.3e} {N:5d} {n:9d}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default="spom1_two_coils_M0.002")
    parser.add_argument("--points", type=int, default=6)
    args = parser.parse_args(argv)
    scene = bc.Scene.from_toml(args.scene).with_overrides({"dynamics.frequencies": True})
    result = bc.analyse(scene)
    cost(result)
    convergence(result, args.points)


if __name__ == "__main__":
    main()
