"""Specialised kernels against the most general class, same scene (SPOM1, M = 0), same points, one run.

Classes (all generated, selected with ``Equilibrium(..., kernel_class=...)``):
  ogden_spom1          exponents (1.3, 4, −2) baked in, no field terms (what the scene uses by default)
  ogden_spom1_field    exponents baked in, field terms on (zero field: M = 0, no coils)
  ogden_general_field  the most general class: 3 Ogden terms with runtime exponents, field terms on, M = 0
Per point: (a) the node kernels alone (energy_gradient + energy_hessian at every quadrature node), (b) one
pole-stretch-constrained Newton solve from the neighbour at λ* − 0.02 (what a continuation step costs
without the step control), (c) pseudo-arclength continuation (continuation.trace) from the sphere at 1.01 to
λ = 3 at fixed step, time per converged point. Best of REPEAT, classes interleaved. Every class must give the
same P (checked). Times are process CPU times, single-threaded BLAS (the machine is shared and loaded: see
benchmarks/work_precision.py).

Run: python benchmarks/specialisation.py   (writes benchmarks/results/specialisation.txt)
"""
import os
import time

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # single-threaded BLAS (before numpy loads), as the other benchmarks

import numpy as np  # noqa: E402

import work_precision as wp  # noqa: E402
from balloon_cg.numerics import continuation  # noqa: E402
from balloon_cg.analysis.branches.problem import ParameterSystem  # noqa: E402
from balloon_cg.galerkin.discretisation import Discretisation  # noqa: E402
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters  # noqa: E402
from balloon_cg.numerics.newton import newton  # noqa: E402
from balloon_cg.scene import parse_scene  # noqa: E402
from balloon_cg.model.sphere import sphere_pressure  # noqa: E402

CLASSES = ("ogden_spom1", "ogden_spom1_field", "ogden_general_field")
DEGREES = (24, 40, 64)
STRETCHES = (1.3, 2.0)
REPEAT = 7


def equilibrium(scene, degree, name):
    return Equilibrium(scene, Discretisation(degree, True, True), kernel_class=name)


def point_system(eq):
    """(residual, jacobian) of X = (u, P) for the constrained point solve."""
    system = ParameterSystem(eq, Parameters(0.0), "P")
    return system.residual, system.jacobian


def sphere_X(eq, lam, material):
    a, b = np.zeros(eq.disc.degree + 1), np.zeros(eq.disc.degree + 1)
    a[0], b[1] = lam, lam
    return np.append(eq.disc.join(a, b), sphere_pressure(material, lam))


def kernels_only(eq, X):
    p = Parameters(X[-1])
    t0 = time.process_time()
    eq._pointwise("energy_gradient", X[:-1], p)
    eq._pointwise("energy_hessian", X[:-1], p)
    return time.process_time() - t0


def throughput(eq, X, nodes=20000, repeat=REPEAT):
    """CPU time per node of the Hessian kernel alone, on the solution's node states tiled to ``nodes``."""
    state = eq.disc.node_state(X[:-1])
    reps = nodes // state.shape[1] + 1
    state = tuple(np.ascontiguousarray(np.tile(s, reps)[:nodes]) for s in state)
    geometry = tuple(np.ascontiguousarray(np.tile(g, reps)[:nodes]) for g in (eq.disc.cos_theta, eq.disc.sin_theta))
    values = {"cos_theta": geometry[0], "sin_theta": geometry[1], **eq.kernels.state(state), "P": X[-1], "M": 0.0,
              "chi": 1.0, "field": np.zeros((6, nodes))}
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        eq.kernels.nodes("energy_hessian", values)
        best = min(best, time.process_time() - t0)
    return best / nodes


def point_solve(eq, X0, stretch):
    residual, jacobian = point_system(eq)
    row = np.append(eq.disc.pole_rows()["lam2_top"], 0.0)
    t0 = time.process_time()
    result = newton(residual, jacobian, X0, row, stretch, 1e-11, 25)
    return time.process_time() - t0, result


def trace(eq, scene, top=3.0):
    system = ParameterSystem(eq, Parameters(0.0), "P")
    settings = continuation.Settings(0.02, 1e-7, 0.02, 2000, 1e-11, 25)
    X0 = sphere_X(eq, 1.01, scene.material)
    north = np.append(eq.disc.pole_rows()["lam2_top"], 0.0)
    t0 = time.process_time()
    start = continuation.Point(X0, continuation.tangent(system, X0, north), 0, 0.0)
    path = continuation.trace(system, start, settings, lambda p: "top" if north @ p.X >= top else None,
                              {"LP": np.eye(X0.size)[-1]})
    return time.process_time() - t0, len(path.points), path


