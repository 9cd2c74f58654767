"""The tube over (S, φ) (tube/surface/, docs/tubes.md "The tube over (S, φ)"): the switched point against the
discretisation, and what an evaluation costs.

SPOM1, L = 10, sliding closed ends: the bulge branch to V/V0 = 5 at each degree, its first located m = 1 zero (the
lateral buckle of the bulge), and the point of amplitude ε = 0.1 along its critical mode (tube/surface/switching.py)
with the orders (0, 1, 2) at the default n_phi, with the order 3 added, and with n_phi doubled: P − P_0 and its
change. Then the CPU of one residual and one Hessian of the surface (orders 0, 1, 2; sum-factorised over φ,
tube/surface/basis.py ``hessian``) against the same Hessian from dense node maps (the first version's assembly, rebuilt here from the
basis' factors; their difference printed) and one Jacobian of the interval discretisation at the same state (best of
``REPEATS``), one run, with the load average.

    OMP_NUM_THREADS=1 python benchmarks/tube_surface.py [--degrees 20 30 40]

With ``--refinement`` instead: the cost of the refinement along the branch (tube/surface/resolution.py), one run.
SPOM1's bulge's lateral buckle (tests/test_tube_surface.py ``located_zeros("bulge")``: degree 20, its first m = 1
zero) traced to ``--points`` points before (solver.max_error = 1e-2: no point refined, the orders (0, 1, 2) at the
parent's degree, as before the refinement) and after (the scene's 1e-9): CPU, the final basis, the largest estimate,
P at the last point. Then ``balloon-cg run scenes/tube_spom1_L10.toml`` with ``[surface] branches`` "none" and
"first" (each in a child process, its CPU from getrusage), their ratio, and what "first" traced.

    OMP_NUM_THREADS=1 python benchmarks/tube_surface.py --refinement [--points 30]
"""
import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_tube_surface import located_zeros, tube_scene  # noqa: E402

from balloon_cg.galerkin.equilibrium import Equilibrium  # noqa: E402
from balloon_cg.galerkin.interval import Mirror  # noqa: E402
from balloon_cg.tube import azimuthal  # noqa: E402
from balloon_cg.tube.azimuthal_crossings import crossings  # noqa: E402
from balloon_cg.tube.bulge import bulge_branch  # noqa: E402
from balloon_cg.tube.primary import primary_branch  # noqa: E402
from balloon_cg.io.tube_file import read_tube_run  # noqa: E402
from balloon_cg.tube.surface.basis import TubeSurfaceBasis  # noqa: E402
from balloon_cg.tube.surface.branch import traced_branch  # noqa: E402
from balloon_cg.tube.surface.equilibrium import MeridianSurfaceEquilibrium  # noqa: E402
from balloon_cg.tube.surface.switching import switched_point  # noqa: E402

AMPLITUDE = 0.1
REPEATS = 5


def cpu(call) -> float:
    """The best CPU seconds of REPEATS calls."""
    best = np.inf
    for _ in range(REPEATS):
        start = time.process_time()
        call()
        best = min(best, time.process_time() - start)
    return best


def dense_hessian(basis: TubeSurfaceBasis, pointwise: np.ndarray) -> np.ndarray:
    """Σ_ab T_aᵀ diag(h_ab) T_b with the dense node maps T_a[(q, k), j] = F_a[q, j] g_a[k] (9 × nodes × unknowns)."""
    maps = np.zeros((9, basis.disc.x.size, basis.n_phi, basis.size))
    for m, (F, g) in zip(basis.orders, basis.factors):
        maps[:, :, :, basis.block(m)] = F[:, :, None, :] * g[:, None, :, None]
    maps = maps.reshape(9, -1, basis.size)
    scaled = np.einsum("abn,bnj->anj", pointwise, maps)
    return maps.reshape(-1, basis.size).T @ scaled.reshape(-1, basis.size)


