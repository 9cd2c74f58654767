"""Benchmark: where the banded sibling of the stability blocks (analysis/stability/banded.py) starts to win over the
dense Legendre blocks, per perturbation degree N: the assessment (every block's lowest eigenvalues, m = 0 and m = 1,
held and free: ``SecondVariation.assess``) and the flags alone (``SecondVariation.flags``: the inertia, what a point's
check at its check degree reads), each dense (stability.banded_from = banded_flags_from = 0) and banded (both 20) at
the same points and degrees (issue 37: the defaults of those two keys).

Points: the paper coil's branches (the whole picture analysed once, surface branches off, to reach them): pear_free_2
and pear_0 (general states on their wire maps, held and free readings) and the primary branch (equator-symmetric),
POINTS of each spread along it. Per branch and degree, in one process, dense and banded interleaved point by point,
the bases and plans built before the clock: CPU seconds per point, the ratio banded/dense, and the number of points
whose six flags differ between the two.

    BALLOON_CG_WORKERS=1 python benchmarks/banded_crossover.py > benchmarks/results/banded_crossover.txt
"""
import os
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.stability.axisymmetric import SecondVariation
from balloon_cg.numerics.threads import blas_threads
from balloon_cg.scene import load_scene

SCENE = Path(__file__).resolve().parents[1] / "scenes" / "spom1_paper_coil.toml"
DEGREES = {"pear_free_2": (45, 67, 100, 135, 150, 180, 213, 225), "pear_0": (45, 67, 100, 135, 150, 180),
           "primary": (30, 45, 67, 90, 135)}
POINTS = 5


def _timed(call) -> tuple:
    start = time.process_time()
    value = call()
    return time.process_time() - start, value


def main() -> None:
    scene = load_scene(SCENE).with_overrides({"surface.branches": "none"}, name="spom1_paper_coil")
    picture = analyse(scene)
    print(f"# {SCENE.name}: CPU s per point (m_max = 1, every block; POINTS = {POINTS} per branch); load average "
          f"{os.getloadavg()[0]:.1f} at the start")
    print(f"{'branch':<14}{'degree':>7}{'assess dense':>14}{'banded':>9}{'ratio':>8}{'flags dense':>13}{'banded':>9}"
          f"{'ratio':>8}{'flags differ':>14}")
    with blas_threads():
        for name, degrees in DEGREES.items():
            branch = next(b for b in picture.branches if b.name == name)
            symmetric = branch.disc.symmetric
            points = np.linspace(0, len(branch.X) - 1, POINTS).round().astype(int)
            variants = {key: replace(branch, scene=scene.with_overrides(
                {"stability.banded_from": start, "stability.banded_flags_from": start}, name=scene.name))
                for key, start in (("dense", 0), ("banded", 20))}
            for degree in degrees:
                variations = {key: SecondVariation(equilibrium_of(b), degree) for key, b in variants.items()}
                X = branch.X[points[0]]
                for variation in variations.values():  # bases, plans and factors built before the clock
                    variation.assess(X[:-1], branch.params_at(X), symmetric, 1)
                    variation.flags(X[:-1], branch.params_at(X), symmetric, 1)
                seconds = {(key, what): 0.0 for key in variations for what in ("assess", "flags")}
                differ = 0
                for n in points:
                    X = branch.X[n]
                    u, params = X[:-1], branch.params_at(X)
                    flags = {}
                    for key, variation in variations.items():
                        spent, _ = _timed(lambda: variation.assess(u, params, symmetric, 1))
                        seconds[key, "assess"] += spent
                        spent, flags[key] = _timed(lambda: variation.flags(u, params, symmetric, 1))
                        seconds[key, "flags"] += spent
                    differ += flags["dense"] != flags["banded"]
                per = {k: v / len(points) for k, v in seconds.items()}
                print(f"{name:<14}{degree:>7}{per['dense', 'assess']:>14.4f}{per['banded', 'assess']:>9.4f}"
                      f"{per['banded', 'assess'] / per['dense', 'assess']:>8.2f}{per['dense', 'flags']:>13.4f}"
                      f"{per['banded', 'flags']:>9.4f}{per['banded', 'flags'] / per['dense', 'flags']:>8.2f}"
                      f"{differ:>14}", flush=True)
    print(f"# load average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    main()
