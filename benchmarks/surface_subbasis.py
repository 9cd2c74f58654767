"""Benchmark: the two-coil m = 1 surface branch's stability readings on sub-bases (issue 37's first lever, "resolve each
question at the degree it needs"). The branch of scenes/spom1_two_coils_M0.002.toml is traced (its stability not
read); at the points ``POINTS`` each symmetry sector is read as the assessment reads it (``surface.stability.
sector_spectra``: the six readings, the 4 lowest μ each, following a guess) on its traced basis (L, M) and on the
nested sub-bases (L − 4k, M − k), k = 2, 4, 6, 8 (``surface.stability.sub_basis``: Rayleigh–Ritz, the state kept on
its traced basis and quadrature). Per sector and sub-basis: its size, the largest |μ_sub − μ| / max(1, |μ|) over the
24 values (issue 37's "unchanged" allows 1e-9), and the CPU seconds of the read over the full read's (one process,
one run: the ratios, not the seconds, on a loaded machine). ``needed``: the smallest sub-basis within 1e-9 (an
oracle: what a perfect choice would cost); ``nested``: it and the next finer one read both (what showing the
convergence by two nested sub-bases costs). The guess each read follows: the dense lowest μ of the (L/2, M/2)
sub-basis (an upper bound), the same for every read of a sector.

Then, at the last point given, a check without a second read: for the held reading under pressure control of each
sector on rungs 2 and 4, the residual r of each Ritz pair (μ, y) on the whole sector (its zero modes projected out),
and the estimate |r|²/(λ_rest − μ), λ_rest the lowest eigenvalue of the sector's block outside the rung (the second
order Rayleigh–Ritz error where the unresolved part is stiff), against the error μ − μ_sector (dense solves on
explicit null spaces: a study, not an implementation; |r| would come from ``SurfaceEquilibrium.hessian_product``).

    BALLOON_CG_WORKERS=1 python benchmarks/surface_subbasis.py [POINT ...] > benchmarks/results/surface_subbasis.txt
"""
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy import linalg

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.surface import branches
from balloon_cg.numerics.threads import blas_threads
from balloon_cg.scene import load_scene
from balloon_cg.surface import stability

SCENE = Path(__file__).resolve().parent.parent / "scenes" / "spom1_two_coils_M0.002.toml"
POINTS = (2, 5, 8, 10, 11, 13)
RUNGS = (2, 4, 6, 8)
UNCHANGED = 1e-9
COUNT = 4


def traced_branch(scene) -> tuple:
    """(the m = 1 branch's traced points, its parameter values) of ``scene``, its stability not read."""
    kept = []

    def keep(sb, traced, *args, **kwargs):
        kept.append((traced, list(sb.values), sb.params))
        return True
    branches.assess = keep
    analyse(scene)
    return kept[0]


def read(eq, c, params, key, guesses, within=None) -> tuple:
    """(the sector's spectra {reading: values}, CPU seconds) of one read of sector ``key``."""
    start = time.process_time()
    with blas_threads():  # as the assessment reads: one BLAS thread (a spinning second one is CPU, not work)
        spectra = stability.sector_spectra(eq, c, params, COUNT, stability.READINGS, guesses, (key,), within)
    return {r: spectra[r][key] for r in stability.READINGS}, time.process_time() - start


def deviation(found: dict, full: dict) -> float:
    """max |μ_sub − μ| / max(1, |μ|) over the readings' values."""
    return max(float(np.max(np.abs(found[r] - full[r]) / np.maximum(1.0, np.abs(full[r])))) for r in full)


