"""docs/tuning_curves.png: the natural frequencies of the two-coil scene against the field M at fixed pressure, and
the convergence of the lowest ones in the perturbation degree (docs/dynamics.md, "Tuning curves").

For each M the primary branch of spom1_two_coils_M0.002 (M overridden) is traced up from the reference sphere
until P first reaches P0, and that state is solved at P = P0 exactly (Newton with the row P = P0); there the
lowest Ω² of every block (m ≤ 2) and the rigid translations' Ω² are computed at the branch's own Legendre degree
N (at least 20), and again at 1.5N and 2N for the convergence table. Where the first fold of the branch falls below
P0 the state at P0 does not exist on the rising branch: the curve ends there.

Run: python docs/figures/tuning_curves.py   (about a minute; prints the table docs/dynamics.md shows)
"""
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from balloon_cg.analysis.primary import trace_primary  # noqa: E402
from balloon_cg.analysis.problem import branch_system, equilibrium_of  # noqa: E402
from balloon_cg.dynamics.frequencies import frequencies  # noqa: E402
from balloon_cg.dynamics.pencil import mass_variation  # noqa: E402
from balloon_cg.dynamics.translation import translation_omega2  # noqa: E402
from balloon_cg.numerics.newton import newton  # noqa: E402
from balloon_cg.scene import load_scene  # noqa: E402

SCENE = "spom1_two_coils_M0.002"
P0 = 2.5  # just below the M = 0 fold (P = 2.568), where the breathing mode is soft: the rising, stable branch
FIELDS = np.linspace(0.0, 0.004, 17)
M_MAX, COUNT = 2, 2
HELD = ("even", "odd_held", "m1_held", "m2_held")
FREE = ("odd_free", "m1_free")  # with the rigid translation (axial, lateral) each is nearest
BLOCKS = HELD + FREE + ("m2_free",)
TABLE_FIELDS = (0.0, 0.002, 0.004)  # M of the convergence table


def state_at_pressure(M: float):
    """(branch, X) of the rising primary branch at P = P0 for field M, or None where it does not reach P0."""
    scene = load_scene(SCENE).with_overrides({"field.M": float(M)})
    branch = trace_primary(scene, stop_stretch=3.0, down=False)
    above = np.flatnonzero(branch.X[:, -1] >= P0)
    if not above.size or np.any(np.diff(branch.X[:above[0] + 1, -1]) < 0):  # a fold before P0
        return None
    n = above[0]
    t = (P0 - branch.X[n - 1, -1]) / (branch.X[n, -1] - branch.X[n - 1, -1])
    guess = (1 - t) * branch.X[n - 1] + t * branch.X[n]
    system = branch_system(branch)
    row = np.zeros(guess.size)
    row[-1] = 1.0
    solved = newton(system.residual, system.jacobian, guess, row, P0, scene.solver.tol, 30)
    return (branch, solved.x) if solved.converged else None


def spectrum(branch, X, degree: int) -> dict:
    return frequencies(mass_variation(equilibrium_of(branch), degree), X[:-1], branch.params_at(X), True, M_MAX,
                       COUNT)


def main(out=Path(__file__).parent.parent / "tuning_curves.png"):
    rows, table = [], []
    for M in FIELDS:
        found = state_at_pressure(M)
        if found is None:
            break
        branch, X = found
        N = max(20, branch.disc.degree)
        values = spectrum(branch, X, N)
        rigid = translation_omega2(equilibrium_of(branch), X[:-1], branch.params_at(X), N)
        rows.append((M, values, rigid))
        if any(np.isclose(M, m) for m in TABLE_FIELDS):
            finer = [spectrum(branch, X, d) for d in (3 * N // 2, 2 * N)]
            table.append((M, N, values, *finer))
    fig, (held, free) = plt.subplots(1, 2, figsize=(8.0, 3.4), constrained_layout=True)
    fields = np.array([M for M, _, _ in rows])

    def lowest(block, k=0):
        return np.array([values[block][k] if block in values else np.nan for _, values, _ in rows])

    for k, block in enumerate(HELD):
        held.plot(fields, lowest(block), "o-", ms=2.5, color=f"C{k}", label=block)
    held.plot(fields, lowest("even", 1), "o--", ms=2.5, color="C0", label="even, second")
    held.set(xlabel="field M", ylabel=r"$\Omega^2 = \omega^2 R_0^2 \rho/\mu$",
             title=f"(a) held: lowest Ω² per block, P = {P0:g}")
    held.legend(fontsize=7, loc="lower left", bbox_to_anchor=(0.0, 0.14))
    free.axhline(0.0, color="0.6", linewidth=0.6)
    for k, (block, direction) in enumerate(zip(FREE, ("axial", "lateral"))):
        free.plot(fields, lowest(block), "o-", ms=2.5, color=f"C{k + 4}", label=block)
        free.plot(fields, [rigid[direction] for _, _, rigid in rows], ":", color="k" if k else "0.5",
                  label=f"rigid translation, {direction}")
    free.set(xlabel="field M", title="(b) free: the translations the field pulls")
    free.legend(fontsize=7)
    if len(rows) < len(FIELDS):
        held.axvline(fields[-1], color="0.4", linestyle="--", linewidth=0.8)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}; M = {fields[0]:g} … {fields[-1]:g} ({len(rows)} of {len(FIELDS)} fields reach P = {P0:g})")
    print(f"\nconvergence in the perturbation degree at P = {P0:g}: lowest Ω² at N, 1.5N, 2N")
    print(f"| M | N | block | Ω²(N) | Ω²(1.5N) − Ω²(N) | Ω²(2N) − Ω²(N) |\n|---|---|---|---|---|---|")
    for M, N, coarse, middle, fine in table:
        for block in BLOCKS:
            if block in coarse:
                a, b, c = coarse[block][0], middle[block][0], fine[block][0]
                print(f"| {M:g} | {N} | {block} | {a:.12f} | {b - a:.1e} | {c - a:.1e} |")


if __name__ == "__main__":
    main()
