"""Benchmark: the stability flags at a check degree from the banded sibling's inertia (numerics/banded.BandedSigns)
against the dense Legendre blocks' Cholesky factorisations (issue 37, "signs by inertia where only a sign is
needed").

Points: the paper coil's pear_free_2 (a general state near the wire; the whole picture analysed once, surface branches
off, to reach it), every fifth point assessed at degree 320. Per degree N of the check (the check degrees of the
points assessed at 135, 150 and 225: 270, 300, 320), in one process, interleaved point by point: the CPU seconds per
point of ``SecondVariation.flags`` (m = 0 and m = 1, held and free: what ``assess_branch``'s flag check reads) on the
dense blocks (stability.banded_from and banded_flags_from = 0) and on the banded ones (the defaults), their ratio, and the number of
points whose six flags differ (banded against dense, and banded against the signs of the banded eigenvalues).

    BALLOON_CG_WORKERS=1 python benchmarks/banded_flags.py > benchmarks/results/banded_flags.txt
"""
import os
import time
from dataclasses import replace
from pathlib import Path

from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.stability.axisymmetric import SecondVariation
from balloon_cg.numerics.threads import blas_threads
from balloon_cg.scene import load_scene

SCENE = Path(__file__).resolve().parents[1] / "scenes" / "spom1_paper_coil.toml"
DEGREES = (270, 300, 320)
EVERY = 5


def main() -> None:
    scene = load_scene(SCENE).with_overrides({"surface.branches": "none"}, name="spom1_paper_coil")
    branch = next(b for b in analyse(scene).branches if b.name == "pear_free_2")
    dense_scene = scene.with_overrides({"stability.banded_from": 0, "stability.banded_flags_from": 0}, name=scene.name)
    points = [n for n, a in enumerate(branch.stability) if a.degree == 320][::EVERY]
    print(f"# {SCENE.name}, pear_free_2: {len(points)} of its {len(branch.X)} points (every {EVERY}th assessed at 320); "
          f"load average {os.getloadavg()[0]:.1f} at the start")
    print(f"{'degree':>8}{'dense s/pt':>12}{'banded s/pt':>13}{'banded/dense':>14}{'differ (dense)':>16}"
          f"{'differ (eigen)':>16}")
    with blas_threads():
        for degree in DEGREES:
            banded = SecondVariation(equilibrium_of(branch), degree)
            dense = SecondVariation(equilibrium_of(replace(branch, scene=dense_scene)), degree)
            X = branch.X[points[0]]
            for variation in (dense, banded):  # the bases, plans and factors built once, before the clock
                variation.flags(X[:-1], branch.params_at(X), False, 1)
            seconds = {"dense": 0.0, "banded": 0.0}
            differ_dense = differ_eigen = 0
            for n in points:
                X = branch.X[n]
                u, params = X[:-1], branch.params_at(X)
                found = {}
                for name, variation in (("dense", dense), ("banded", banded)):
                    start = time.process_time()
                    found[name] = variation.flags(u, params, False, 1)
                    seconds[name] += time.process_time() - start
                differ_dense += found["banded"] != found["dense"]
                differ_eigen += found["banded"] != tuple(banded.assess(u, params, False, 1).flags().values())
            d, b = seconds["dense"] / len(points), seconds["banded"] / len(points)
            print(f"{degree:>8}{d:>12.4f}{b:>13.4f}{b / d:>14.3f}{differ_dense:>16}{differ_eigen:>16}", flush=True)
    print(f"# load average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    main()
