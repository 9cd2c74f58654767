"""The onset of bulging against the held pre-stretch λ of a tube with sliding ends held at λL (docs/tubes.md):
``critical --parameter axial_stretch``'s curve (tube/onset.py, L = 10, degree 12: the uniform tube is exact there)
traced from λ = 1.5 up and down for SPOM1, neo-Hookean and Gent, against the long-tube limit k → 0 of the
fixed-stretch dispersion relation (model/tube.bulge_condition at λz = λ: Fu's det ∂(P, N)/∂(λθ, λz) = 0 on the
fixed-λz path, its first root in λθ from the state at P = 0). Prints the onset (P, λθ) at λ = 1 … 5 on both, the folds
of the traced curve in λ (the critical pre-stretch above which the held tube does not bulge) and the long tube's
critical pre-stretch (where the roots in λθ meet: bisection in λ); draws docs/tube_onset_prestretch.png.

    python benchmarks/tube_onset_prestretch.py
"""
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_held_tube import held_scene  # noqa: E402

from balloon_cg.galerkin.interval import Mirror  # noqa: E402
from balloon_cg.model import tube  # noqa: E402
from balloon_cg.tube.onset import onset_curve  # noqa: E402
from balloon_cg.tube.primary import primary_branch  # noqa: E402

PRESETS = ("SPOM1", "neo-Hookean", "Gent")
STRETCHES = (1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0)
LENGTH = 10.0
FIGURE = Path(__file__).resolve().parents[1] / "docs" / "tube_onset_prestretch.png"


def traced(preset: str):
    """The onset curve of the held tube from λ = 1.5 down to 1 and up (joined, λ ascending along the first part):
    (λ, P, λθ), the folds' (λ, P), the upward curve's stop message, CPU seconds."""
    start = time.process_time()
    scene = held_scene(preset, LENGTH, 1.5, "sliding", 12, 8.0)
    primary = primary_branch(scene)
    point = primary.branch_points(Mirror.ODD)[0]
    down, up = (onset_curve(scene, primary, point, "axial_stretch", d) for d in (-1.0, 1.0))
    q = np.concatenate([down.q[::-1], up.q[1:]])
    P = np.concatenate([down.pressure[::-1], up.pressure[1:]])
    hoop = np.concatenate([down.states[::-1, 0], up.states[1:, 0]])
    folds = [(float(f), s.pressure, s.u[0]) for f, s in zip(up.fold_q, up.folds)]
    return q, P, hoop, folds, up.stop.message, time.process_time() - start


def long_tube_roots(material, stretch: float) -> list:
    """λθ where bulge_condition at k = 0 changes sign on the fixed-λz path with P > 0 (from the P = 0 state)."""
    hoops = np.geomspace(0.3, 9.0, 600)
    P = tube.hoop_pressure(material, hoops, stretch)

    def condition(h):
        return tube.bulge_condition(material, tube.UniformTube(h, stretch, tube.hoop_pressure(material, h, stretch)),
                                    0.0)

    values = np.array([condition(h) if p > 0 else np.nan for h, p in zip(hoops, P)])
    return [brentq(condition, hoops[i], hoops[i + 1], xtol=1e-14) for i in range(len(hoops) - 1)
            if values[i] * values[i + 1] < 0]


def long_tube_critical(material, low: float, high: float) -> float:
    """The pre-stretch in [low, high] above which the long tube's condition has no root below λθ = 9: bisection."""
    for _ in range(30):
        mid = (low + high) / 2
        low, high = (mid, high) if long_tube_roots(material, mid) else (low, mid)
    return (low + high) / 2


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    from balloon_cg.post.style import JournalFigure, journal_style

    with journal_style():
        fig = JournalFigure(figsize=(7.0, 2.8), layout="constrained")
        left, right = fig.subplots(1, 2)
        for colour, preset in zip(("k", "C0", "C1"), PRESETS):
            material = held_scene(preset, LENGTH, 1.5, "sliding", 12).material
            q, P, hoop, folds, stop, cpu = traced(preset)
            print(f"{preset}, L = {LENGTH:g}: {len(q)} points, {cpu:.1f} s CPU; upwards: {stop}")
            for lam, p, h in folds:
                print(f"  fold in λ: critical pre-stretch λ_c = {lam:.10f} (P = {p:.10f}, λθ = {h:.8f})")
            print(f"  {'λ':>4} {'P onset L=10':>13} {'λθ L=10':>9} {'P onset L=∞':>12} {'λθ L=∞':>9}")
            first = np.argmax(np.diff(q) < 0) if folds else len(q)  # before the fold: the onset itself
            for lam in STRETCHES:
                inside = q[0] <= lam <= q[:first + 1].max()
                traced_p = np.interp(lam, q[:first + 1], P[:first + 1]) if inside else np.nan
                traced_h = np.interp(lam, q[:first + 1], hoop[:first + 1]) if inside else np.nan
                roots = long_tube_roots(material, lam)
                h_inf = roots[0] if roots else np.nan
                p_inf = tube.hoop_pressure(material, h_inf, lam) if roots else np.nan
                print(f"  {lam:4.1f} {traced_p:13.8f} {traced_h:9.6f} {p_inf:12.8f} {h_inf:9.6f}")
            if preset == "Gent":
                print(f"  long tube (k → 0): critical pre-stretch λ_c = {long_tube_critical(material, 3.0, 4.0):.8f}")
            left.plot(q, P, color=colour, label=f"{preset}, L = 10")
            right.plot(q, hoop, color=colour, label=f"{preset}, L = 10")
            lams = np.linspace(1.0, 5.0, 81)
            longs = [long_tube_roots(material, lam) for lam in lams]
            h_inf = np.array([r[0] if r else np.nan for r in longs])
            left.plot(lams, tube.hoop_pressure(material, h_inf, lams), color=colour, linestyle=":",
                      label=f"{preset}, L → ∞")
            right.plot(lams, h_inf, color=colour, linestyle=":")
            for lam, p, h in folds:
                left.plot(lam, p, "o", color=colour, markersize=3)
                right.plot(lam, h, "o", color=colour, markersize=3)
        left.set(xlabel="$\\lambda$ (ends held at $\\lambda L$)", ylabel="onset $P$",
                 title="onset of bulging against the pre-stretch")
        right.set(xlabel="$\\lambda$", ylabel="onset $\\lambda_\\theta$", ylim=(0.8, 6.0),
                  title="hoop stretch at the onset")
        left.legend(fontsize=5)
        fig.savefig(FIGURE, dpi=200)
    print(f"figure: {FIGURE}")


if __name__ == "__main__":
    main()
