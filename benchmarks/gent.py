"""The paper's workflow on Gent (J_m = 97.2, μ as neo-Hookean: the "Gent" preset): pear points, isola, critical
parameter, with the default single coil and with the two coils.

1. M = 0, closed form: the sphere's pressure extrema (λ(Φ11 + Φ12) = 2Φ1) and its pear condition
   λ(Φ11 + Φ12) = Φ1 (model/sphere_modes.py); the traced primary branch against them.
2. The single coil (scenes/spom1_single_coil.toml, a = 4, h = 0, M = 0.002), the coil inferred for the paper
   (scenes/spom1_paper_coil.toml, a = 1.961) and the two coils (scenes/spom1_two_coils_M0.002.toml) with
   material.preset = "Gent": the whole picture (balloon_cg.analyse: primary branch, pear pitchforks, pear
   branches).
3. Where there is a pear pitchfork: its curve in M and in J_m, both ways (analysis.critical.pitchfork_curve: the critical value is
   a fold of the curve at P > 0 followed by the partner pitchfork); checks: plain primary branches at a few J_m
   (their pear point must lie on the curve), and the J_m → ∞ end against the neo-Hookean preset (Ogden class,
   another kernel module) in the same field.
4. The figure docs/gent.png: P against the north-pole stretch (primary and pear branches) and the pitchfork
   pressure along its curves in M and in J_m.

Run: python benchmarks/gent.py  (output kept in benchmarks/results/gent.txt; about 10 min on the shared CPU)
"""
import tempfile
import time
from pathlib import Path

import numpy as np

import balloon_cg as bc
from balloon_cg.analysis.critical.pitchfork_curve import continue_branch_point, land_on_q
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.io.curve_file import write_curve
from balloon_cg.model.sphere import sphere_pressure
from balloon_cg.model.sphere_modes import bifurcation_condition, bifurcation_stretches
from balloon_cg.scene import load_scene
from balloon_cg.scene.materials import get_preset
from two_parameter import pear_points  # benchmarks/two_parameter.py (this script's folder)

ROOT = Path(__file__).resolve().parent.parent
SCENES = {"single coil (a = 4, M = 0.002)": "spom1_single_coil.toml",
          "inferred paper coil (a = 1.961, M = 0.002)": "spom1_paper_coil.toml",
          "two coils (M = 0.002)": "spom1_two_coils_M0.002.toml"}
GENT = {"material.preset": "Gent"}
FIGURE = ROOT / "docs" / "gent.png"


def closed_form(out: Path):
    gent = get_preset("Gent")
    lam_max = 0.999 * _limit_stretch(gent.parameters["Jm"])
    extrema = bifurcation_stretches(gent, 0, lam_max=lam_max)
    grid = np.geomspace(1.0 + 1e-6, lam_max, 20000)
    pear = bifurcation_condition(gent, grid, 1)
    print(f"Gent, mu = {gent.parameters['mu']:g}, Jm = {gent.parameters['Jm']:g} (sphere limit stretch "
          f"{_limit_stretch(gent.parameters['Jm']):.4f}), M = 0: closed form")
    for lam in extrema:
        print(f"  pressure extremum lambda(Phi11 + Phi12) = 2 Phi1: lambda = {lam:.10f}, P = "
              f"{float(sphere_pressure(gent, lam)):.10f}")
    print(f"  pear condition 4(S - t) over lambda in (1, {lam_max:.3f}): min {pear.min():.4g} > 0, "
          f"{len(bifurcation_stretches(gent, 1, lam_max=lam_max))} roots: no pear point, no isola "
          "(t = Phi1/lambda = W'(I1)(2 - 2 lambda^-6) rises with lambda for every Jm: W' = (mu/2)/(1 - (I1 - 3)/Jm))")
    t = time.perf_counter()
    scene = load_scene("spom1").with_overrides(GENT | {"continuation.stop_stretch": 6.0})
    branch = trace_primary(scene)
    bc.trace(scene).save(out / "gent_M0.h5")
    lam2 = branch.pole_values()["lam2_top"]
    folds = [s for s in branch.special if s.kind.value == "LP"]
    print(f"  traced primary branch (spom1 scene, stop 6): {len(lam2)} points, {len(pear_points(branch))} pear "
          f"points; folds: " + "; ".join(
              f"lambda {branch.pole_values(s.X)['lam2_top'][0]:.10f}, P {s.X[-1]:.10f} "
              f"(closed form {abs(s.X[-1] / float(sphere_pressure(get_preset('Gent'), extrema[k])) - 1):.1e} rel.)"
              for k, s in enumerate(folds)) + f"  ({time.perf_counter() - t:.1f} s)")


