"""What people look at on a tube (a tube run file, io/tube_file.py): P against V/V0 of every branch with Maxwell's
line (``pressure_volume``), and the family of profiles r(Z) of a branch (``profiles``), in the journal style.

Curves are solid where a point is stable under the chosen control (no negative eigenvalue of ∂R/∂u without, or
with, δV = 0: the file's ``unstable_pressure``/``unstable_volume``) and dashed where it is not; located points are
marked and labelled (LP, LV, BP with its mirror block).
"""
import numpy as np

from .style import JournalFigure, journal_style
from ..io.tube_file import discretisation

TUBE_KINDS = ("pressure-volume", "profiles")
CONTROLS = ("pressure", "volume")
PROFILES = 8  # profiles drawn along a branch unless the points are given
_COLOURS = {"primary": "k", "bulge": "C0"}


class TubePlotError(ValueError):
    """A figure a tube run file cannot give (exit code 2)."""


def tube_figure(run: dict, what: str, control: str = "pressure", branch: str | None = None, points=None,
                width: float = 3.5):
    """The figure of kind ``what`` (TUBE_KINDS) of a tube run (read_tube_run output)."""
    if what not in TUBE_KINDS:
        raise TubePlotError(f"--what {what}: not drawn for a tube run file; allowed: {', '.join(TUBE_KINDS)}")
    if control not in CONTROLS:
        raise TubePlotError(f"--stability {control}: allowed for a tube: {', '.join(CONTROLS)}")
    with journal_style():
        fig = JournalFigure(figsize=(width, 0.75 * width), layout="constrained")
        ax = fig.add_subplot()
        if what == "pressure-volume":
            pressure_volume(ax, run, control)
        else:
            name = branch or ("bulge" if "bulge" in run["branches"] else "primary")
            if name not in run["branches"]:
                raise TubePlotError(f"--branch {name}: not in the file; it has {', '.join(run['branches'])}")
            profiles(ax, run, name, points)
    return fig


def pressure_volume(ax, run: dict, control: str) -> None:
    """P against V/V0 of every branch, solid where stable under ``control``, the located points labelled, and
    Maxwell's pressure as a dotted line where the file has one."""
    for name, b in sorted(run["branches"].items(), key=lambda item: item[0] != "primary"):
        colour = _COLOURS.get(name, "C1")
        stable = b[f"unstable_{control}"] == 0
        for solid in (True, False):
            shown = np.where(_runs(stable, solid), b["pressure"], np.nan)
            ax.plot(b["volume"], shown, color=colour, linestyle="-" if solid else "--",
                    label=name if solid else None)
        for s in b["special_points"]:
            ax.plot(s["volume"], s["pressure"], "o", color=colour, markersize=3)
            ax.annotate(f"{s['kind']}{' ' + s['block'] if s['block'] else ''}", (s["volume"], s["pressure"]),
                        textcoords="offset points", xytext=(3, 3), fontsize=6)
    maxwell = run["attrs"]["maxwell_pressure"]
    if np.isfinite(maxwell):
        ax.axhline(maxwell, color="0.4", linestyle=":", linewidth=0.8, label=f"Maxwell $P_M$ = {maxwell:.5g}")
    ax.set_xscale("log")
    ax.set_xlabel("$V/V_0$")
    ax.set_ylabel("$P$")
    ax.set_title(f"{run['attrs']['scene_name']} (solid: stable under {control} control)")
    ax.legend()


def profiles(ax, run: dict, name: str, points=None) -> None:
    """The profiles r(Z) (ρ against the height η, both over the reference radius) of branch ``name`` at
    ``points`` (indices, negative from the end; default: PROFILES spread along the branch), coloured by V/V0."""
    b = run["branches"][name]
    disc, n = discretisation(run["attrs"]), len(b["pressure"])
    chosen = np.unique(np.linspace(0, n - 1, min(PROFILES, n)).round().astype(int)) if points is None else points
    s = np.linspace(0, disc.length, 401)
    colours = matplotlib_colours(len(chosen))
    for colour, i in zip(colours, chosen):
        if not -n <= i < n:
            raise TubePlotError(f"--points {i}: branch {name} has points 0..{n - 1}")
        rho, eta = disc.profile(b["unknowns"][i], s)
        ax.plot(eta, rho, color=colour, label=f"{i}: V/V0 = {b['volume'][i]:.3g}, P = {b['pressure'][i]:.4g}")
    ax.set_xlabel("$Z$")
    ax.set_ylabel("$r$")
    ax.set_title(f"{run['attrs']['scene_name']}: profiles of the {name} branch")
    ax.legend(fontsize=5)


def matplotlib_colours(count: int) -> list:
    """``count`` colours of the viridis map, from dark to light."""
    from matplotlib import colormaps

    return [colormaps["viridis"](x) for x in np.linspace(0.0, 0.9, count)]


def _runs(stable: np.ndarray, solid: bool) -> np.ndarray:
    """Which points a solid (stable) or dashed (unstable) line passes through: its own points and the next one, so
    that the two lines meet where the stability changes."""
    own = stable if solid else ~stable
    return own | np.concatenate([[False], own[:-1]])
