"""Critical values from two-parameter continuation of a pear pitchfork (balloon_cg.analysis.critical.pitchfork_curve).

1. SPOM1 at M = 0, continued in α1 (μ1 = (4 − Σ_{i≥2} μ_i α_i)/α1): the critical α1 where the isola's two
   pitchforks merge (fold of the curve in α1), against the closed form of sphere_modes (α1 where the minimum over
   λ of the pear condition touches zero), and the worst relative stretch error of the curve points against
   sphere_modes.bifurcation_stretches.
2. SPOM1 single coil (scenes/spom1_single_coil.toml, coil a = 4 at h = 0), continued in M from the lower pitchfork
   at the scene's M: the critical M, then a plain check by sweep: the primary branch at M* (1 ∓ 1e-3) has two /
   no pear branch points.
Run: python benchmarks/two_parameter.py  (output kept in benchmarks/results/two_parameter.txt)
"""
import sys
import time
from pathlib import Path

import numpy as np

from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.points import branch_points as bifurcation
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.scene.materials import get_preset
from balloon_cg.scene import load_scene, parse_scene
from balloon_cg.analysis.stability.axisymmetric import SecondVariation
from balloon_cg.analysis.critical.pitchfork_curve import continue_branch_point, sphere_critical_alpha1, sphere_pear_stretches

ROOT = Path(__file__).resolve().parent.parent
SINGLE_COIL = ROOT / "scenes" / "spom1_single_coil.toml"


def pear_points(branch):
    """Located pear branch points of a symmetric primary branch: sign changes of the lowest eigenvalue of the
    odd (pear) block only (the full assessment with azimuthal blocks is not needed here)."""
    variation = SecondVariation(equilibrium_of(branch), branch.disc.degree)
    odd = bifurcation.block_indices(variation, "odd_held", False)
    lowest = np.array([variation._lowest(variation.matrices(X[:-1], branch.params.with_value("P", X[-1]))[0],
                                         odd)[0] for X in branch.X])
    events = [(int(i), "odd_held", 0) for i in np.flatnonzero(np.sign(lowest[:-1]) != np.sign(lowest[1:]))]
    return [bifurcation.locate(branch, *e) for e in events]


def alpha1_case():
    t0 = time.perf_counter()
    scene = parse_scene('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 4.0\n', name="SPOM1")
    branch = trace_primary(scene, down=False)
    bps = pear_points(branch)
    t1 = time.perf_counter()
    curve = continue_branch_point(branch, bps[0], "alpha1")
    t2 = time.perf_counter()
    q, P, lam = curve.critical
    expected, lam_expected = sphere_critical_alpha1(get_preset("SPOM1"), 1.3, 2.5)
    errors = []
    for a1, stretch in zip(curve.q, curve.pole_stretch):
        roots = sphere_pear_stretches(get_preset("SPOM1"), a1)
        if len(roots):
            errors.append(np.min(np.abs(roots - stretch)) / stretch)
    print("SPOM1, M = 0, continuation in alpha1 (mu1 from sum mu_i alpha_i = 4), Legendre degree "
          f"{branch.disc.degree}")
    print(f"  critical alpha1 (merge of the two pear pitchforks) = {q:.12f}  at P = {P:.10f}, pole stretch "
          f"{lam:.8f}")
    print(f"  closed form (sphere_modes)                        = {expected:.12f}  (stretch {lam_expected:.8f})")
    print(f"  relative difference {abs(q / expected - 1):.2e}; curve points {len(curve.X)}, worst stretch error "
          f"vs bifurcation_stretches {max(errors):.1e} over {len(errors)} points")
    print(f"  stop: {curve.stop_reason}")
    print(f"  time: primary + locate {t1 - t0:.1f} s, two-parameter curve {t2 - t1:.1f} s")


def field_case(check: bool = True):
    t0 = time.perf_counter()
    scene = load_scene(SINGLE_COIL).with_overrides({"continuation.stop_stretch": 3.7})
    branch = trace_primary(scene, down=False)
    bps = pear_points(branch)
    t1 = time.perf_counter()
    curve = continue_branch_point(branch, bps[0], "M")
    t2 = time.perf_counter()
    q, P, lam = curve.critical
    print(f"SPOM1 single coil (a = 4, h = 0), continuation in M from M = {scene.field.M:g}, Legendre degree "
          f"{branch.disc.degree}")
    print("  pear pitchforks at the scene's M: " + "; ".join(
        f"stretch {branch.pole_values(bp.X)['lam2_top'][0]:.6f}, P {bp.X[-1]:.6f}" for bp in bps))
    print(f"  critical M (merge of the two pear pitchforks) = {q:.10f}  at P = {P:.8f}, pole stretch {lam:.6f}")
    print(f"  curve points {len(curve.X)}, largest spectral tail "
          f"{max(branch.disc.tail(X[:branch.disc.size]) for X in curve.X):.1e}; stop: {curve.stop_reason}")
    print(f"  time: primary + locate {t1 - t0:.1f} s, two-parameter curve {t2 - t1:.1f} s")
    if check:
        # the field cannot be switched on at the default start stretch 1.01 for M ≈ 4 (Newton fails near
        # M ≈ 1 at fixed P): start at the merge stretch and trace both ways over [1.5, 2.8]
        for M in (q * (1 - 1e-3), q * (1 + 1e-3)):
            s = time.perf_counter()
            probe = load_scene(SINGLE_COIL).with_overrides({
                "field.M": M, "continuation.start_stretch": round(lam, 1), "continuation.min_stretch": 1.5,
                "continuation.stop_stretch": 2.8, "continuation.step_max": 0.05, "solver.max_degree": 80})
            primary = trace_primary(probe)
            found = pear_points(primary)
            print(f"  sweep check M = {M:.8f}: {len(found)} pear branch points"
                  + "".join(f"; stretch {primary.pole_values(bp.X)['lam2_top'][0]:.6f}, P {bp.X[-1]:.6f}"
                            for bp in found)
                  + f"  (primary: {len(primary.X)} points, stretch {primary.pole_values()['lam2_top'].min():.3f}"
                  f"..{primary.pole_values()['lam2_top'].max():.3f}, {time.perf_counter() - s:.1f} s)")


def main():
    alpha1_case()
    if "--no-field" not in sys.argv:
        field_case()


if __name__ == "__main__":
    main()
