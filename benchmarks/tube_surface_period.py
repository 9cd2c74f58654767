"""Benchmark: the tube over (S, φ) summed over one period 2π/g in φ (analysis/surface/meridian/basis.py ``phi_nodes``: the
orders 0, g, 2g, … of a branch born at an m = g zero) against the whole circle (the code before: phi_nodes = n_phi),
one process, the two alternating (a switch: the property patched), BLAS held to one thread.

Per case (SPOM1 tube, L = 10, in the coil of scenes/tube_spom1_L10_coil.toml at M = 0.03; a random state near the
reference, the k-th coefficient of every field and order 0.005/(k + 1) random): the CPU seconds of EVALS residuals and Hessians (what each Newton
step and each stability reading costs), the minimum over REPS alternating repetitions, whole over period, and the
largest difference of the two Hessians over its largest entry (the same sums: rounding). The load average is
printed before and after.

    python benchmarks/tube_surface_period.py
"""
import os
import time
from pathlib import Path

import numpy as np

from balloon_cg.galerkin.interval import IntervalDiscretisation
from balloon_cg.numerics.threads import limited_blas
from balloon_cg.scene import load_scene
from balloon_cg.tube.primary import scene_parameters
from balloon_cg.tube.surface import basis as tube_basis, meridian
from balloon_cg.tube.surface.basis import TubeSurfaceBasis
from balloon_cg.tube.surface.equilibrium import MeridianSurfaceEquilibrium

ROOT = Path(__file__).resolve().parents[1]
REPS, EVALS = 5, 3
CASES = ((30, (0, 1, 2)), (30, (0, 2, 4)), (30, tuple(range(0, 13, 2))), (60, (0, 2, 4)), (30, (0, 3, 6)))
PERIOD = meridian.MeridianSurfaceBasis.phi_nodes


def whole(basis) -> int:
    """The code before: every one of the n_phi nodes."""
    return basis.n_phi


def cost(scene, degree: int, orders: tuple, nodes) -> tuple:
    """(CPU seconds of EVALS residuals and Hessians, the Hessian) with ``phi_nodes`` = ``nodes``."""
    meridian.MeridianSurfaceBasis.phi_nodes = property(nodes)
    tube_basis._tables.cache_clear()  # built again for this node count
    disc = IntervalDiscretisation(degree, 10.0, ends=scene.geometry.ends)
    basis = TubeSurfaceBasis(disc, orders)
    surface = MeridianSurfaceEquilibrium(scene, basis)
    rng = np.random.default_rng(1)
    c = basis.axisymmetric(disc.reference() + 0.005 * rng.standard_normal(disc.size) / (1 + np.arange(disc.size)))
    for m in orders[1:]:
        c = basis.with_mode(c, m, 0.005 * rng.standard_normal(basis.mode_size) / (1 + np.arange(basis.mode_size)))
    params = scene_parameters(scene, 1.3)
    surface.hessian(c, params)  # warm: tables and kernels
    start = time.process_time()
    for _ in range(EVALS):
        surface.residual(c, params)
        H = surface.hessian(c, params)
    return time.process_time() - start, H


@limited_blas
def main():
    scene = load_scene(ROOT / "scenes" / "tube_spom1_L10_coil.toml").with_overrides({"field.M": 0.03})
    print(f"load average before: {os.getloadavg()}")
    print(f"{'degree':>6} {'orders':<24} {'n_phi':>5} {'nodes':>5} {'whole s':>8} {'period s':>8} {'ratio':>6} "
          f"{'|ΔH|/|H|':>9}")
    for degree, orders in CASES:
        times = {"whole": [], "period": []}
        for _ in range(REPS):
            for name, nodes in (("whole", whole), ("period", PERIOD.fget)):
                seconds, H = cost(scene, degree, orders, nodes)
                times[name].append(seconds)
                if name == "whole":
                    reference = H
        difference = np.max(np.abs(H - reference)) / np.max(np.abs(reference))
        basis = TubeSurfaceBasis(IntervalDiscretisation(degree, 10.0), orders)
        meridian.MeridianSurfaceBasis.phi_nodes = PERIOD
        a, b = min(times["whole"]), min(times["period"])
        print(f"{degree:>6} {str(orders):<24} {basis.n_phi:>5} {basis.phi_nodes:>5} {a:>8.3f} {b:>8.3f} "
              f"{a / b:>6.2f} {difference:>9.1e}", flush=True)
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
