"""Benchmark: the second variation on the banded basis (C⁰ elements on the wire map: analysis/stability/banded.py for
m = 0, banded_azimuthal.py for m = 1) against the dense Legendre blocks (issue 37, "a local basis where the wires
demand resolution").

Points: the paper coil's pear_free_2 (a general state, its points at mapped degree 320; the whole picture is analysed
once, surface branches off, to reach it) at its first, middle and last point assessed at 320, and the two-coil
(M = 0.002) primary branch (equator-symmetric blocks on the half interval) at its last point (gap 0.1) and at the
point a third of the way there. Per point: the Legendre blocks (m = 0 and m = 1, as ``SecondVariation.assess`` with
m_max = 1 reads them) at the point's degree N (``point_degrees``) and their
own error estimate |μ(N) − μ(⌊N/1.5⌋)| (as tests/data/reference's error tables), then per element ladder (E elements
of order p) the largest |Δμ| over every block's three lowest eigenvalues against Legendre-N, the largest
|Δμ| / (estimate + 1e-10 max(1, |μ|)) (≤ 1: within the Legendre blocks' own error; at degree 320 the dense
eigensolve itself is ~1e-8 off, ε‖A‖: docs/numerics.md §6), and the CPU time of one assessment of every block (the
bases built beforehand, the median of three), old against new in one run.

    BALLOON_CG_WORKERS=1 python benchmarks/banded_stability.py > benchmarks/results/banded_stability.txt
"""
import time
from pathlib import Path

import numpy as np

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.stability.axisymmetric import SecondVariation, point_degrees
from balloon_cg.analysis.stability.banded import BandedVariation
from balloon_cg.analysis.stability.banded_azimuthal import BandedAzimuthal
from balloon_cg.numerics.threads import blas_threads
from balloon_cg.scene import load_scene

SCENES = Path(__file__).resolve().parents[1] / "scenes"
LADDER = ((10, 8), (20, 8), (40, 8), (10, 12), (20, 12), (30, 12), (40, 12))
REPEATS = 3


def timed(assess) -> tuple:
    """(the median CPU seconds of REPEATS calls, the last result) of ``assess()``, after one warm call."""
    assess()
    seconds = []
    for _ in range(REPEATS):
        start = time.process_time()
        result = assess()
        seconds.append(time.process_time() - start)
    return float(np.median(seconds)), result


def study(branch, n: int, label: str):
    eq, X = equilibrium_of(branch), branch.X[n]
    u, params, symmetric = X[:-1], branch.params_at(X), branch.disc.symmetric
    degree = int(point_degrees(branch, branch.scene.stability.degree)[n])
    variation = SecondVariation(eq, degree)
    seconds, legendre = timed(lambda: variation.assess(u, params, symmetric, 1).blocks)
    coarse = SecondVariation(eq, int(degree / 1.5)).assess(u, params, symmetric, 1).blocks
    print(f"\n{label}, point {n} of {len(branch.X)}: P = {X[-1]:.8f}, Legendre degree {degree} on the map "
          f"({'equator-symmetric' if symmetric else 'general'}); Legendre blocks {seconds * 1e3:.1f} ms CPU")
    for name, values in legendre.items():
        print(f"  {name:<17}" + "".join(f"{v:>22.12g}" for v in values)
              + "   estimate " + " ".join(f"{e:.1e}" for e in np.abs(values - coarse[name])))
    print(f"  {'elements':>10} {'functions':>10} {'max |Δμ|':>10} {'max Δ/est':>10} {'worst block':>18} "
          f"{'ms CPU':>8} {'Legendre/banded':>16}")
    for elements, order in LADDER:
        banded = BandedVariation(eq, elements, order)
        azimuthal = BandedAzimuthal(banded, 1)
        readings = (True, False) if "m1_free" in legendre else (True,)

        def assess():
            found = azimuthal.lowest_readings(u, params, 3, readings)
            return banded.lowest_blocks(u, params) | {f"m1_{'held' if held else 'free'}": values
                                                      for held, values in found.items()}

        spent, found = timed(assess)
        worst, ratio, where = 0.0, 0.0, ""
        for name, values in legendre.items():
            delta = np.abs(found[name] - values)
            scaled = delta / (np.abs(values - coarse[name]) + 1e-10 * np.maximum(1.0, np.abs(values)))
            if scaled.max() > ratio:
                ratio, where = float(scaled.max()), name
            worst = max(worst, float(delta.max()))
        print(f"  {f'{elements}x{order}':>10} {banded.basis.functions:>10} {worst:>10.2e} {ratio:>10.2f} "
              f"{where:>18} {spent * 1e3:>8.1f} {seconds / spent:>16.2f}")


def main():
    with blas_threads():
        scene = load_scene(SCENES / "spom1_two_coils_M0.002.toml")
        primary = trace_primary(scene, down=False)
        last = len(primary.X) - 1
        for n in (last // 3, last):
            study(primary, n, "two coils, primary")
        scene = load_scene(SCENES / "spom1_paper_coil.toml")
        picture = analyse(scene.with_overrides({"surface.branches": "none"}, name=scene.name))
        pear = next(b for b in picture.branches if b.name == "pear_free_2")
        degrees = point_degrees(pear, scene.stability.degree)
        top = np.flatnonzero(degrees == degrees.max())
        for n in (top[0], top[len(top) // 2], top[-1]):
            study(pear, int(n), "paper coil, pear_free_2")


if __name__ == "__main__":
    main()
