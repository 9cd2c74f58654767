"""Convergence of a whole-sphere state in the polar degree L and the azimuthal order M, where it is hardest: the
last point of the m = 1 branch of the shipped two-coil scene (M = 0.002), the membrane ~0.11 from the wires on one
side. That point is solved again at its P on bases (L, M) with the branch's final wire map, from its own state
transferred; the centroid offset x_c, the pole stretch λ(0) and the smallest wire gap are compared with the finest
basis. Run against the installed package: `make install-dev && python benchmarks/surface_convergence.py`
(about ten minutes: the branch is traced first, its stability is not computed). Results:
benchmarks/results/surface_convergence.txt, docs/numerics.md §4b.
"""
from dataclasses import replace
from pathlib import Path

import numpy as np

from balloon_cg.analysis.surface import branches as sb
from balloon_cg.analysis.picture import analyse
from balloon_cg.model.field import wire_distance
from balloon_cg.scene import load_scene
from balloon_cg.surface.embedding import transfer
from balloon_cg.surface.measures import measures, tails

SCENE = Path(__file__).resolve().parent.parent / "scenes" / "spom1_two_coils_M0.002.toml"
BASES = [(48, 36), (56, 36), (64, 36), (72, 36), (64, 24), (64, 28), (64, 32), (64, 40), (64, 44), (88, 52)]
REFERENCE = (88, 52)


def main():
    scene = load_scene(SCENE).with_overrides({"surface.branches": "none"})
    primary = analyse(scene, pear=False).primary
    bp = next(s for s in primary.branch_points() if s.m == 1 and s.block.held)
    sb.assess = lambda branch, traced: None  # the trace only: stability is not what is measured here
    branch = sb.trace_surface(primary, 0, bp, 1.0, "m1", scene.surface.max_points)
    c, P = branch.coefficients[-1], branch.values[-1]
    coils = [[k.radius, k.height, k.current] for k in scene.field.coils]
    print(f"# the last point of the two-coil m = 1 branch: point {len(branch.values) - 1}, P = {P:.10f}, traced on "
          f"degree {branch.basis.degree}, order {branch.basis.order} ({branch.basis.size} unknowns); "
          f"stop: {branch.special[-1].stop.message}")
    found = {}
    for L, M in BASES:
        basis = replace(branch.basis, degree=L, order=M, n_theta=0, n_phi=0)
        trace = sb.SurfaceTrace(scene, basis, branch.params.with_value("P", P))
        result = trace.system.solve(trace.system.point(transfer(branch.basis, c, basis), P), scene.solver.tol,
                                    scene.solver.max_newton)
        if not result.converged:
            print(f"  L = {L}, M = {M}: Newton did not converge ({result.message})")
            continue
        state = trace.system.coefficients(result.x)
        m = measures(basis, state)
        x = trace.eq.node_values(state)["state"][:3]
        gap = float(wire_distance(np.hypot(x[0], x[1]), x[2], coils).min())
        found[L, M] = (basis.size, tails(basis, state), m["centroid"][0], m["lam_top"], gap)
    reference = found[REFERENCE]
    print("   L   M  unknowns  θ-tail   φ-tail   |Δx_c|    |Δλ(0)|   x_c")
    for (L, M), (size, (theta, phi), xc, lam, gap) in found.items():
        print(f"  {L:3d} {M:3d} {size:8d}  {theta:.1e}  {phi:.1e}  {abs(xc - reference[2]):.1e}  "
              f"{abs(lam - reference[3]):.1e}  {xc:.12f}")
    print(f"   the smallest node gap to a wire: {reference[4]:.4f}")


if __name__ == "__main__":
    main()
