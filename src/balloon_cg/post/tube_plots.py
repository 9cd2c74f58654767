"""What people look at on a tube (a tube run file, io/tube_file.py), in the journal style: P against V/V0 of every
branch with Maxwell's line (``pressure_volume``), the family of profiles r(z) of a branch (``profiles``), the bulge's
front, its position and width against V/V0 (``front_motion``), and the hoop and axial stretches along the deformed
axis at a few states (``stretch_profiles``; post/tube_measures.py measures both), the critical modes of a
branch's located m ≥ 1 zeros (``critical_modes``), and the onset curve of ``critical`` (``onset_curve``: the onset's
P and largest hoop stretch against its parameter). Profiles, stretches and the front read one axial coordinate, the
distance z along the deformed axis from the end S = 0 (tube_measures.along: where a bulge forms), the modes its
reference S: every figure has that end on the left.

Curves are solid where a point is stable under the chosen control (default: the run's loading.control; no negative
eigenvalue of the second variation under it: the file's ``unstable_pressure``/``unstable_volume``/``unstable_gas``,
tube/stability.py) and dashed where it is not; located points are marked and labelled with the number ``inspect``
lists and ``continue`` takes ("1 BP odd", post/labels.py: clear of one another and of the curves), placed once the
figure is laid out at its width; titles are wrapped to the figure, and a legend stays inside the panel only where it
hides nothing drawn, else it goes under it (post/fit.fit_with_legend). Legend entries follow the labels: the primary
branch, then each switched branch in the order of the label of its branch point ("bulge" from 1, "bulge_2" from 2,
…, "bulge_10" from 10: the names are the labels ``continue`` takes, never renumbered).
"""
import numpy as np

from .fit import MAX_WIDTH, MIN_WIDTH, fit_with_legend
from .labels import label_points
from .style import JournalFigure, journal_style
from .tube_measures import SAMPLES, along, fronts, stretches
from ..io.tube_file import discretisation, tube_labels
from ..tube.azimuthal import mode_profile

TUBE_KINDS = ("pressure-volume", "profiles", "front", "stretches", "modes", "onset")
CONTROLS = ("pressure", "volume", "gas")
PROFILES = 8  # profiles drawn along a branch unless the points are given
STRETCHED = 3  # states whose stretches are drawn unless the points are given
_COLOURS = {"primary": "k", "bulge": "C0"}
DISTANCE = "$z$, from the end $S = 0$"  # the axial coordinate of profiles, stretches and the front (module docstring)
VOLUME = "$V/V_0$"
PROFILE_KEY = f"point: {VOLUME}, $P$"  # the title of the profiles' legend, its entries "26: 2.81, 1.241"


class TubePlotError(ValueError):
    """A figure a tube run file cannot give (exit code 2)."""


def tube_figure(run: dict, what: str, control: str | None = None, branch: str | None = None, points=None,
                width: float = 3.5):
    """The figure of kind ``what`` (TUBE_KINDS) of a tube run (read_tube_run output); ``control``: the stability
    reading (None: the run's loading.control)."""
    if what not in TUBE_KINDS:
        raise TubePlotError(f"--what {what}: not drawn for a tube run file; allowed: {', '.join(TUBE_KINDS)}")
    if not MIN_WIDTH <= width <= MAX_WIDTH:
        raise TubePlotError(f"--width {width:g}: must be in [{MIN_WIDTH:g}, {MAX_WIDTH:g}] inches (3.5 one column, "
                            "7.2 two)")
    control = run["attrs"]["control"] if control is None else control
    if control not in CONTROLS:
        raise TubePlotError(f"--stability {control}: allowed for a tube: {', '.join(CONTROLS)}")
    if any(f"unstable_{control}" not in b for b in run["branches"].values()):
        raise TubePlotError(f"--stability {control}: this file (written before gas control) has no "
                            f"unstable_{control}; allowed here: pressure, volume")
    with journal_style():
        fig = JournalFigure(figsize=(width, 0.75 * width), layout="constrained")
        ax = fig.add_subplot()
        if what == "pressure-volume":
            pressure_volume(ax, run, control)
        elif what == "onset":
            onset_curve(ax, run)
        else:
            name = branch or ("bulge" if "bulge" in run["branches"] else "primary")
            if name not in run["branches"]:
                raise TubePlotError(f"--branch {name}: not in the file; it has {', '.join(run['branches'])}")
            draw = {"profiles": profiles, "front": front_motion, "stretches": stretch_profiles,
                    "modes": critical_modes}[what]
            draw(ax, run, name, points)
        fit_with_legend(fig, ax, width, **({"title": PROFILE_KEY} if what == "profiles" else {}))
    return fig


