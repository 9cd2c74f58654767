"""The three lowest eigenvalues of a dense symmetric matrix: the jitted path (numerics.eigen: Householder
tridiagonalisation, then bisection on Sturm counts turning to safeguarded Newton steps once an eigenvalue is
isolated) against LAPACK dsyevr (range 'I'), by size, one run; and each one's largest error against the full
spectrum of numpy's eigvalsh, relative to max |λ|. The sizes of the stability blocks: 20–41 (m = 0 at N = 20),
28–57 (m = 1), 80+ (the check at 2N and near wires). SMALL_EIGEN is where ``lowest_of`` changes from one to the
other. Best of 5 rounds of 2000 calls, wall clock, single-threaded BLAS.

    python benchmarks/eigen_small.py
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import time  # noqa: E402

import numpy as np  # noqa: E402
from scipy.linalg.lapack import dsyevr  # noqa: E402

from balloon_cg.numerics import eigen  # noqa: E402

SIZES = (20, 30, 41, 57, 64, 80, 120)
COUNT = 3


def best(f, calls=2000, rounds=5):
    f()
    times = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        for _ in range(calls):
            f()
        times.append((time.perf_counter() - t0) / calls)
    return min(times)


def main():
    rng = np.random.default_rng(0)
    print(f"three lowest eigenvalues, SMALL_EIGEN = {eigen.SMALL_EIGEN} (µs per call, error / max|λ|)")
    print(f"{'n':>5} {'jitted':>9} {'dsyevr':>9} {'dsyevr/jitted':>14} {'jitted err':>11} {'dsyevr err':>11}")
    for n in SIZES:
        B = rng.standard_normal((n, n))
        A = B + B.T
        exact = np.linalg.eigvalsh(A)
        scale = np.abs(exact).max()

        def jitted():
            return eigen._lowest_small(A.copy(), COUNT)

        def lapack():
            return dsyevr(A.copy().T, compute_v=0, range="I", il=1, iu=COUNT, overwrite_a=1)[0][:COUNT]

        errors = [np.abs(f() - exact[:COUNT]).max() / scale for f in (jitted, lapack)]
        t_jit, t_lap = best(jitted), best(lapack)
        print(f"{n:5d} {t_jit * 1e6:9.1f} {t_lap * 1e6:9.1f} {t_lap / t_jit:14.2f} {errors[0]:11.1e} {errors[1]:11.1e}")


if __name__ == "__main__":
    main()
