"""docs/tuning_curves.png: the natural frequencies of the two-coil scene against the field M at fixed pressure
(docs/dynamics.md, "Tuning curves"), from the commands a researcher runs:

    balloon-cg run two_coils_P2.5.toml --primary-only -o run.h5     # spom1_two_coils_M0.002 with [dynamics] and a
                                                                    # user point at P = 2.5 ([[events]])
    balloon-cg continue run.h5 LABEL --parameter M --set continuation.stop_field=0.004 -o tuning.h5

(LABEL: the user point on the rising branch), and the convergence of the lowest Ω² in the perturbation degree at
M = 0, 0.002, 0.004 (the curve's ends, landed on, and its start), recomputed at 1.5N and 2N, N = the branch's own
Legendre degree (at least 20).

Run: python docs/figures/tuning_curves.py   (well under a minute; prints the table docs/dynamics.md shows)
"""
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import balloon_cg as bc  # noqa: E402
from balloon_cg.analysis.branches.problem import equilibrium_of  # noqa: E402
from balloon_cg.app.cli import main as balloon_cg  # noqa: E402
from balloon_cg.app.restart import stored_branch  # noqa: E402
from balloon_cg.dynamics.frequencies import frequencies  # noqa: E402
from balloon_cg.dynamics.pencil import mass_variation  # noqa: E402
from balloon_cg.io.run_file import read_run  # noqa: E402

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "spom1_two_coils_M0.002.toml"
P0 = 2.5  # just below the M = 0 fold (P = 2.568), where the breathing mode is soft: the rising, stable branch
M_MAX, COUNT = 2, 2
TUNING = f"""
[dynamics]
frequencies = true
count = {COUNT}
m_max = {M_MAX}

[[events]]
quantity = "pressure"
value = {P0}
"""
SETTINGS = ["--set", "continuation.stop_field=0.004", "--set", "continuation.step=0.002",
            "--set", "continuation.step_max=0.002"]
HELD = ("even", "odd_held", "m1_held", "m2_held")
FREE = ("odd_free", "m1_free")  # with the rigid translation (axial, lateral) each is nearest
BLOCKS = HELD + FREE + ("m2_free",)
TABLE_FIELDS = (0.0, 0.002, 0.004)  # M of the convergence table


def tuning_curve(folder: Path) -> Path:
    """The run file of the curve in M at P0 (module docstring's commands)."""
    scene = folder / "two_coils_P2.5.toml"
    scene.write_text(SCENE.read_text().replace("stop_stretch = 5.0", "stop_stretch = 1.6") + TUNING)
    run, curve = folder / "run.h5", folder / "tuning.h5"
    assert balloon_cg(["run", str(scene), "--primary-only", "--quiet", "-o", str(run)]) == 0
    label = next(s["label"] for s in bc.load(run).special_points if s["kind"] == "UZ")
    assert balloon_cg(["continue", str(run), str(label), "--parameter", "M", "--quiet", "-o", str(curve),
                       *SETTINGS]) == 0
    return curve


def spectrum(branch, X, degree: int) -> dict:
    return frequencies(mass_variation(equilibrium_of(branch), degree), X[:-1], branch.params_at(X), True, M_MAX,
                       COUNT)


def main(out=Path(__file__).parent.parent / "tuning_curves.png"):
    with tempfile.TemporaryDirectory() as folder:
        path = tuning_curve(Path(folder))
        data = bc.load(path).branches["primary"].data
        branch = stored_branch(read_run(path), "primary")
    fields, omega2 = data["M"], data["frequencies"]
    fig, (held, free) = plt.subplots(1, 2, figsize=(8.0, 3.4), constrained_layout=True)
    for k, block in enumerate(HELD):
        held.plot(fields, omega2[block][:, 0], "o-", ms=2.5, color=f"C{k}", label=block)
    held.plot(fields, omega2["even"][:, 1], "o--", ms=2.5, color="C0", label="even, second")
    held.set(xlabel="field M", ylabel=r"$\Omega^2 = \omega^2 R_0^2 \rho/\mu$",
             title=f"(a) held: lowest Ω² per block, P = {P0:g}")
    held.legend(fontsize=7, loc="lower left", bbox_to_anchor=(0.0, 0.14))
    free.axhline(0.0, color="0.6", linewidth=0.6)
    at_field = fields > 0  # without a field the free blocks are the held ones: not drawn
    for k, (block, direction) in enumerate(zip(FREE, ("axial", "lateral"))):
        free.plot(fields[at_field], omega2[block][at_field, 0], "o-", ms=2.5, color=f"C{k + 4}", label=block)
        free.plot(fields, data["translation_omega2"][direction], ":", color="k" if k else "0.5",
                  label=f"rigid translation, {direction}")
    free.set(xlabel="field M", title="(b) free: the translations the field pulls")
    free.legend(fontsize=7)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}; M = {fields.min():g} … {fields.max():g}, {len(fields)} points of {path.name}")
    print(f"\nconvergence in the perturbation degree at P = {P0:g}: lowest Ω² at N, 1.5N, 2N")
    print("| M | N | block | Ω²(N) | Ω²(1.5N) − Ω²(N) | Ω²(2N) − Ω²(N) |\n|---|---|---|---|---|---|")
    N = max(20, branch.disc.degree)
    for M in TABLE_FIELDS:
        X = branch.X[int(np.argmin(np.abs(fields - M)))]
        coarse, middle, fine = (spectrum(branch, X, d) for d in (N, 3 * N // 2, 2 * N))
        for block in BLOCKS:
            if block in coarse:
                a, b, c = coarse[block][0], middle[block][0], fine[block][0]
                print(f"| {X[-1]:g} | {N} | {block} | {a:.12f} | {b - a:.1e} | {c - a:.1e} |")


if __name__ == "__main__":
    main()
