"""Stiff and extreme cases, the slow versions of tests/test_extremes.py: what each does and what limits it.

Every case either converges (residual, exact or refinement check reported) or stops with a diagnostic; the
report says which, and whether any stored point holds a NaN. Every loop is bounded (max_points, max_degree,
Newton iterations).

Run: python benchmarks/extremes.py   (writes benchmarks/results/extremes.txt)
"""
import time
from pathlib import Path

import numpy as np

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.branches.wires import wire_gap
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Parameters
from balloon_cg.galerkin.point_solve import constrained_newton
from balloon_cg.scene import load_scene, parse_scene
from balloon_cg.model.shooting import shoot_symmetric
from balloon_cg.model.sphere import sphere_pressure

import work_precision as wp

ROOT = Path(__file__).resolve().parent.parent

LINES = []


def say(text=""):
    print(text, flush=True)
    LINES.append(text)


def two_coils(**overrides):
    return load_scene(ROOT / "scenes" / "spom1_two_coils_M0.002.toml").with_overrides(overrides)


def summary(branch, t0):
    lam = branch.pole_values()["lam2_top"]
    degrees = sorted({int(d) for d in branch.degree})
    return (f"{len(branch.X)} points, λ ∈ [1 + {lam.min() - 1:.3g}, {lam.max():.6g}], degrees {degrees}, "
            f"max residual {branch.residual.max():.1e}, max tail {branch.error_estimate.max():.1e}, "
            f"NaN stored: {bool(np.isnan(branch.X).any())}, {time.perf_counter() - t0:.1f} s\n"
            f"    stop: {branch.stop_reason}")


def refined(branch, factor=1.5):
    X = branch.X[-1]
    lam = branch.pole_values()["lam2_top"][-1]
    result, _ = constrained_newton(branch.scene, int(branch.disc.degree * factor), X, branch.disc, lam,
                                   branch.params)
    return f"refinement × {factor}: P changes by {abs(result.x[-1] / X[-1] - 1):.1e} ({result.message})"


def sphere_error(branch):
    lam = branch.pole_values()["lam2_top"]
    return np.abs(branch.pressure / sphere_pressure(branch.scene.material, lam) - 1).max()


def pole_stretch_10():
    say("1. Pole stretch up to 10, SPOM1, M = 0 (exact sphere)")
    for preset in ("SPOM1", "TPOM2", "neo-Hookean"):
        t0 = time.perf_counter()
        branch = trace_primary(parse_scene(f'[material]\npreset = "{preset}"\n[continuation]\nstop_stretch = 10.0\n'),
                               down=False)
        say(f"  {preset}: {summary(branch, t0)}")
        say(f"    max |P/P_sphere − 1| = {sphere_error(branch):.1e}; {refined(branch)}")


def extreme_exponents():
    say("2. One-term Ogden, μα = 4: α = 8 (μ = 0.5) and α = −4 (μ = −1), M = 0 (exact sphere)")
    for mu, alpha in ((0.5, 8.0), (-1.0, -4.0)):
        scene = parse_scene(f"[material]\nmu = [{mu}]\nalpha = [{alpha}]\n[continuation]\nstop_stretch = 5.0\n")
        t0 = time.perf_counter()
        branch = trace_primary(scene, down=False)
        say(f"  α = {alpha}, default steps: {summary(branch, t0)}")
        say(f"    P at the end {branch.pressure[-1]:.6g}; max |P/P_sphere − 1| = {sphere_error(branch):.1e}; "
            f"{refined(branch)}")


def tiny_field():
    say("3. M → 0 with the paper's two coils: P(λ = 1.5) − P_sphere = O(M)")
    P0 = sphere_pressure(two_coils().material, 1.5)
    for M in (1e-9, 1e-7, 1e-5, 1e-3):
        t0 = time.perf_counter()
        branch = trace_primary(two_coils(**{"field.M": M}), stop_stretch=1.5, down=False)
        say(f"  M = {M:g}: (P − P0)/M = {(branch.pressure[-1] - P0) / M:.8f}, residual {branch.residual.max():.1e}, "
            f"NaN: {bool(np.isnan(branch.X).any())}, {time.perf_counter() - t0:.1f} s")


def far_coils():
    say("4. The paper's opposed pair scaled by L (M = 0.002): shift of P(λ = 1.5) from the M = 0 sphere")
    P0 = sphere_pressure(two_coils().material, 1.5)
    for L in (1.0, 2.0, 5.0, 10.0, 20.0):
        scene = two_coils(**{"field.coils[0].radius": 1.7321 * L, "field.coils[0].height": L,
                             "field.coils[1].radius": 1.7321 * L, "field.coils[1].height": -L})
        branch = trace_primary(scene, stop_stretch=1.5, down=False)
        shift = branch.pressure[-1] / P0 - 1
        say(f"  L = {L:4g}: (P − P0)/P0 = {shift:.4e}, × L⁴ = {shift * L**4:.4e}, degrees {sorted(set(branch.degree))}")