def _limit_stretch(Jm: float) -> float:
    """The sphere's λ where I1 − 3 = 2λ² + λ⁻⁴ − 3 reaches Jm (the largest root)."""
    from scipy.optimize import brentq
    return brentq(lambda lam: 2 * lam**2 + lam**-4 - 3 - Jm, 1.5, 100.0)


def whole_picture(label, file, out: Path):
    t = time.perf_counter()
    scene = load_scene(file).with_overrides(GENT | {"continuation.stop_stretch": 6.0})
    result = bc.analyse(scene)
    path = result.save(out / f"gent_{Path(file).stem}.h5")
    elapsed = time.perf_counter() - t
    bps = [s for s in result.special_points if s["kind"] == "BP" and s["block"] == "odd_held"
           and s["branch"] == "primary"]
    primary = result.branches["primary"]
    stretch = primary["lam2_top"]
    print(f"{label}: whole picture {elapsed:.1f} s; primary branch {len(primary)} points, lambda2(0) "
          f"{stretch.min():.4f}..{stretch.max():.4f}, ended {primary.attrs['stop_reason']}")
    print(f"  pear pitchforks on the primary branch: {len(bps)}" + "".join(
        f"; lambda2(0) {s['lam2_top']:.8f}, P {s['pressure']:.8f} ({s['classification']}, {s['status']})"
        for s in bps))
    for name, b in result.branches.items():
        if name != "primary":
            print(f"  pear branch {name}: {len(b)} points, P {b['pressure'].min():.6f}..{b['pressure'].max():.6f},"
                  f" lambda2(0) up to {b['lam2_top'].max():.4f}; ended {b.attrs['stop_reason']}")
    return scene, path


def curves(scene, out: Path):
    """The first pear pitchfork continued in M and in Jm, both ways; rows of the table and the curve files."""
    branch = trace_primary(scene)
    bps = pear_points(branch)
    rows, files = [], {}
    for key, direction, budget in (("M", 1.0, 400), ("M", -1.0, 400), ("material.parameters.Jm", 1.0, 60),
                                   ("material.parameters.Jm", -1.0, 400)):
        t = time.perf_counter()
        curve = continue_branch_point(branch, bps[0], key, direction, max_points=budget)
        rows.append((key, direction, curve, time.perf_counter() - t))
        stem = f"{key.split('.')[-1]} {'increasing' if direction > 0 else 'decreasing'}"
        files.setdefault(key, []).append(write_curve(out / f"{stem}.h5", scene, curve, force=True))
    print("  the first pear pitchfork continued (codim2; dR/dM exact, dR/dJm central differences):")
    print("  | parameter | direction | points | end | q range | P range | pole stretch range | time |")
    print("  |---|---|---|---|---|---|---|---|")
    for key, direction, curve, elapsed in rows:
        print(f"  | {key} | {direction:+.0f} | {len(curve.q)} | {curve.end.value} | {curve.q.min():.6g}.."
              f"{curve.q.max():.6g} | {curve.pressure.min():.6f}..{curve.pressure.max():.6f} | "
              f"{curve.pole_stretch.min():.5f}..{curve.pole_stretch.max():.5f} | {elapsed:.1f} s |")
        print(f"    {curve.describe()}")
    return branch, rows, files


