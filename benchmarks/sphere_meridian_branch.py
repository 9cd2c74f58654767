"""Study: the two-coil scene's m = 1 surface branch (m1_bp1 of a run file of scenes/spom1_two_coils_M0.002.toml)
traced with the meridian engine on the sphere (analysis/surface/meridian/sphere.traced_branch: orders 0..K refined by
capsule_resolution, MAX_HARMONICS = 16) and compared with the stored whole-sphere branch: per meridian point its tails
(axis, mode, order) and the RMS of each order's field over the mean radius (the decay that sets K); then at each
stored point's pressure the meridian state solved again on its final basis (Newton at fixed P from the nearest traced
point off the axisymmetric one) and its volume and both material pole stretches √J (J's φ-mean at θ = 1e-4 and 2e-4
from each pole, Richardson: J = J0 + O(θ²)) against the stored ones, beside both error estimates.

    python benchmarks/sphere_meridian_branch.py RUN_FILE [MAX_POINTS]
"""
import sys
import time

import numpy as np

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.stability.azimuthal import _point_ops
from balloon_cg.analysis.surface.meridian import capsule_resolution, sphere
from balloon_cg.analysis.surface.meridian.equilibrium import MeridianSurfaceEquilibrium
from balloon_cg.analysis.surface.meridian.system import MeridianSurfaceSystem
from balloon_cg.io.run_file import read_run, stored_scene
from balloon_cg.numerics.newton import newton
from balloon_cg.numerics.threads import limited_blas


def pole_stretch(basis, c, north: bool, theta0=1e-4, n_phi=64):
    """√J at the material pole (module docstring)."""
    values = []
    for th in (theta0, 2 * theta0):
        th = th if north else np.pi - th
        x, s_ = np.cos(th), np.sin(th)
        lam2, dlam2, eta, deta = (np.atleast_1d(v)[0] for v in basis.disc.evaluate(c[basis.block(0)], np.array([th])))
        phi = 2 * np.pi * np.arange(n_phi) / n_phi
        zero = 0 * phi
        r, dr, t, dt = lam2 * s_ + zero, dlam2 * s_ + lam2 * np.cos(th) + zero, zero.copy(), zero.copy()
        z, dz, rp, tp, zp = eta + zero, deta + zero, zero.copy(), zero.copy(), zero.copy()
        mapping = basis.disc.mapping
        for m in basis.orders[1:]:
            b = basis.perturbations(m)
            s = mapping.s(np.array([x])) if mapping is not None else np.array([x])
            _, ops = _point_ops(m, b.degree, s, np.array([x]), mapping)
            R, dR, Z, dZ, T, dT = ops[:, 0, basis.kept(m)] @ c[basis.block(m)]
            cm, sm = np.cos(m * phi), np.sin(m * phi)
            r, dr, z, dz, t, dt = r + R * cm, dr + dR * cm, z + Z * cm, dz + dZ * cm, t + T * sm, dt + dT * sm
            rp, zp, tp = rp - m * R * sm, zp - m * Z * sm, tp + m * T * cm
        a_s, a_phi = np.array([dr, dt, dz]), np.array([rp - t, tp + r, zp]) / s_
        values.append(np.mean(np.linalg.norm(np.cross(a_s.T, a_phi.T), axis=1)))
    return np.sqrt((4 * values[0] - values[1]) / 3)


def main():
    run = read_run(sys.argv[1])
    max_points = int(sys.argv[2]) if len(sys.argv) > 2 else 10
    scene = stored_scene(run)
    stored = run["branches"]["m1_bp1"]
    primary = analyse(scene.with_overrides({"surface.branches": "none"})).primary
    k0 = stored["attrs"]["parent_branch_point"]
    bp = primary.branch_points()[k0]
    params = primary.params_at(bp.X)
    t0, c0 = time.perf_counter(), time.process_time()
    mb = limited_blas(sphere.traced_branch)(scene, primary, bp, max_points=max_points, parent=("primary", k0))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    basis = mb.basis
    print(f"meridian trace: wall {wall:.1f} s, cpu {cpu:.1f} s, {len(mb.pressure)} points, stop {mb.stop.code.value}; "
          f"final basis disc degree {basis.disc.degree}, mode degree {basis.mode_degree}, "
          f"orders 0..{basis.orders[-1]}, "
          f"n_phi {basis.n_phi}, {basis.size} unknowns; folds {mb.folds}")
    print("stored branch: wall_time", stored["attrs"]["wall_time"], "s,", len(stored["pressure"]), "points")
    print("unstable counts of the mirror sector (pressure, volume, gas):",
          {k.value: v.tolist() for k, v in mb.unstable.items()})
    print("per-point tails (axis, mode, order) and RMS of each order's field / mean radius, orders 1..16:")
    radius = [abs(basis.disc.split(c[basis.block(0)])[0][0]) for c in mb.coefficients]
    for i, c in enumerate(mb.coefficients):
        t = capsule_resolution.tails(basis, c)
        rms = [np.sqrt(c[basis.block(m)] @ basis.gram(m) @ c[basis.block(m)]) / radius[i] for m in basis.orders[1:]]
        print(f" {i:2d} P={mb.pressure[i]:.6f} tails {t[0]:.1e} {t[1]:.1e} {t[2]:.1e} |",
              " ".join(f"{r:.0e}" for r in rms))

    eq = MeridianSurfaceEquilibrium(scene, basis)
    system = MeridianSurfaceSystem(eq, params, mb.coefficients[0])
    print(f"\nat the stored pressures (meridian re-solved on its final basis, orders 0..{basis.orders[-1]}, "
          f"mode degree {basis.mode_degree}):")
    print(" k  P               V stored      V mer-stored  top stored    top mer-stored  bottom mer-stored  "
          "stored err  mer err at P")
    for k, P in enumerate(stored["pressure"]):
        if k == 0:
            c = mb.coefficients[0]
        else:
            before = np.flatnonzero(np.diff(mb.pressure) > 0)  # the traced points before the first fold
            last = before[0] + 1 if before.size else len(mb.pressure)
            j = 1 + int(np.argmin(np.abs(mb.pressure[1:last] - P)))
            X0 = system.point(mb.coefficients[j], mb.pressure[j])
            row = np.zeros(X0.size)
            row[-1] = 1.0
            res = newton(system.residual, system.jacobian, X0, row, P, scene.solver.tol, scene.solver.max_newton)
            if not res.converged:
                print(k, "no convergence", res.message)
                continue
            c = system.coefficients(res.x)
        V = 2 * np.pi * eq.volume(c)
        top, bottom = pole_stretch(basis, c, True), pole_stretch(basis, c, False)
        print(f"{k:2d} {P:.12f} {stored['volume'][k]:.10f} {V - stored['volume'][k]:+.2e}     "
              f"{stored['lam2_top'][k]:.10f} {top - stored['lam2_top'][k]:+.2e}       "
              f"{bottom - stored['lam2_bottom'][k]:+.2e}           {stored['error_estimate'][k]:.1e}    "
              f"{capsule_resolution.error_estimate(basis, c):.1e}")


if __name__ == "__main__":
    main()
