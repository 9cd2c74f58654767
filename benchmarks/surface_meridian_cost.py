"""Benchmark: the per-point cost of the two-coil scene's m = 1 surface branch (m1_bp1) in the whole-sphere harmonics
(surface/, the run's) against the sphere over (θ, φ) of the meridian engine (analysis/surface/meridian/sphere.py),
in one process (one machine load), for issue 37's lever "a basis made for coaxial scenes".

Harmonics: the run file's stored basis (degree 64, order 36, its map) at its last stored point (13, gap 0.096 from
a wire): the bordered Jacobian's assembly (SurfaceSystem.jacobian), its LU factorisation, and the dense reading of
the branch's own sector (y → −y and z → −z even: surface.stability.sector_spectra, held, pressure control, 4
eigenvalues; the run reads all four sectors and six readings). Meridian: the sphere's basis at the branch point's
mode degree (90, the
trace's) with the orders 0..K, K = 8 (what the branch's first points need for 1e-9), 16 (the refinement cap the
trace reached, MAX_HARMONICS) and 36 (what its last stored point needs: the per-order content decays by ~0.65 per
order there), at the axisymmetric branch point state (a dense assembly and factorisation cost the same at any
state): the bordered Jacobian's assembly, its LU, and one dense eigvalsh of the pressure-control matrix (of the
three readings SectorStability makes per point: that sector, the meridian basis holding only it). CPU seconds of
this process with one BLAS thread (numerics.threads.blas_threads; on a machine loaded several times over its cores,
wall seconds measure the neighbours), with the load average.

    python benchmarks/surface_meridian_cost.py RUN_FILE   (a run of scenes/spom1_two_coils_M0.002.toml)
"""
import os
import sys
import time
from dataclasses import replace

import numpy as np
from scipy import linalg

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.surface.branches import SurfaceTrace
from balloon_cg.analysis.surface.meridian.equilibrium import MeridianSurfaceEquilibrium
from balloon_cg.analysis.surface.meridian.sphere import SphereSurfaceBasis
from balloon_cg.analysis.surface.meridian.stability import SectorStability
from balloon_cg.analysis.surface.meridian.system import MeridianSurfaceSystem
from balloon_cg.io.run_file import read_run, stored_basis, stored_scene
from balloon_cg.numerics.threads import blas_threads
from balloon_cg.surface import stability as surface_stability

MODE_DEGREE, ORDERS = 90, (8, 16, 36)


def timed(call):
    t = time.process_time()
    out = call()
    return time.process_time() - t, out


def bordered(J):
    """The square matrix Newton factors: J with the continuation row (here e_P)."""
    row = np.zeros(J.shape[1])
    row[-1] = 1.0
    return np.vstack([J, row])


def harmonic_costs(scene, run, k, branch_params):
    stored = run["branches"]["m1_bp1"]
    basis = stored_basis(stored["attrs"])
    c, P = stored["coefficients"][k], stored["pressure"][k]
    params = branch_params.with_value("P", P)
    trace = SurfaceTrace(scene, basis, params, held=True)
    X = trace.system.point(c, P)
    t_jac, J = timed(lambda: trace.system.jacobian(X))
    t_lu, _ = timed(lambda: linalg.lu_factor(bordered(J)))
    held = (surface_stability.Reading(True),)
    t_stab, _ = timed(lambda: surface_stability.sector_spectra(trace.eq, c, params, 4, held, only=((1, 1),)))
    sectors = [s.size for s in basis.sectors() if s.size]
    return f"harmonics L64 M36, point {k}", J.shape[0], f"sectors {sectors}", t_jac, t_lu, t_stab


def meridian_costs(scene, primary, bp, K):
    disc = replace(primary.disc, symmetric=True)
    basis = SphereSurfaceBasis(disc, scene.geometry, MODE_DEGREE, tuple(range(K + 1)), 0, True)
    params = primary.params_at(bp.X)
    c = basis.axisymmetric(primary.disc.transfer(bp.X[:-1], disc))
    system = MeridianSurfaceSystem(MeridianSurfaceEquilibrium(scene, basis), params, c)
    X = system.point(c, bp.X[-1])
    t_jac, J = timed(lambda: system.jacobian(X))
    t_lu, _ = timed(lambda: linalg.lu_factor(bordered(J)))
    reader = SectorStability(system)
    t_stab, _ = timed(lambda: np.linalg.eigvalsh(reader.pressure_matrix(c, params)))
    return f"meridian N{MODE_DEGREE} K={K}", J.shape[0], f"n_phi {basis.n_phi}, nodes {basis.rule()[0].size}", \
        t_jac, t_lu, t_stab


def main():
    run = read_run(sys.argv[1])
    scene = stored_scene(run)
    primary = analyse(scene.with_overrides({"surface.branches": "none"})).primary
    bp = primary.branch_points()[run["branches"]["m1_bp1"]["attrs"]["parent_branch_point"]]
    rows = [harmonic_costs(scene, run, 13, primary.params)]
    rows += [meridian_costs(scene, primary, bp, K) for K in ORDERS]
    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}; "
          f"CPU s of this process, one BLAS thread")
    print(f"{'basis':34s} {'unknowns':>8s} {'Jacobian':>9s} {'LU':>7s} {'stability':>10s}   "
          "(Jacobian + LU) / harmonics'")
    base = rows[0][3] + rows[0][4]
    for name, n, note, t_jac, t_lu, t_stab in rows:
        print(f"{name:34s} {n:8d} {t_jac:9.3f} {t_lu:7.3f} {t_stab:10.3f}   {(t_jac + t_lu) / base:6.2f}   ({note})")
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    with blas_threads():
        main()
