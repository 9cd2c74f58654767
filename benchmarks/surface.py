"""Speed of the whole-sphere engine (surface/): a Newton solve at degree L, a branch of ~100 points, and one
axisymmetric state solved in the 2D space against the axisymmetric solver (ratios from one run: the machine is
noisy). Run against the installed package: `make install-dev && python benchmarks/surface.py`.

1. Newton at fixed P from the previous point of the M = 0 m = 1 branch of SPOM1 (the sideways pear; subspace
   y → −y, z → −z), L = 12, 16, 20: wall time per solve, best of 5.
2. That branch traced at a fixed degree L = 16 (solver.max_error 1e-3: no refinement), up to 100 points: the trace
   alone and the stability of every point (4 sectors, held and free).
3. The SPOM1 sphere at λ2(0) = 1.5 (below the pear point) from a perturbed start, at the prescribed pole stretch: the axisymmetric solver
   (galerkin.point_solve, degree 24) against the 2D one (L = 16 and 24, the same subspace).
"""
import time
from dataclasses import replace

import numpy as np

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Block
from balloon_cg.analysis.surface import branches as sb
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Parameters
from balloon_cg.galerkin.point_solve import constrained_newton
from balloon_cg.model.sphere import sphere_pressure
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import load_scene
from balloon_cg.surface.basis import EQUATOR, MIRROR_Y, SphericalBasis
from balloon_cg.surface.embedding import displacement_coefficients
from balloon_cg.surface.equilibrium import SurfaceEquilibrium
from balloon_cg.surface.gauge import FieldSymmetry, Gauge
from balloon_cg.surface.measures import axial_stretch_row
from balloon_cg.surface.system import SurfaceSystem


def best(function, repeat=5):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), result


def pear_branch(scene, points: int):
    picture = analyse(scene.with_overrides({"continuation.stop_stretch": 4.0, "surface.branches": "none"}))
    primary = picture.primary
    bp = replace(primary.branch_points()[0], m=1, block=Block.M1_HELD)
    return primary, bp


def newton_solves(scene, primary, bp):
    print("1. Newton at fixed P from the previous point of the branch (M = 0 sideways pear)")
    print(f"{'L':>4} {'unknowns':>9} {'iterations':>10} {'ms/solve':>9}")
    for degree in (12, 16, 20):
        primary.scene = scene.with_overrides({"surface.degree": degree, "solver.max_error": 1e-5})
        branch = sb.trace_surface(primary, 0, bp, 1.0, "m1", 8)
        trace = sb.SurfaceTrace(primary.scene, branch.basis, branch.params)
        X0 = trace.system.point(branch.coefficients[-2], branch.values[-1])
        elapsed, result = best(lambda: trace.system.solve(X0, tol=1e-11))
        print(f"{degree:>4} {trace.gauge.size:>9} {result.iterations:>10} {elapsed * 1e3:>9.1f}")


def branch_timing(scene, primary, bp):
    print("2. the branch at fixed L = 16, up to 100 points")
    primary.scene = scene.with_overrides({"surface.degree": 16, "solver.max_error": 1e-3,
                                          "continuation.stop_stretch": 10.0})
    assess = sb.assess
    timing = {}

    def timed(branch, trace):
        start = time.perf_counter()
        assess(branch, trace)
        timing["assess"] = time.perf_counter() - start

    sb.assess = timed
    try:
        start = time.perf_counter()
        branch = sb.trace_surface(primary, 0, bp, 1.0, "m1", 100)
        total = time.perf_counter() - start
    finally:
        sb.assess = assess
    n = len(branch.values)
    print(f"   {n} points, stop: {branch.stop_reason}")
    print(f"   trace {total - timing['assess']:.2f} s ({(total - timing['assess']) / n * 1e3:.1f} ms/point), "
          f"stability {timing['assess']:.2f} s ({timing['assess'] / n * 1e3:.1f} ms/point), total {total:.2f} s")


def sphere_solves(scene):
    print("3. one axisymmetric state (SPOM1 sphere, λ2(0) = 1.5) from a perturbed start, pole stretch prescribed")
    stretch, P = 1.5, sphere_pressure(scene.material, 1.5)
    disc = Discretisation(24, symmetric=True, pin_translation=True)
    a, b = np.zeros(disc.degree + 1), np.zeros(disc.degree + 1)
    a[0], b[1] = stretch, stretch  # λ2 = λ, η = λ cos θ
    u0 = disc.join(a, b) + 1e-3 * np.random.default_rng(0).standard_normal(disc.size)
    axi, result = best(lambda: constrained_newton(scene, 24, np.append(u0, 1.05 * P), disc, stretch,
                                                  Parameters(P), tol=1e-11))
    print(f"   axisymmetric, degree 24: {axi * 1e3:.2f} ms, P error {abs(result[0].x[-1] - P):.1e}")
    for degree in (16, 24):
        basis = SphericalBasis(degree, (MIRROR_Y, EQUATOR))
        eq = SurfaceEquilibrium(scene, basis)
        system = SurfaceSystem(eq, Gauge(basis, held=True, field_symmetry=FieldSymmetry.NONE), Parameters(P))
        row, offset = axial_stretch_row(basis)
        c = displacement_coefficients(basis, (stretch - 1) * basis.nodes["reference"][:3])
        c = c + 1e-3 * np.random.default_rng(0).standard_normal(basis.size)
        X0 = system.point(system.gauge.expand(system.gauge.reduce(c)), 1.05 * P)
        rows = np.append(system.gauge.reduce(row), 0.0)
        elapsed, result = best(lambda: newton(system.residual, system.jacobian, X0, rows, stretch - offset, 1e-11,
                                              30))
        print(f"   2D, L = {degree} ({system.gauge.size} unknowns): {elapsed * 1e3:.2f} ms "
              f"({elapsed / axi:.0f}x the axisymmetric solve), P error {abs(result.x[-1] - P):.1e}")


def main():
    scene = load_scene("scenes/spom1.toml")
    primary, bp = pear_branch(scene, 100)
    sb.trace_surface(primary, 0, bp, 1.0, "warm", 3)  # compile
    newton_solves(scene, primary, bp)
    branch_timing(scene, primary, bp)
    sphere_solves(scene)


if __name__ == "__main__":
    main()
