"""docs/tubes.png: the bulge of a closed SPOM1 tube (docs/tubes.md), and the convergence tables that page shows.

The tube: SPOM1, length L = 20 reference radii, sliding closed ends (the repeating cell of a long tube), degree 100.
Its primary branch (the uniform tube) to a hoop stretch of 11.5, past the second Maxwell state, and its bulge branch
switched at the first odd branch point (the onset) and traced to V/V0 = 420 (tube/primary.py, tube/bulge.py, as
``balloon-cg run`` does but with the bulge stopped at a volume), written to a tube run file (io/tube_file.py) and read
back; the panels are post/tube_plots.py's (``balloon-cg plot --what pressure-volume,profiles,front,stretches``):

(a) P against V/V0, solid where stable under volume control, with Maxwell's line P_M (model/tube.maxwell_pressure);
(b) the profiles r(z) of the bulge branch at a few V/V0, z the distance along the deformed axis from the end S = 0
    (the classic photograph: the bulge forms at that end and its front moves along the tube at P_M);
(c) the front's position z_f and width against V/V0 (none drawn where the profile has no front: near the onset);
(d) the hoop stretch λ2 and the axial stretch λ1 against z at three states of the plateau.

Printed (the tables of docs/tubes.md): the onset of bulging against L at degree 20 (the first odd branch point against
model/tube.bulge_onset and the long-tube limit, the pressure maximum); the bulge's volume fold against the degree
(L = 10); P − P_M along the plateau at degrees 100 and 140 (L = 20); the front's reference position against the lever
rule of the two Maxwell states a, b: a sharp front at S_f has V/V0 = v_a + (S_f/L)(v_b − v_a), v = λθ²λz, so
on the plateau S_f − L(V/V0 − v_a)/(v_b − v_a) is a constant (the front translates without changing its shape).

Run: python docs/figures/tubes.py   (about three minutes on a quiet machine: the plateau at two degrees)
"""
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from balloon_cg.galerkin.equilibrium import Equilibrium  # noqa: E402
from balloon_cg.galerkin.interval import Mirror  # noqa: E402
from balloon_cg.io.tube_file import discretisation, read_tube_run, write_tube_run  # noqa: E402
from balloon_cg.model import tube  # noqa: E402
from balloon_cg.post.style import journal_style  # noqa: E402
from balloon_cg.post.tube_measures import fronts  # noqa: E402
from balloon_cg.post.tube_plots import front_motion, pressure_volume, profiles, stretch_profiles  # noqa: E402
from balloon_cg.scene import parse_scene  # noqa: E402
from balloon_cg.tube.bulge import bulge_branch  # noqa: E402
from balloon_cg.tube.picture import TubePicture, maxwell  # noqa: E402
from balloon_cg.tube.primary import primary_branch  # noqa: E402

LENGTH, DEGREE, FINER = 20.0, 100, 140
STOP_VOLUME = 420.0
SHOWN = (3.0, 10.0, 30.0, 100.0, 200.0, 300.0, 400.0)  # V/V0 of the profiles drawn
STRETCHED = (150.0, 250.0, 400.0)  # V/V0 of the stretches drawn
TABLE = (20.0, 50.0, 100.0, 200.0, 300.0, 320.0, 360.0, 400.0)  # V/V0 of the plateau's table
LENGTHS = (10.0, 20.0, 40.0, 80.0, 160.0)
DEGREES = (30, 40, 60, 90)


def scene_of(length: float, degree: int, stop_stretch: float, preset: str = "SPOM1"):
    return parse_scene(f'[material]\npreset = "{preset}"\n[geometry]\nshape = "tube"\nlength = {length}\n'
                       f'ends = "sliding"\n[solver]\ndegree = {degree}\n[continuation]\nstop_stretch = {stop_stretch}\n'
                       'step_max = 0.5\nmax_points = 2000\n', name=f"tube_spom1_L{length:g}")


def picture(length: float, degree: int, stop_stretch: float, stop_volume: float) -> tuple:
    """(scene, TubePicture) of the module docstring's run."""
    scene = scene_of(length, degree, stop_stretch)
    primary = primary_branch(scene)
    bulge = bulge_branch(scene, primary, primary.branch_points(Mirror.ODD)[0], stop_volume=stop_volume * np.pi * length, step=0.02)
    return scene, TubePicture({"primary": primary, "bulge": bulge}, maxwell(scene))


