"""Benchmark: convergence of the second variation near a wire in the two perturbation bases (issue 37).

At near-wire points of the primary branches of the two-coil scene (M = 0.002) and the paper coil, the lowest
eigenvalue of every block (m = 0 and m = 1, held and free) at a ladder of degrees: "legendre" (P_k(x), x = cos θ:
today's, the point assessed at the degree in x that holds the equilibrium) and "mapped" (P_k(s) on the branch's
wire map, assessed at the branch's mapped degree). Each row: degree, CPU seconds of one ``SecondVariation.assess``
(m_max = 1, the basis built beforehand: tables and kernels are cached along a branch), then per block the
eigenvalue and its difference from the reference, x-degree 400 (``ref``). ``even_volume`` is converged in neither
basis with today's Gram matrix.

A second table per point repeats the m = 0 blocks with the displacement norm ∫(sin²θ δλ2² + δη²) dx as Gram matrix
(|δx|² of the m = 0 perturbation; the m ≥ 1 blocks use that norm already) in place of today's ∫(δλ2² + δη²) dx:
today's has no pole weight on δλ2, so perturbations concentrating at a pole keep a bounded Rayleigh quotient (it is
scale invariant there) and the eigenvalues above that threshold, and the eigenvectors' pole content below it,
converge algebraically in either basis; with the pole weight every block converges spectrally, the mapped basis at
about a third of the degree in x. Inertia, hence flags and crossings, does not depend on the Gram matrix.

    python benchmarks/stability_basis.py > benchmarks/results/stability_basis.txt
"""
import time
from pathlib import Path

import numpy as np
from scipy import linalg

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.stability.axisymmetric import SecondVariation, block_indices, point_degrees
from balloon_cg.numerics.threads import blas_threads
from balloon_cg.scene import load_scene

SCENES = Path(__file__).resolve().parents[1] / "scenes"
LADDERS = {"legendre": (100, 150, 225, 320), "mapped": (45, 60, 90, 135, 180)}
REFERENCE = 400
BLOCKS = ("even", "even_volume", "even_gas", "odd_held", "odd_free", "m1_held", "m1_free")


def assessed(eq, X, params, kind, degree):
    variation = SecondVariation(eq, degree, kind)
    variation.assess(X[:-1], params, True, 1)  # warm: the node kernels' first call
    start = time.process_time()
    blocks = variation.assess(X[:-1], params, True, 1).blocks
    return time.process_time() - start, {name: values[0] for name, values in blocks.items()}


def displacement_norm(eq, X, params, kind, degree):
    """The lowest eigenvalue of the m = 0 blocks (pressure, volume) with the Gram matrix ∫(sin²θ δλ2² + δη²) dx."""
    variation = SecondVariation(eq, degree, kind)
    H, g = variation.matrices(X[:-1], params)
    ops, w = variation.ops, variation.weights
    G = ops[0].T @ ((w * variation.basis.sin_theta ** 2)[:, None] * ops[0]) + ops[2].T @ (w[:, None] * ops[2])
    out = {}
    for name in ("even", "odd_held", "odd_free"):
        idx = block_indices(variation, name, True)
        out[name] = linalg.eigh(H[np.ix_(idx, idx)], G[np.ix_(idx, idx)], eigvals_only=True, subset_by_index=[0, 0])[0]
    idx = block_indices(variation, "even", True)
    Z = linalg.null_space(g[idx][None, :])
    out["even_volume"] = linalg.eigh(Z.T @ H[np.ix_(idx, idx)] @ Z, Z.T @ G[np.ix_(idx, idx)] @ Z, eigvals_only=True,
                                     subset_by_index=[0, 0])[0]
    return out


def main():
    for name in ("spom1_two_coils_M0.002", "spom1_paper_coil"):
        branch = trace_primary(load_scene(SCENES / f"{name}.toml"), down=False)
        eq, plain = equilibrium_of(branch), point_degrees(branch, 20)
        points = [len(branch.X) - 1, int(np.flatnonzero(plain >= 150)[0])]
        for n in points:
            X = branch.X[n]
            params = branch.params_at(X)
            north = float(branch.disc.pole_rows()["lam2_top"] @ X[:-1])
            print(f"\n{name}, point {n}: λ2(0) = {north:.6f}, P = {X[-1]:.8f}; held in x at degree {plain[n]}, "
                  f"stored at mapped degree {branch.disc.degree}")
            with blas_threads():
                _, ref = assessed(eq, X, params, "legendre", REFERENCE)
                print(f"  {'ref x-400':<14}{'':>8}" + "".join(f"{b + ' ' + format(ref[b], '.12g'):>34}" for b in BLOCKS))
                for kind, ladder in LADDERS.items():
                    for degree in ladder:
                        seconds, values = assessed(eq, X, params, kind, degree)
                        print(f"  {kind:<9}{degree:>5}{seconds:8.3f}s" + "".join(
                            f"{format(values[b], '.12g'):>22}{values[b] - ref[b]:>+12.1e}" for b in BLOCKS))
                ref = displacement_norm(eq, X, params, "legendre", REFERENCE)
                print("  displacement norm ∫(sin²θ δλ2² + δη²) dx:")
                print(f"  {'ref x-400':<14}" + "".join(f"{b + ' ' + format(ref[b], '.12g'):>34}" for b in ref))
                for kind, ladder in LADDERS.items():
                    for degree in ladder:
                        values = displacement_norm(eq, X, params, kind, degree)
                        print(f"  {kind:<9}{degree:>5}" + "".join(
                            f"{format(values[b], '.12g'):>22}{values[b] - ref[b]:>+12.1e}" for b in ref))


if __name__ == "__main__":
    main()
