"""The readings of one symmetry sector through one shifted factorisation (numerics.eigen.ShiftInvert): each
relative's Lanczos run alone (one single-vector solve with the factor per step, ``lowest``) against all of them in
lockstep (one solve of several columns per step, ``lowest_of_relatives``), with the same numbers (checked bit for
bit). The sector: the size of the two-coil m = 1 surface branch's largest (2585 unknowns), a spectrum growing as
l(l + 1) with its lowest near zero, and the relatives of its own sector along the branch (held and free under
pressure, volume and gas: no constraint, one and two constraint rows, a positive rank-one gas term); the other
sectors have two (held and free under pressure). CPU seconds, best of 3 alternating rounds, single-threaded BLAS.

    python benchmarks/shift_invert_relatives.py [--size 2585]
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from balloon_cg.numerics import eigen  # noqa: E402

COUNT = 4  # surface_assessment.STABILITY_COUNT


def sector(n: int, rng) -> np.ndarray:
    """A symmetric matrix with eigenvalues 0.02 l(l + 1) − 0.05 (l = 1..n, a few below zero) in a random basis."""
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    values = 0.02 * np.arange(1, n + 1) * np.arange(2, n + 2) - 0.05
    return (q * values) @ q.T


def relatives(n: int, rng, own: bool) -> list:
    """(count, constraints, update) of the sector's readings (module docstring)."""
    held = rng.standard_normal((1, n))
    if not own:
        return [(COUNT, None, None), (COUNT, held, None)]
    g = rng.standard_normal(n)
    return [(COUNT, None, None), (COUNT, held, None), (COUNT, g[None, :], None), (COUNT, np.vstack([held, g]), None),
            (COUNT, None, (g / np.linalg.norm(g), 0.5)), (COUNT, held, (g / np.linalg.norm(g), 0.5))]


def seconds(f) -> float:
    start = time.process_time()
    f()
    return time.process_time() - start


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", type=int, default=2585)
    args = parser.parse_args(argv)
    rng = np.random.default_rng(0)
    A = sector(args.size, rng)
    shifted = eigen.ShiftInvert.below(A, -0.05)
    print(f"n = {args.size}, {COUNT} lowest per relative; CPU s, best of 3")
    print(f"{'sector':<8}{'relatives':>10}{'alone':>9}{'lockstep':>10}{'alone/lockstep':>16}  identical")
    for own in (True, False):
        wanted = relatives(args.size, rng, own)
        alone, together = [], []
        for _ in range(3):
            alone.append(seconds(lambda: [shifted.lowest(*r) for r in wanted]))
            together.append(seconds(lambda: shifted.lowest_of_relatives(wanted)))
        same = all(np.array_equal(a, b) for a, b in zip([shifted.lowest(*r) for r in wanted],
                                                        shifted.lowest_of_relatives(wanted)))
        print(f"{'own' if own else 'other':<8}{len(wanted):>10}{min(alone):9.3f}{min(together):10.3f}"
              f"{min(alone) / min(together):16.2f}  {same}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