def main(degrees) -> None:
    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f}; OMP_NUM_THREADS="
          f"{os.environ.get('OMP_NUM_THREADS', 'unset')}; SPOM1, L = 10, ε = {AMPLITUDE}")
    print(f"{'N':>3} {'P_0':>14} {'V/V0':>8} {'P − P_0':>13} {'(P−P_0)/ε²':>12} {'+ order 3':>10} "
          f"{'2 n_phi':>10} {'Newton it':>9}")
    costs = []
    for degree in degrees:
        scene = tube_scene("SPOM1", 10.0).with_overrides({"solver.degree": degree, "continuation.stop_stretch": 5.0})
        primary = primary_branch(scene)
        branch = bulge_branch(scene, primary, primary.branch_points(Mirror.ODD)[0], stop_volume=5.0 * np.pi * 10.0)
        eq = Equilibrium(scene, branch.disc)
        modes = azimuthal.branch_modes(eq, np.column_stack([branch.states, branch.pressure]), branch.params, 1)
        zero = [c for c in crossings(scene, branch, modes) if c.pressure > 0.5][0]
        point = switched_point(scene, branch.disc, zero, AMPLITUDE, branch.params)
        more = switched_point(scene, branch.disc, zero, AMPLITUDE, branch.params, orders=(0, 1, 2, 3))
        finer = switched_point(scene, branch.disc, zero, AMPLITUDE, branch.params,
                               n_phi=2 * point.basis.n_phi)
        rise = point.pressure - zero.pressure
        print(f"{degree:3d} {zero.pressure:14.10f} {zero.volume:8.5f} {rise:13.6e} {rise / AMPLITUDE**2:12.8f} "
              f"{more.pressure - point.pressure:10.1e} {finer.pressure - point.pressure:10.1e} {point.iterations:9d}")
        basis = TubeSurfaceBasis(branch.disc, (0, 1, 2))
        surface = MeridianSurfaceEquilibrium(scene, basis)
        params = branch.params.with_value("P", point.pressure)
        rows = surface.node_hessian(point.c, params)
        factorised = surface.hessian(point.c, params)
        gap = np.max(np.abs(dense_hessian(basis, rows) - factorised)) / np.max(np.abs(factorised))
        costs.append((degree, basis.size, branch.disc.size, basis.disc.x.size * basis.n_phi,
                      cpu(lambda: surface.residual(point.c, params)), cpu(lambda: surface.hessian(point.c, params)),
                      cpu(lambda: dense_hessian(basis, rows)), gap, cpu(lambda: eq.jacobian(zero.u, params))))
    print(f"\n{'N':>3} {'unknowns':>8} {'interval':>8} {'nodes':>6} {'residual s':>11} {'Hessian s':>10} "
          f"{'dense s':>9} {'dense/H':>7} {'|dense − H|':>11} {'interval J s':>12} {'H / J':>6}")
    for degree, size, interval, nodes, residual, hessian, dense, gap, jacobian in costs:
        print(f"{degree:3d} {size:8d} {interval:8d} {nodes:6d} {residual:11.2e} {hessian:10.2e} {dense:9.2e} "
              f"{dense / hessian:7.1f} {gap:11.1e} {jacobian:12.2e} {hessian / jacobian:6.0f}")
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


SCENE = Path(__file__).resolve().parents[1] / "scenes" / "tube_spom1_L10.toml"


def child_cpu(command: list) -> float:
    """The CPU seconds (user + system) of ``command`` run to its end in a child process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime


def refinement(points: int) -> None:
    """The ``--refinement`` tables (module docstring)."""
    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f}; OMP_NUM_THREADS="
          f"{os.environ.get('OMP_NUM_THREADS', 'unset')}; SPOM1's bulge's lateral buckle, {points} points")
    scene, parent, found = located_zeros("bulge")
    print(f"{'':>7} {'max_error':>9} {'CPU s':>7} {'degree':>6} {'orders':>6} {'largest est.':>12} "
          f"{'est. > max_error':>16} {'limited':>7} {'P at the last':>15} {'stop':>10}")
    cpus = {}
    for what, max_error in (("before", 1e-2), ("after", scene.solver.max_error)):
        at = scene.with_overrides({"solver.max_error": max_error})
        start = time.process_time()
        branch = traced_branch(at, parent.disc, found[0], parent.params, max_points=points)
        cpus[what] = time.process_time() - start
        past = int(np.sum(branch.error_estimate[1:] > scene.solver.max_error))
        print(f"{what:>7} {max_error:9.0e} {cpus[what]:7.1f} {branch.basis.disc.degree:6d} "
              f"{branch.basis.orders[-1]:6d} {branch.error_estimate[1:].max():12.1e} {past:16d} "
              f"{str(branch.limited):>7} {branch.pressure[-1]:15.10f} {branch.stop.code.value:>10}")
    print(f"after / before: {cpus['after'] / cpus['before']:.1f}")
    print(f"\nballoon-cg run {SCENE.name} (child processes, CPU from getrusage); load average "
          f"{os.getloadavg()[0]:.2f}")
    runs = {}
    with tempfile.TemporaryDirectory() as folder:
        for asked in ("none", "first"):
            out = Path(folder) / f"{asked}.h5"
            runs[asked] = child_cpu([sys.executable, "-m", "balloon_cg", "run", str(SCENE), "--quiet", "--force",
                                     "-o", str(out), "--set", f"surface.branches={asked}"])
            traced = [f"{name} ({len(b['pressure'])} points)"
                      for name, b in read_tube_run(out)["surface_branches"].items()]
            print(f"  surface.branches = {asked!r:8} CPU {runs[asked]:6.1f} s; surface branches traced: "
                  f"{', '.join(traced) or 'none'}")
    print(f"  first / none: {runs['first'] / runs['none']:.2f}")
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--degrees", type=int, nargs="+", default=[20, 30, 40])
    parser.add_argument("--refinement", action="store_true", help="the cost of the refinement along the branch")
    parser.add_argument("--points", type=int, default=30)
    arguments = parser.parse_args()
    if arguments.refinement:
        refinement(arguments.points)
    else:
        main(arguments.degrees)