def pressure_volume(ax, run: dict, control: str) -> None:
    """P against V/V0 of every branch, solid where stable under ``control``, the located points labelled, the
    non-axisymmetric branches (/surface_branches: thinner, labelled with their m, their folds LP) beside them, and
    Maxwell's pressure as a dotted line where the file has one."""
    others = iter(f"C{k}" for k in range(1, 10_000))  # a colour of its own for every other switched branch
    colours = {}
    for name, b in sorted(run["branches"].items(), key=_born):
        colour = colours[name] = _COLOURS.get(name) or next(others)
        _curve(ax, b, control, colour, name)
    marks = []
    for label, (name, _, s) in enumerate(tube_labels(run)):
        ax.plot(s["volume"], s["pressure"], "o", color=colours[name], markersize=3)
        marks.append((ax, label, " ".join(filter(None, (s["kind"], s["block"]))), s["volume"], s["pressure"],
                      colours[name]))
    for name, b in run.get("surface_branches", {}).items():
        colour = next(others)
        _curve(ax, b, control, colour, f"{name} ($m$ = {b['attrs']['m']})", 0.8)
        for index, pressure in b["folds"]:
            ax.plot(b["volume"][index], pressure, "o", color=colour, markersize=3)
            ax.annotate("LP", (b["volume"][index], pressure), textcoords="offset points", xytext=(3, 3), fontsize=6)
    maxwell = run["attrs"]["maxwell_pressure"]
    if np.isfinite(maxwell):
        ax.axhline(maxwell, color="0.4", linestyle=":", linewidth=0.8, label=f"Maxwell $P_M$ = {maxwell:.5g}")
    ax.set_xscale("log")
    ax.set_xlabel(VOLUME)
    ax.set_ylabel("$P$")
    ax.set_title(f"{run['attrs']['scene_name']} (solid: stable under {control} control)")
    label_points(marks)


def _born(item) -> tuple:
    """The legend's order of a branch (name, group): the primary branch, then by the label of the branch point it was
    switched at (its ``parent_label``), then by name."""
    name, b = item
    return name != "primary", int(b["attrs"].get("parent_label", -1)), name


def profiles(ax, run: dict, name: str, points=None) -> None:
    """The profiles r(z) (the radius ρ against the distance z along the deformed axis from the end S = 0, both over
    the reference radius) of branch ``name`` at ``points`` (indices, negative from the end; default: PROFILES spread
    along the branch), coloured by V/V0; each labelled with its index, V/V0 and P (PROFILE_KEY)."""
    b = run["branches"][name]
    disc = discretisation(run["attrs"], b["attrs"])
    chosen = _chosen(len(b["pressure"]), name, points, PROFILES)
    s = np.linspace(0, disc.length, 401)
    colours = matplotlib_colours(len(chosen))
    for colour, i in zip(colours, chosen):
        ax.plot(*along(disc, b["unknowns"][i], s), color=colour,
                label=f"{i}: {b['volume'][i]:.3g}, {b['pressure'][i]:.4g}")
    ax.set_xlabel(DISTANCE)
    ax.set_ylabel("$r$")
    ax.set_title(f"{run['attrs']['scene_name']}: profiles of the {name} branch")