def residual_study(eq, c, params, sector) -> None:
    """Prints, for rungs 2 and 4 of ``sector``, the held pressure reading's error and residual estimate (module
    docstring)."""
    fields = stability.zero_mode_fields(eq.node_values(c)["state"], eq.basis,
                                        stability.field_symmetry(eq, params), True)
    with blas_threads():
        A = eq.hessian(c, params, sector) / sector.gram()
        Z = stability.mode_rows(sector, fields)
        Q, N = linalg.orth(Z.T), linalg.null_space(Z)
        exact = linalg.eigh(N.T @ A @ N, eigvals_only=True, subset_by_index=[0, COUNT - 1])
        blocks = {(b.component, b.m, b.t): b for b in sector.blocks}
        for k in (2, 4):
            sub = stability.sub_basis(sector, sector.degree - 4 * k, sector.order - k)
            index = np.concatenate([blocks[b.component, b.m, b.t].offset
                                    + np.searchsorted(blocks[b.component, b.m, b.t].degrees, b.degrees)
                                    for b in sub.blocks])
            N1 = linalg.null_space(Z[:, index])
            mu, W = linalg.eigh(N1.T @ A[np.ix_(index, index)] @ N1, subset_by_index=[0, COUNT - 1])
            Y = np.zeros((A.shape[0], COUNT))
            Y[index] = N1 @ W
            R = A @ Y - Y * mu
            r = np.linalg.norm(R - Q @ (Q.T @ R), axis=0)
            rest = np.setdiff1d(np.arange(A.shape[0]), index)
            stiff = linalg.eigh(A[np.ix_(rest, rest)], eigvals_only=True, subset_by_index=[0, 0])[0]
            print(f"  {str(sector.characters):>9} k={k} n={sub.size:>5}  error " + " ".join(f"{e:8.1e}" for e in mu - exact)
                  + "   |r|²/(λ_rest − μ) " + " ".join(f"{e:8.1e}" for e in r ** 2 / (stiff - mu))
                  + f"   λ_rest {stiff:.0f}", flush=True)


def main(points=POINTS):
    scene = load_scene(SCENE)
    traced, values, params0 = traced_branch(scene)
    print(f"# {SCENE.name}: m = 1 branch, {len(traced)} points; load average before the reads "
          f"{os.getloadavg()[0]:.1f}")
    print(f"{'point':>5} {'sector':>9} {'L,M':>6} {'n':>5} {'full s':>7}   " +
          "   ".join(f"{'k=' + str(k) + ' n':>7} {'dev':>8} {'cpu':>5}" for k in RUNGS) + "   needed  nested")
    totals = {"full": 0.0, "needed": 0.0, "nested": 0.0}
    for i in points:
        trace, c = traced[i]
        eq, params = trace.eq, params0.with_value("P", values[i])
        for sector in trace.basis.sectors():
            if not sector.size:
                continue
            key, L, M = sector.characters, sector.degree, sector.order
            rough = stability.sub_basis(sector, max(L // 2, 1), max(M // 2, 1))
            guess, _ = read(eq, c, params, key, None, {key: rough})
            guesses = {r: {key: guess[r]} for r in stability.READINGS}
            full, full_cpu = read(eq, c, params, key, guesses)
            rows, found = [], []
            for k in RUNGS:
                if M - k < 1:
                    rows.append(f"{'-':>7} {'-':>8} {'-':>5}")
                    continue
                sub = stability.sub_basis(sector, L - 4 * k, M - k)
                values_k, cpu = read(eq, c, params, key, guesses, {key: sub})
                dev = deviation(values_k, full)
                found.append((k, dev, cpu))
                rows.append(f"{sub.size:>7} {dev:8.1e} {cpu / full_cpu:5.2f}")
            within = [(k, dev, cpu) for k, dev, cpu in found if dev <= UNCHANGED]
            needed = max(within, key=lambda x: x[0]) if within else None
            needed_cpu = needed[2] if needed else full_cpu
            finer = [cpu for k, _, cpu in found if needed and k == needed[0] - 2]
            nested_cpu = needed_cpu + (finer[0] if finer else full_cpu) if needed else 2.0 * full_cpu
            totals["full"] += full_cpu
            totals["needed"] += needed_cpu
            totals["nested"] += nested_cpu
            print(f"{i:>5} {str(key):>9} {f'{L},{M}':>6} {sector.size:>5} {full_cpu:7.2f}   " + "   ".join(rows)
                  + f"   {needed_cpu / full_cpu:6.2f}  {nested_cpu / full_cpu:6.2f}", flush=True)
    print(f"# CPU over these points: full {totals['full']:.1f} s, the needed sub-basis {totals['needed']:.1f} s "
          f"({totals['needed'] / totals['full']:.2f}x), the nested pair {totals['nested']:.1f} s "
          f"({totals['nested'] / totals['full']:.2f}x); load average after {os.getloadavg()[0]:.1f}")
    trace, c = traced[points[-1]]
    print(f"# point {points[-1]}: the held reading under pressure control on rungs 2 and 4, its error against the "
          "sector's and the residual estimate")
    for sector in trace.basis.sectors():
        if sector.size:
            residual_study(trace.eq, c, params0.with_value("P", values[points[-1]]), sector)


if __name__ == "__main__":
    main(tuple(int(a) for a in sys.argv[1:]) or POINTS)
