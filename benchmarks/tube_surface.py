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
"""
import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_tube_surface import tube_scene  # noqa: E402

from balloon_cg.galerkin.equilibrium import Equilibrium  # noqa: E402
from balloon_cg.galerkin.interval import Mirror  # noqa: E402
from balloon_cg.tube import azimuthal  # noqa: E402
from balloon_cg.tube.azimuthal_crossings import crossings  # noqa: E402
from balloon_cg.tube.bulge import bulge_branch  # noqa: E402
from balloon_cg.tube.primary import primary_branch  # noqa: E402
from balloon_cg.tube.surface.basis import TubeSurfaceBasis  # noqa: E402
from balloon_cg.tube.surface.equilibrium import TubeSurfaceEquilibrium  # noqa: E402
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
        branch = bulge_branch(scene, primary, primary.branch_points(Mirror.ODD)[0], stop_volume=5.0)
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
        surface = TubeSurfaceEquilibrium(scene, basis)
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


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--degrees", type=int, nargs="+", default=[20, 30, 40])
    main(parser.parse_args().degrees)