def nearly_undeformed():
    say("5. Nearly undeformed: start/min stretch 1 + 1e-8 … 1 + 1e-15 (the first-order system is singular at λ = 1)")
    for start, low in ((1 + 2e-8, 1 + 1e-8), (1 + 1e-12, 1 + 5e-13), (1 + 1e-15, 1 + 5e-16)):
        for label, scene in (("M = 0", parse_scene(f'[material]\npreset = "SPOM1"\n[continuation]\n'
                                                  f"start_stretch = {start!r}\nmin_stretch = {low!r}\n"
                                                  "stop_stretch = 1.2\n")),
                             ("two coils", two_coils(**{"continuation.start_stretch": start,
                                                        "continuation.min_stretch": low,
                                                        "continuation.stop_stretch": 1.2}))):
            t0 = time.perf_counter()
            try:
                branch = trace_primary(scene)
            except Exception as error:  # a clear stop is an acceptable outcome; report it
                say(f"  start {start!r}, {label}: {type(error).__name__}: {error}")
                continue
            lam = branch.pole_values()["lam2_top"]
            extra = ""
            if not scene.field.coils:
                error = np.abs(branch.pressure - sphere_pressure(scene.material, lam)).max()
                extra = f", max |P − P_sphere| = {error:.1e}"
            say(f"  start {start!r}, {label}: {summary(branch, t0)}{extra}")
    scene = parse_scene('[material]\npreset = "SPOM1"\n')
    disc = Discretisation(40, True, True)
    for lam in (1 + 1e-8, 1 + 1e-12):
        a, b = np.zeros(41), np.zeros(41)
        a[0], a[2], b[1] = lam * (1 + 1e-3), 1e-4, lam
        X0 = np.append(disc.join(a, b), 1.01 * sphere_pressure(scene.material, lam))
        result, _ = constrained_newton(scene, 40, X0, disc, lam, Parameters(0.0))
        exact = sphere_pressure(scene.material, lam)
        say(f"  constrained Newton at λ = 1 + {lam - 1:.0e} from a perturbed sphere: {result.message} in "
            f"{result.iterations} its, P = {result.x[-1]:.3e}, |P − P_sphere| = {abs(result.x[-1] - exact):.1e} "
            f"(relative {abs(result.x[-1] / exact - 1):.1e}), NaN: {bool(np.isnan(result.x).any())}")


def wire_approach():
    say("6. The membrane approaching a wire, wire_gap = 1e-3, adaptive degree (max_error 1e-9, max_degree 320)")
    for name in ("spom1_two_coils_M0.002", "spom1_single_coil"):
        scene = load_scene(ROOT / "scenes" / f"{name}.toml").with_overrides({"continuation.wire_gap": 1e-3})
        t0 = time.perf_counter()
        branch = trace_primary(scene, down=False)
        gaps = [wire_gap(branch.disc, X[:-1], scene.field.coils)[0] for X in branch.X]
        say(f"  {name}: {summary(branch, t0)}")
        say(f"    smallest gap reached {min(gaps):.3g} (last point {gaps[-1]:.3g}) at degree {branch.degree[-1]}, "
            f"basis map {branch.disc.mapping}")
        X = branch.X[-1]
        rows = branch.disc.pole_rows()
        shot = shoot_symmetric(scene, float(rows["lam2_top"] @ X[:-1]), X[-1], float(rows["eta_top"] @ X[:-1]))
        say(f"    last point against shooting at its pole stretch: |P/P_shoot − 1| = {abs(X[-1] / shot.P - 1):.1e} "
            f"({shot.message})")


def stability_basis():
    say("7. Stability basis degree N up to 60 (second variation, two coils M = 0.002, primary branch to λ = 1.8)")
    try:
        from balloon_cg.analysis.stability import axisymmetric as stability
    except ImportError as error:
        say(f"  skipped: {error}")
        return
    branch = trace_primary(two_coils(), stop_stretch=1.8, down=False)
    params = branch.params
    picks = list(range(0, len(branch.X), max(1, len(branch.X) // 5)))
    lowest = {}
    for N in (20, 40, 60):
        variation = stability.SecondVariation(equilibrium_of(branch), N)
        t0 = time.perf_counter()
        results = [variation.assess(branch.X[i][:-1], params.with_value("P", branch.X[i][-1]), True) for i in picks]
        seconds = (time.perf_counter() - t0) / len(picks)
        finite = all(np.all(np.isfinite(v)) for r in results for v in r.blocks.values())
        lowest[N] = np.array([min(r.blocks["odd_held"][0], r.blocks["even"][0]) for r in results])
        flags = "".join("S" if r.stable_pressure else "u" for r in results)
        say(f"  N = {N}: {seconds * 1e3:.0f} ms per point, all eigenvalues finite: {finite}, "
            f"pressure-control flags {flags} at λ = "
            + ", ".join(f"{branch.pole_values()['lam2_top'][i]:.3f}" for i in picks))
    say("  lowest eigenvalue change N = 40 → 60: "
        + ", ".join(f"{d:.1e}" for d in np.abs(lowest[60] - lowest[40]) / np.maximum(np.abs(lowest[60]), 1e-300)))


def main():
    t0 = time.perf_counter()
    say("Extreme cases (benchmarks/extremes.py); 'stop' is the branch's own stop reason")
    say()
    for case in (pole_stretch_10, extreme_exponents, tiny_field, far_coils, nearly_undeformed, wire_approach,
                 stability_basis):
        case()
        say()
    say(f"total wall time {time.perf_counter() - t0:.0f} s")
    wp.RESULTS.mkdir(parents=True, exist_ok=True)
    (wp.RESULTS / "extremes.txt").write_text("\n".join(LINES) + "\n")


if __name__ == "__main__":
    main()
