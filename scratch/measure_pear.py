"""The held pear branch of a spheroid (aspect 1.3, one coil, M = 0.002): P on the first corrections
phi·(X − X*) = δ against the located P*, extrapolated to δ = 0 (P even in δ)."""
import sys, numpy as np
from balloon_cg.analysis.picture import analyse
from balloon_cg.scene import load_scene
from balloon_cg.numerics.newton import newton
from balloon_cg.analysis.points.branch_points import general_tracer, mode_direction, plain_degree, to_general

scene = load_scene("spom1_single_coil").with_overrides(
    {"geometry.shape": "spheroid", "geometry.aspect": 1.3, "continuation.stop_stretch": 1.8,
     "surface.branches": "none"})
branch = analyse(scene, pear=False).primary
for bp in branch.branch_points():
    if bp.block.value not in ("odd_held", "odd_free"):
        continue
    tracer = general_tracer(scene, bp.block)
    degree = plain_degree(branch, bp.X)
    system = tracer.system(degree, branch.params)
    X_star = np.append(to_general(branch, tracer, degree, bp.X[:-1]), bp.X[-1])
    phi = mode_direction(bp, system.eq.disc)
    r0 = np.linalg.norm(system.residual(X_star))
    rows = []
    for d in (0.02, 0.01, 0.005, -0.005, -0.01):
        g = X_star + d * phi
        res = newton(system.residual, system.jacobian, g, phi, phi @ g, scene.solver.tol, scene.solver.max_newton)
        rows.append((d, res.x[-1], res.converged))
    P = {d: p for d, p, _ in rows}
    extrap = (4 * P[0.01] - P[0.02]) / 3
    print(f"{bp.block.value}: P* = {bp.X[-1]:.10f}  |R(X*)| in the general held space = {r0:.3e}  degree {degree}")
    for d, p, c in rows:
        print(f"  delta {d:+.3f}  P = {p:.10f}  P - P* = {p - bp.X[-1]:+.3e}  converged {c}")
    print(f"  P(δ→0) (Richardson 0.02, 0.01) = {extrap:.10f}, minus P* = {extrap - bp.X[-1]:+.3e}; "
          f"P(+.005) - P(-.005) = {P[0.005] - P[-0.005]:+.2e}")