def draw(run: dict, out: Path) -> None:
    volume = run["branches"]["bulge"]["volume"]
    nearest = lambda targets: [int(np.argmin(np.abs(volume - v))) for v in targets]
    with journal_style():
        fig, axes = plt.subplots(2, 2, figsize=(8.0, 6.4), layout="constrained")
        pressure_volume(axes[0, 0], run, "volume")
        kept = [next(text for text in axes[0, 0].texts if text.get_text().split(maxsplit=1)[-1] == kind)
                for kind in ("LP", "BP odd", "LV")]  # the labels "0 LP", "1 BP odd", …: post/labels.py
        for text in [text for text in axes[0, 0].texts if text not in kept]:
            text.remove()  # the higher modes' branch points and the plateau's folds (docs/tubes.md): marked only
        axes[0, 0].set_title("(a) P against V/V0 (solid: stable under volume control)")
        profiles(axes[0, 1], run, "bulge", nearest(SHOWN))
        axes[0, 1].set_title("(b) profiles r(z) of the bulge branch")
        front_motion(axes[1, 0], run, "bulge", np.flatnonzero(volume >= 5.0))
        axes[1, 0].set_title("(c) the front along the deformed axis")
        stretch_profiles(axes[1, 1], run, "bulge", nearest(STRETCHED))
        axes[1, 1].set_title("(d) hoop (solid) and axial (dashed) stretch")
        for ax in axes.flat:  # each panel's legend at matplotlib's best place (tube_figure's: post/fit.py)
            ax.legend(*ax.get_legend_handles_labels(), fontsize=5)
        fig.savefig(out, dpi=130)
    print(f"wrote {out}")


def onset_table() -> None:
    """The first odd branch point of the primary branch against L (degree 20) and the long-tube limit."""
    material = scene_of(10.0, 20, 1.75).material
    peak = tube.pressure_maximum(material)
    print(f"\nonset of bulging against L (SPOM1, degree 20); the pressure maximum λθ* = {peak.hoop:.12f}, "
          f"P* = {peak.pressure:.12f}")
    print("| L | λθ at the BP | P at the BP | λθ − oracle | P − oracle | λθ − λθ* | ratio to the previous L | P* − P |")
    print("|---|---|---|---|---|---|---|---|")
    previous = None
    for length in LENGTHS:
        point = primary_branch(scene_of(length, 20, 1.75)).branch_points(Mirror.ODD)[0]
        oracle = tube.bulge_onset(material, length)
        gap = point.u[0] - peak.hoop
        ratio = "" if previous is None else f"{previous / gap:.4f}"
        print(f"| {length:g} | {point.u[0]:.12f} | {point.pressure:.12f} | {point.u[0] - oracle.hoop:.1e} | "
              f"{point.pressure - oracle.pressure:.1e} | {gap:.4e} | {ratio} | {peak.pressure - point.pressure:.3e} |")
        previous = gap


def fold_table() -> None:
    """The bulge branch's volume fold (LV) on L = 10 against the degree."""
    print("\nthe bulge's volume fold LV against the degree (SPOM1, L = 10)")
    print("| degree | P at LV | V/V0 at LV | ΔP from the previous | ΔV/V0 |\n|---|---|---|---|---|")
    previous = None
    for degree in DEGREES:
        scene, found = picture(10.0, degree, 1.75, 10.0)
        fold = next(s for s in found.branches["bulge"].special if s.kind == "LV")
        volume = 2 * Equilibrium(scene, found.branches["bulge"].disc).volume(fold.u) / 10.0  # V/(2π) over L/2
        step = ("", "") if previous is None else (f"{fold.pressure - previous[0]:.1e}", f"{volume - previous[1]:.1e}")
        print(f"| {degree} | {fold.pressure:.13f} | {volume:.13f} | {step[0]} | {step[1]} |")
        previous = (fold.pressure, volume)


def plateau_table(coarse: dict, fine: dict) -> None:
    """P − P_M along the plateau at both degrees, the front's width and its reference position against the lever
    rule of the Maxwell states."""
    pm, a, b = tube.maxwell_pressure(scene_of(LENGTH, DEGREE, 1.75).material)
    va, vb = a.hoop**2 * a.axial, b.hoop**2 * b.axial
    reference, deformed = fronts(discretisation(coarse["attrs"]), coarse["branches"]["bulge"]["unknowns"])
    volume = coarse["branches"]["bulge"]["volume"]
    finer = fine["branches"]["bulge"]
    print(f"\nthe plateau (SPOM1, L = {LENGTH:g}): P_M = {pm:.12f}, states a: v = {va:.6f}, b: v = {vb:.4f}")
    print(f"| V/V0 | P − P_M, degree {DEGREE} | P − P_M, degree {FINER} | S_f | S_f − lever rule | "
          "front width (deformed) |\n|---|---|---|---|---|---|")
    for target in TABLE:
        i = int(np.argmin(np.abs(volume - target)))
        P = coarse["branches"]["bulge"]["pressure"][i]
        P_fine = np.interp(volume[i], finer["volume"], finer["pressure"])
        lever = LENGTH * (volume[i] - va) / (vb - va)
        S = reference[i].position
        print(f"| {volume[i]:.4g} | {P - pm:.2e} | {P_fine - pm:.2e} | {S:.4f} | {S - lever:.4f} | "
              f"{deformed[i].width:.4f} |")


def main(out=Path(__file__).parent.parent / "tubes.png"):
    with tempfile.TemporaryDirectory() as folder:
        runs = {}
        for degree in (DEGREE, FINER):
            scene, found = picture(LENGTH, degree, 11.5 if degree == DEGREE else 1.75, STOP_VOLUME)
            runs[degree] = read_tube_run(write_tube_run(Path(folder) / f"tube_{degree}.h5", scene, found))
    draw(runs[DEGREE], out)
    plateau_table(runs[DEGREE], runs[FINER])
    onset_table()
    fold_table()


if __name__ == "__main__":
    main()
