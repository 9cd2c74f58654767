"""docs/dielectric.png: the neo-Hookean dielectric balloon (docs/scenes.md, [electric]).

(a) P against the pole stretch at fixed voltages Φ̄ (pressure continuations; folds LP and pear points marked;
    each branch ends where the membrane would be compressed); (b) Φ̄ against the stretch at P = 0 (a voltage
    continuation) with the located pull-in fold, and the closed form Φ̄² = λ⁻² − λ⁻⁸.

Run: python docs/figures/dielectric.py   (about 30 s)
"""
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from balloon_cg.analysis.picture import analyse  # noqa: E402
from balloon_cg.analysis.results import Block, Kind  # noqa: E402
from balloon_cg.scene import parse_scene  # noqa: E402

VOLTAGES = (0.0, 0.1, 0.2, 0.3, 0.4)
NEO = '[material]\npreset = "neo-Hookean"\n'


def main(out=Path(__file__).parent.parent / "dielectric.png"):
    fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.6), constrained_layout=True)
    for voltage in VOLTAGES:
        scene = parse_scene(NEO + f"[electric]\nvoltage = {voltage}\n[continuation]\nstart_stretch = 1.15\n"
                            "stop_stretch = 4.0\n[stability]\nm_max = 0\n", name=f"voltage{voltage}")
        branch = analyse(scene, pear=False).primary
        lam = branch.pole_values()["lam2_top"]
        line, = left.plot(lam, branch.pressure, label=rf"$\bar\Phi$ = {voltage:g}")
        for s in branch.special:
            stretch = branch.pole_values(s.X)["lam2_top"][0]
            if s.kind == Kind.LP:
                left.plot(stretch, s.X[-1], "o", color=line.get_color(), ms=4)
            elif s.kind == Kind.BP and s.block == Block.ODD_HELD:
                left.plot(stretch, s.X[-1], "s", mfc="none", color=line.get_color(), ms=5)
    left.set(xlabel="pole stretch λ", ylabel="pressure P", title=r"(a) pressure control at fixed $\bar\Phi$",
             xlim=(1, 4), ylim=(0, None))
    left.plot([], [], "ko", ms=4, label="fold (LP)")
    left.plot([], [], "ks", mfc="none", ms=5, label="odd-mode BP (n = 1, 3, …)")
    left.legend(fontsize=7)

    scene = parse_scene(NEO + '[electric]\n[continuation]\nparameter = "voltage"\nstop_stretch = 4.0\n', name="P0")
    branch = analyse(scene).primary
    lam = branch.pole_values()["lam2_top"]
    stable = np.array([a.stable_pressure for a in branch.stability])
    right.plot(lam[stable], branch.voltage[stable], "C0-", label=r"stable (fixed P, $\bar\Phi$)")
    right.plot(lam[~stable], branch.voltage[~stable], "C0--", label="unstable")
    grid = np.linspace(1.001, 4, 400)
    right.plot(grid, np.sqrt(grid**-2 - grid**-8), "k:", lw=0.8, label=r"$\bar\Phi^2 = \lambda^{-2} - \lambda^{-8}$")
    fold = next(s for s in branch.special if s.kind == Kind.LP)
    stretch = branch.pole_values(fold.X)["lam2_top"][0]
    right.plot(stretch, fold.X[-1], "ro")
    right.annotate(f"pull-in λ = {stretch:.6f}\n" + rf"$\bar\Phi$ = {fold.X[-1]:.6f}", (stretch, fold.X[-1]),
                   (2.0, 0.58), fontsize=8, arrowprops={"arrowstyle": "->"})
    right.set(xlabel="pole stretch λ", ylabel=r"voltage $\bar\Phi$", title="(b) voltage control at P = 0", xlim=(1, 4),
              ylim=(0, 0.75))
    right.legend(fontsize=7, loc="lower right")
    fig.savefig(out, dpi=150)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