def front_motion(ax, run: dict, name: str, points=None) -> None:
    """The front of branch ``name``'s profiles at ``points`` (default: every point) against V/V0, as
    tube_measures.front measures it: its position z_f, the distance along the deformed axis from the end S = 0
    (left axis), and its width w (right axis); of a bulge in the middle or at both ends (two fronts) the one nearest
    S = 0; the points whose profile has no front (uniform, a bump, or a front wider than either part: near the
    onset) are not drawn, their V/V0 range shaded "no front"; a branch with no front
    at any of them has none to draw (TubePlotError)."""
    b = run["branches"][name]
    chosen = _chosen(len(b["pressure"]), name, points, len(b["pressure"]))
    _, deformed = fronts(discretisation(run["attrs"], b["attrs"]), b["unknowns"][chosen])
    position, width = (np.array([getattr(f, key) for f in deformed]) for key in ("position", "width"))
    if np.isnan(position).all():
        raise TubePlotError(f"--what front: the {name} branch's profiles have no front at the points drawn (uniform, "
                            "a bump, or no part as long as the front is wide)")
    volume = b["volume"][chosen]
    ax.plot(volume, position, color="C0", label="position $z_f$")
    ax.set(xlabel=VOLUME, title=f"{run['attrs']['scene_name']}: the front of the {name} branch")
    ax.set_ylabel("position $z_f$, from the end $S = 0$", color="C0")
    widths = ax.twinx()
    widths.plot(volume, width, color="C1", label="width $w$")
    widths.set_ylabel("width $w$", color="C1")
    if np.isnan(position).any():  # each run of front-less points its own band (one band hid the fronts between)
        ax.fill_between(volume, 0, 1, where=np.isnan(position), transform=ax.get_xaxis_transform(), step="mid",
                        color="0.9", zorder=0, label="no front")


def stretch_profiles(ax, run: dict, name: str, points=None) -> None:
    """The hoop stretch λ2 (solid) and the axial stretch λ1 (dashed) against the distance z along the deformed axis
    from the end S = 0 (as ``profiles``), of branch ``name`` at ``points`` (default: STRETCHED spread along the
    branch), coloured by V/V0."""
    b = run["branches"][name]
    disc, s = discretisation(run["attrs"], b["attrs"]), np.linspace(0.0, run["attrs"]["length"], SAMPLES)
    chosen = _chosen(len(b["pressure"]), name, points, STRETCHED)
    for colour, i in zip(matplotlib_colours(len(chosen)), chosen):
        u = b["unknowns"][i]
        axial, hoop = stretches(disc, u, s)
        z = along(disc, u, s)[0]
        ax.plot(z, hoop, color=colour, label=f"$\\lambda_2$, {VOLUME} = {b['volume'][i]:.3g}")
        ax.plot(z, axial, color=colour, linestyle="--", label=f"$\\lambda_1$, {VOLUME} = {b['volume'][i]:.3g}")
    ax.set(xlabel=DISTANCE, ylabel="stretch",
           title=f"{run['attrs']['scene_name']}: hoop (solid) and axial (dashed) stretch, {name} branch")


def critical_modes(ax, run: dict, name: str, points=None) -> None:
    """The critical modes of branch ``name``'s located m ≥ 1 zeros (tube/azimuthal.critical_mode, the file's
    ``critical_modes``): R (solid), T (dashed) and Z (dotted) of δx = R cos mφ e_ρ + T sin mφ e_φ + Z cos mφ e_z
    against the reference arclength S, one colour per zero (``points``: their indices, default all); a branch
    without a stored one has none to draw (TubePlotError)."""
    located = [(m, p) for m, block in run["branches"][name]["azimuthal"].items() for p in block["points"]
               if p["mode"] is not None]
    if not located:
        raise TubePlotError(f"--what modes: the {name} branch has no located m ≥ 1 zero with a stored mode")
    chosen = _chosen(len(located), name, points, len(located))
    disc = discretisation(run["attrs"], run["branches"][name]["attrs"])
    s = np.linspace(0.0, run["attrs"]["length"], SAMPLES)
    for colour, k in zip(matplotlib_colours(len(chosen)), chosen):
        m, p = located[k]  # m: "1 held" (io/tube_file.HELD_M1) for a zero of the held tube's block
        for values, style, part in zip(mode_profile(disc, p["mode"], s), ("-", "--", ":"), "RTZ"):
            ax.plot(s, values, color=colour, linestyle=style,
                    label=f"${part}$, $m$ = {m}, $P$ = {p['pressure']:.6g}")
    ax.set(xlabel="$S$", ylabel="amplitude ($\\frac{1}{2}\\int (R^2 + T^2 + Z^2)\\,dS = 1$)",
           title=f"{run['attrs']['scene_name']}: critical modes, {name} branch")