def main():
    scene = parse_scene(wp.SPOM1_M0, name="spom1")
    t_start = time.perf_counter()
    rows = {}
    lines = ["Specialised kernels vs the most general class: SPOM1, M = 0 (equator-symmetric subspace, "
             f"best of {REPEAT}, classes interleaved)", ""]
    for degree in DEGREES:
        eqs = {name: equilibrium(scene, degree, name) for name in CLASSES}
        starts, results = {}, {}
        for name, eq in eqs.items():  # compile/load, and the neighbours (untimed)
            residual, jacobian = point_system(eq)
            row = np.append(eq.disc.pole_rows()["lam2_top"], 0.0)
            for s in STRETCHES:
                guess = sphere_X(eq, s - wp.H, scene.material) * (1 + 1e-3)  # not on the solution: Newton works
                starts[(name, s)] = newton(residual, jacobian, guess, row, s - wp.H, 1e-13, 25).x
            trace(eq, scene, top=1.1)
        best = {}
        for _ in range(REPEAT):
            for name, eq in eqs.items():
                for s in STRETCHES:
                    X = starts[(name, s)]
                    k = kernels_only(eq, X)
                    seconds, result = point_solve(eq, X, s)
                    results[(name, s)] = result
                    for key, value in ((("kernels", s), k), (("solve", s), seconds)):
                        best[(name,) + key] = min(best.get((name,) + key, np.inf), value)
                seconds, n, path = trace(eq, scene)
                best[(name, "trace")] = min(best.get((name, "trace"), np.inf), seconds / n)
                best[(name, "trace_points")] = n
        for s in STRETCHES:
            P = [results[(name, s)].x[-1] for name in CLASSES]
            spread = max(abs(p / P[0] - 1) for p in P)
            assert all(results[(name, s)].converged for name in CLASSES) and spread < 1e-11, (degree, s, P)
        rows[degree] = best
        lines.append(f"degree {degree} ({eqs[CLASSES[0]].disc.size} unknowns, {eqs[CLASSES[0]].disc.x.size} nodes); "
                     f"P agrees between classes to {spread:.0e}")
        header = f"  {'class':<22}" + "".join(f"{'kernels λ=' + str(s):>15}{'solve λ=' + str(s):>15}"
                                              for s in STRETCHES)
        header += f"{'trace/point':>14}"
        lines.append(header)
        base = CLASSES[0]
        for name in CLASSES:
            cells = ""
            for s in STRETCHES:
                for what in ("kernels", "solve"):
                    t = best[(name, what, s)]
                    cells += f"{t * 1e6:9.0f} us{'':3}" if name == base else \
                        f"{t * 1e6:7.0f} us {t / best[(base, what, s)]:4.1f}x"
            t = best[(name, "trace")]
            cells += f"{t * 1e6:9.0f} us" + ("" if name == base else f" {t / best[(base, 'trace')]:3.1f}x")
            lines.append(f"  {name:<22}{cells}")
        lines.append(f"  (trace: {best[(base, 'trace_points')]} points from 1.01 to 3.0 at step 0.02)")
        lines.append("")
        print("\n".join(lines[-(len(CLASSES) + 4):]), flush=True)
    lines.append("Hessian kernel alone (energy_hessian_nodes on 20000 nodes, CPU time per node):")
    eqs = {name: equilibrium(scene, 40, name) for name in CLASSES}
    X = sphere_X(eqs[CLASSES[0]], 2.0, scene.material)
    per_node = {name: throughput(eq, X) for name, eq in eqs.items()}
    for name in CLASSES:
        lines.append(f"  {name:<22}{per_node[name] * 1e9:8.0f} ns/node  {per_node[name] / per_node[CLASSES[0]]:4.1f}x")
    lines.append("")
    general, special = CLASSES[-1], CLASSES[0]
    ratios = {what: [rows[d][(general, what, s)] / rows[d][(special, what, s)] for d in DEGREES for s in STRETCHES]
              for what in ("kernels", "solve")}
    ratios["trace"] = [rows[d][(general, "trace")] / rows[d][(special, "trace")] for d in DEGREES]
    lines.append("ratio general / specialised (ogden_general_field at M = 0 over ogden_spom1), min–max over degrees "
                 f"{DEGREES} and λ* {STRETCHES}:")
    lines.append(f"  {'Hessian kernel per node':<36} {per_node[general] / per_node[special]:.1f}x")
    for what, label in (("kernels", "node kernels (gradient + Hessian)"), ("solve", "point solve (Newton)"),
                        ("trace", "continuation per point")):
        lines.append(f"  {label:<36} {min(ratios[what]):.1f}x – {max(ratios[what]):.1f}x "
                     f"(median {np.median(ratios[what]):.1f}x)")
    lines.append(f"total wall time {time.perf_counter() - t_start:.0f} s")
    print("\n".join(lines[-10:]))
    wp.RESULTS.mkdir(parents=True, exist_ok=True)
    (wp.RESULTS / "specialisation.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
