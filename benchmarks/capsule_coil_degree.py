"""Why a capsule's degree climbs in a coil's field: the coil's H² along the membrane, not the caps' joins.

benchmarks/capsule_single_coil.toml (SPOM1 capsule of length 2, one coil of radius 4 around its middle, M = 0.002):
its primary branch traced in P (``trace_primary``, no stability) on the shared basis, at M = 0 (the coil kept for
the wire gap only), and with the cylinder cut into elements of at most 1 radius of graded degrees
(``element_length = 1``, ``element_degrees = "graded"``): points, the stop, the last pole stretch and gap, the
storage degrees. Then per point of the shared M = 0.002 branch (on the basis of its own degree): the gap to the wire
(at the equator, where the bulge is), η' = |dx/dθ| there (ρ' = 0 at the equator), the cylinder's and the caps' tail
estimates (``Discretisation.element_tails``), the cylinder series' fitted decay per degree r (``geometric_fit``),
the decay 1/r_B that a singularity at θ = π/2 ± i·gap/η' predicts (H² of a loop is singular where
(ρ − a)² + (z − h)² = 0: on the deformed meridian near the equator, ρ ≈ ρ_eq, z ≈ η'(θ − π/2), so at that complex
θ; in the cylinder's coordinate ξ ∈ [−1, 1] (θ = π/2 − ξ·(π/2 − θj)) it lies at iε, ε = gap/(η'(π/2 − θj)), and a
Legendre series decays as r_B^−k, r_B = ε + sqrt(1 + ε²)), and the decay of H²'s own Legendre coefficients in ξ
along the deformed cylinder (600 Gauss nodes, fitted where they lie between 1e-11 and 1e-3).

    python benchmarks/capsule_coil_degree.py > benchmarks/results/capsule_coil_degree.txt
"""
import os
from dataclasses import replace
from pathlib import Path

import numpy as np
from numpy.polynomial import legendre

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.wires import wire_gap
from balloon_cg.galerkin.discretisation import geometric_fit
from balloon_cg.model.field import coil_table, field_squared_nodes
from balloon_cg.model.meridian import capsule_rate
from balloon_cg.scene import load_scene

SCENE = Path(__file__).resolve().parent / "capsule_single_coil.toml"
VARIANTS = {"shared, M = 0.002": {}, "shared, M = 0": {"field.M": 0.0},
            "3 cylinder elements graded, M = 0.002": {"geometry.element_length": 1.0,
                                                      "geometry.element_degrees": "graded"}}


def field_decay(disc, u, coils, half_span: float) -> float:
    """Decay per degree of the Legendre coefficients of H²(ρ(ξ), z(ξ)) in the cylinder's ξ (module docstring)."""
    xi, w = legendre.leggauss(600)
    lam2, _, eta, _ = disc.evaluate(u, np.pi / 2 - xi * half_span)
    out = np.empty((6, xi.size))
    field_squared_nodes(np.ascontiguousarray(lam2), np.ascontiguousarray(eta), coils, out)  # R = 1: ρ = λ2
    k = np.arange(0, 400, 2)  # H² is even in ξ on an equator-symmetric state
    c = np.abs((2 * k + 1) / 2 * (legendre.legvander(xi, 399)[:, k].T @ (w * out[0])))
    c /= c[0]
    window = (c > 1e-11) & (c < 1e-3)
    return float(np.exp(np.polyfit(k[window], np.log(c[window]), 1)[0])) if window.sum() > 3 else float("nan")


def main() -> None:
    print(f"load average before: {os.getloadavg()}")
    base = load_scene(SCENE)
    branches = {}
    print("| basis | points | stop | last pole stretch | last gap | storage degree (groups) |")
    print("|---|---|---|---|---|---|")
    for name, overrides in VARIANTS.items():
        scene = base.with_overrides(overrides) if overrides else base
        b = branches[name] = trace_primary(scene, down=False)
        north, X = b.disc.pole_rows()["lam2_top"], b.X[-1]
        gap, _ = wire_gap(b.disc, X[:-1], scene.field.coils, scene.geometry, 4001)
        print(f"| {name} | {len(b.X)} | {b.legs[-1].stop.code.value} | {X[:-1] @ north:.4f} | {gap:.4f} | "
              f"{b.disc.degree} {b.disc.element_degrees or ''} |")
    b = branches["shared, M = 0.002"]
    scene, coils = b.scene, coil_table([(c.radius, c.height, c.current) for c in b.scene.field.coils])
    half_span = np.pi / 2 - np.pi / (2 * capsule_rate(scene.geometry))
    north = b.disc.pole_rows()["lam2_top"]
    print("\nshared basis, M = 0.002, per point on the basis of its own degree:")
    print("| point | P | pole stretch | degree | gap | η'(π/2) | tail cylinder | tail caps | r cylinder | 1/r_B | r of H² |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for n in [0, 12, 24, 30, 36, 42, 45, 48, 54, 60, 66, len(b.X) - 1]:
        disc = replace(b.disc, degree=int(b.degree[n]), quadrature=0)
        u = b.disc.transfer(b.X[n], disc)[:-1]
        lam2, _, _, deta = disc.evaluate(u, np.array([np.pi / 2]))
        gap = coils[0, 0] - lam2[0]
        epsilon = gap / (abs(deta[0]) * half_span)
        cylinder, caps = disc.element_tails(u)
        _, rate = geometric_fit(disc.element_envelopes(u)[0])
        print(f"| {n} | {b.X[n, -1]:.4f} | {b.X[n, :-1] @ north:.4f} | {disc.degree} | {gap:.3f} | {abs(deta[0]):.3f} | "
              f"{cylinder:.1e} | {caps:.1e} | {rate:.4f} | {1 / (epsilon + np.hypot(1, epsilon)):.4f} | "
              f"{field_decay(disc, u, coils, half_span):.4f} |")
    print(f"\nload average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
