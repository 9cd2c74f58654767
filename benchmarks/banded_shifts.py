"""Benchmark: the banded blocks' shifts (numerics/banded.py; issue 37), main's against this one's, in one run.

main: one Cholesky-proved shift below the spectrum (tried 4× farther down per failure) and one Lanczos run for the
three lowest, stopping tests every 8 steps. Now: the proved shift bisected towards μ₁ (``TIGHTEN``), μ₁ read on it,
μ₂ and μ₃ on an inside shift between μ₁ and μ₂ proved by a banded LDLᵀ's inertia (``InsideShift``), stopping tests
every 4 steps. Points: the paper coil's pear_free_2 at its points 35 and 36 (μ₁ ≈ −9) and 104 and 173 (μ₁ ≈ −100,
the case the inside shift is for), on 40 elements of order 12 (the rule at Legendre degree 320). Per block: the
Lanczos products (operator applications, both runs), the CPU ms (median of three after a warm call; the first
block of an index set carries its factorisation) and the largest |Δμ| between the two.

    BALLOON_CG_WORKERS=1 python benchmarks/banded_shifts.py > benchmarks/results/banded_shifts.txt
"""
import time
from pathlib import Path

import numpy as np

import balloon_cg.numerics.banded as banded
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.stability.banded import BandedVariation
from balloon_cg.analysis.stability.banded_azimuthal import BandedAzimuthal
from balloon_cg.numerics.threads import blas_threads
from balloon_cg.scene import load_scene

SCENES = Path(__file__).resolve().parents[1] / "scenes"
POINTS = (35, 36, 104, 173)
REPEATS = 3
products = [0]
_largest = banded.largest_by_lanczos


def _counted(operator, n, count, check_every=1, also=0):
    def counting(v):
        products[0] += 1
        return operator(v)
    return _largest(counting, n, count, check_every, also)


def _main_lowest(self, count, constraints=None, update=None, rcond=banded.RCOND):
    return self._below(count, constraints, update, rcond)


# (label, BandedShiftInvert.lowest, TIGHTEN, CHECK_EVERY)
SETTINGS = (("main", _main_lowest, 0, 8),
            ("now", banded.BandedShiftInvert.lowest, banded.TIGHTEN, banded.CHECK_EVERY))


def blocks(u, params, variation, azimuthal) -> dict:
    """{block: (products, CPU s, the three lowest)} of every m = 0 block and m = 1 held and free."""
    rows = {}
    start, count = time.process_time(), products[0]
    readings = [(name, values) for name, values, _ in variation.lowest(u, params)]
    readings += [(f"m1_{'held' if held else 'free'}", None) for held in (True, False)]
    for name, values in readings:
        if values is None:
            held = name == "m1_held"
            values = azimuthal.lowest_readings(u, params, 3, (held,))[held]
        now = time.process_time()
        rows[name] = (products[0] - count, now - start, values)
        start, count = now, products[0]
    return rows


def study(branch, n: int):
    eq, X = equilibrium_of(branch), branch.X[n]
    u, params = X[:-1], branch.params_at(X)
    variation = BandedVariation(eq, 40, 12)
    azimuthal = BandedAzimuthal(variation, 1)
    found = {}
    for label, lowest, tighten, check in SETTINGS:
        banded.BandedShiftInvert.lowest, banded.TIGHTEN, banded.CHECK_EVERY = lowest, tighten, check
        blocks(u, params, variation, azimuthal)
        runs = [blocks(u, params, variation, azimuthal) for _ in range(REPEATS)]
        found[label] = {k: (runs[0][k][0], float(np.median([r[k][1] for r in runs])), runs[0][k][2])
                        for k in runs[0]}
    print(f"\npaper coil, pear_free_2, point {n}: P = {X[-1]:.8f}, 40x12 elements")
    print(f"  {'block':<16} {'products main':>13} {'now':>5} {'ms main':>8} {'now':>6} {'max |Δμ|':>10}   lowest (now)")
    total = np.zeros(4)
    for name, (steps, seconds, values) in found["main"].items():
        new_steps, new_seconds, new_values = found["now"][name]
        total += (steps, new_steps, seconds, new_seconds)
        print(f"  {name:<16} {steps:>13} {new_steps:>5} {seconds * 1e3:>8.2f} {new_seconds * 1e3:>6.2f} "
              f"{np.abs(values - new_values).max():>10.2e}   {np.array2string(new_values, precision=6)}")
    print(f"  {'all':<16} {int(total[0]):>13} {int(total[1]):>5} {total[2] * 1e3:>8.1f} {total[3] * 1e3:>6.1f}"
          f"   CPU now/main {total[3] / total[2]:.2f}")


def main():
    banded.largest_by_lanczos = _counted
    with blas_threads():
        scene = load_scene(SCENES / "spom1_paper_coil.toml")
        picture = analyse(scene.with_overrides({"surface.branches": "none"}, name=scene.name))
        pear = next(b for b in picture.branches if b.name == "pear_free_2")
        for n in POINTS:
            study(pear, n)


if __name__ == "__main__":
    main()