def check_jm(scene, rows):
    """Plain primary branches at a few Jm: their pear point against the curve landed on the same Jm; and the
    neo-Hookean preset's pitchfork against the curve's large-Jm end."""
    down = next(c for k, d, c, _ in rows if k.endswith("Jm") and d < 0)
    up = next(c for k, d, c, _ in rows if k.endswith("Jm") and d > 0)
    for Jm in (30.0, 60.0):
        t = time.perf_counter()
        near = int(np.argmin(np.abs(down.q - Jm)))
        X = land_on_q(down, Jm, near)
        probe = trace_primary(scene.with_overrides({"material.parameters.Jm": Jm}))
        found = pear_points(probe)
        P_curve = X[down.n]
        P_plain = [bp.X[-1] for bp in found]
        print(f"  check Jm = {Jm:g}: curve P = {P_curve:.10f}; plain primary branch: {len(found)} pear point(s), "
              + ", ".join(f"P = {P:.10f} (diff {abs(P - P_curve):.1e})" for P in P_plain)
              + f"  ({time.perf_counter() - t:.1f} s)")
    neo = trace_primary(scene.with_overrides({"material.preset": "neo-Hookean"}))
    bp = pear_points(neo)[0]
    P_neo = bp.X[-1]
    print(f"  check Jm -> infinity: neo-Hookean preset (Ogden kernels) pitchfork P = {P_neo:.10f}, lambda2(0) = "
          f"{neo.pole_values(bp.X)['lam2_top'][0]:.8f}; on the curve (Gent kernels):")
    P = {}
    for Jm in (1e5, 2e5):
        X = land_on_q(up, Jm, int(np.argmin(np.abs(up.q - Jm))))
        P[Jm] = X[up.n]
        print(f"    Jm = {Jm:g}: P = {P[Jm]:.10f} (minus neo-Hookean: {P[Jm] - P_neo:.3e}; times Jm: "
              f"{(P[Jm] - P_neo) * Jm:.5f})")
    extrapolated = 2 * P[2e5] - P[1e5]  # P(Jm) = P_inf + c/Jm + O(1/Jm^2)
    print(f"    Richardson in 1/Jm: P_inf = {extrapolated:.10f}, minus neo-Hookean {extrapolated - P_neo:.1e}")


def figure(runs: dict, files: dict, rows: list):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from balloon_cg.post.plotting import plot as draw

    fig, axes = plt.subplots(2, 2, figsize=(13, 10))
    (whole, zoom), (in_M, in_Jm) = axes
    draw(list(runs.values()), "pressure-pole", axes=whole)
    whole.set_title("(a) Gent (Jm = 97.2): primary branches (M = 0, one coil a = 4 or 1.961, two coils)",
                    fontsize=10)
    draw([runs["two coils (M = 0.002)"]], "pressure-pole", axes=zoom)
    zoom.set_xlim(1.55, 1.95)
    zoom.set_ylim(2.0, 2.3)
    zoom.set_title("(b) two coils, M = 0.002: the pear pitchfork and its pear branches (to the wire gap)",
                   fontsize=10)
    ends = {(key, direction): curve for key, direction, curve, _ in rows}
    draw(files["M"], "phase", axes=in_M)
    in_M.set_title(f"(c) two coils: the pitchfork continued in M (ends: {ends['M', 1.0].end.value}, "
                   f"{ends['M', -1.0].end.value})", fontsize=10)
    draw(files["material.parameters.Jm"], "phase", axes=in_Jm)
    in_Jm.set_xscale("log")
    in_Jm.set_xlabel(r"Gent $J_m$ (log scale)")
    down = ends["material.parameters.Jm", -1.0]
    in_Jm.set_title(f"(d) two coils: the pitchfork in Jm (down: {down.end.value} at Jm = {down.q[-1]:.3g}; "
                    "up: to neo-Hookean)", fontsize=10)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=130)
    print(f"figure: {FIGURE.relative_to(ROOT)}")


def main():
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        closed_form(out)
        runs, files = {"M = 0": out / "gent_M0.h5"}, {}
        for label, file in SCENES.items():
            scene, runs[label] = whole_picture(label, file, out)
            if "two coils" in label:
                _, rows, files = curves(scene, out)
                check_jm(scene, rows)
        figure(runs, files, rows)
    print(f"total {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