def onset_curve(ax, run: dict) -> None:
    """The onset curve of ``critical`` (/onset, tube/onset.py): the onset's P (left axis) and its largest hoop
    stretch (right axis) against the curve's parameter q, its folds in q marked (the critical value); a file without
    one has none to draw (TubePlotError)."""
    onset = run["onset"]
    if onset is None:
        raise TubePlotError("--what onset: the file has no onset curve (written by balloon-cg critical on a tube)")
    name = onset["attrs"]["parameter"]
    symbol = {"axial_stretch": "$\\lambda$", "voltage": "$\\bar\\Phi$"}.get(name, name)
    ax.plot(onset["q"], onset["pressure"], color="C0")
    middle = 0.5 * (np.min(onset["q"]) + np.max(onset["q"]))
    for f in onset["folds"]:  # its text towards the middle of the curve's range: a fold in q is at one of its ends
        ax.plot(f["q"], f["pressure"], "o", color="C0", markersize=3)
        left = f["q"] > middle
        ax.annotate(f"LP {symbol} = {f['q']:.5g}", (f["q"], f["pressure"]), textcoords="offset points",
                    xytext=(-3 if left else 3, 3), ha="right" if left else "left", fontsize=6)
    labels = {"axial_stretch": "$\\lambda$ (ends held at $\\lambda L$)"}
    ax.set(xlabel=labels.get(name, symbol), title=f"{run['attrs']['scene_name']}: onset of bulging against {symbol}")
    ax.set_ylabel("onset $P$", color="C0")
    hoops = ax.twinx()
    hoops.plot(onset["q"], onset["hoop_stretch"], color="C1", linestyle="--")
    hoops.set_ylabel("onset's largest hoop stretch", color="C1")


def _chosen(n: int, name: str, points, count: int) -> np.ndarray:
    """The indices of the ``n`` points (of branch ``name``, or its located zeros) to draw: ``points`` (checked,
    negative from the end) or ``count`` spread evenly among them."""
    if points is not None and not len(points):
        raise TubePlotError(f"--points: none given for branch {name}")
    if points is None:
        return np.unique(np.linspace(0, n - 1, min(count, n)).round().astype(int))
    for i in points:
        if not -n <= i < n:
            raise TubePlotError(f"--points {i}: branch {name} has points 0..{n - 1}")
    return np.asarray(points, dtype=int) % n


def matplotlib_colours(count: int) -> list:
    """``count`` colours of the viridis map, from dark to light."""
    from matplotlib import colormaps

    return [colormaps["viridis"](x) for x in np.linspace(0.0, 0.9, count)]


def _curve(ax, b: dict, control: str, colour: str, label: str, width: float | None = None) -> None:
    """Branch ``b``'s P against V/V0, solid where stable under ``control`` and dashed where not, ``label``led."""
    stable = b[f"unstable_{control}"] == 0
    for solid in (True, False):
        shown = np.where(_runs(stable, solid), b["pressure"], np.nan)
        ax.plot(b["volume"], shown, color=colour, linestyle="-" if solid else "--", linewidth=width,
                label=label if solid else None)


def _runs(stable: np.ndarray, solid: bool) -> np.ndarray:
    """Which points a solid (stable) or dashed (unstable) line passes through: its own points and the next one, so
    that the two lines meet where the stability changes."""
    own = stable if solid else ~stable
    return own | np.concatenate([[False], own[:-1]])
