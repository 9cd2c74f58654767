"""The paper's figures (docs/paper.md): which runs each one draws (``Case``: a shipped scene with overrides) and
how (``PaperFigure.draw``: runs into a Figure), built from the plot kinds of ``plotting``. The runs themselves are
computed or reused by ``app.figures``.

Numbered configurations (Figs. 9–12): ``numbered_configurations`` picks them by rule from a run: 1 primary and
2 pear-shaped at the common pressure P* = the middle of the first pear branch's pressure range (1 on the
primary branch before its turning point TP, if it has one), 3 the last point of the primary branch (after the TP
where there is one, next to the wire), then the snap-throughs under the figure's stability reading
(``snap_throughs``: default pressure control), each as its pair (from, to): 4 → 5, 6 → 7. Figs. 10–12 number
the two-coil pair 8 (primary) and 9 (pear) at P*.
"""
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from importlib import resources

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from .plotting import P_LABEL, Configuration, PlotError, Reading, describe_scene, plot, stable_points
from .quantities import branch_discretisation
from . import labels
from .fit import fit_titles, fitted_legend
from .style import JournalFigure, journal_style
from ..analysis.switching.landscape import Landscape, LandscapeError, landscape, state_at
from ..analysis.branches.control import control_values, minimised_energy
from ..analysis.switching.mirror import MIRROR
from ..analysis.picture import Curve, find_snaps, located_folds
from ..analysis.results import Kind, Status
from ..galerkin.equilibrium import Equilibrium, Parameters
from ..io.run_file import stored_scene
from ..scene import Control, parse_scene

ONE_COLUMN, TWO_COLUMNS = 3.5, 7.2  # journal widths, inches
M_VALUES = (0.001, 0.002, 0.003)  # the several M of Figs. 3–8 (with M = 0 from the field-free scenes)
QUICK_M_VALUES = (0.001,)
QUICK = {"solver.degree": 12, "solver.max_degree": 60, "stability.degree": 8, "stability.m_max": 0,
         "continuation.max_points": 12, "continuation.step": 0.2, "continuation.step_max": 0.8}

@dataclass(frozen=True)
class Case:
    """One run a figure draws: the shipped scene ``scene`` (balloon_cg.scenes, by file stem) with ``overrides``
    (dotted keys, Scene.with_overrides), without the non-axisymmetric branches (``[surface] branches = "none"``)."""

    scene: str
    overrides: tuple[tuple[str, object], ...] = ()

    def load(self, quick: bool = False):
        """The Scene (``quick``: with the QUICK numerical settings, a reduced run for tests)."""
        text = (resources.files("balloon_cg.scenes") / f"{self.scene}.toml").read_text(encoding="utf-8")
        scene = parse_scene(text, self.scene)
        # the paper draws axisymmetric branches only: its runs leave out the non-axisymmetric ones
        overrides = {"surface.branches": "none"} | dict(self.overrides) | (QUICK if quick else {})
        return scene.with_overrides(overrides)


@dataclass(frozen=True)
class PaperFigure:
    """A figure of the paper: its caption (what it shows), the runs it draws and how (``draw(runs, figure,
    reading)``, runs in the order of ``cases``); ``height`` in units of the width."""

    name: str
    caption: str
    cases: tuple[Case, ...]
    draw: Callable
    height: float


# --- shared panels -----------------------------------------------------------------------------------------

def pear_only(run: dict) -> dict:
    """The run with its primary branch left out (the pear panels)."""
    return run | {"branches": {k: v for k, v in run["branches"].items() if k != "primary"}}


def primary_only(run: dict) -> dict:
    return run | {"branches": {"primary": run["branches"]["primary"]}}


def shared_legend(fig, axes, ncols: int = 4, markers: bool = True):
    """Replace the legends drawn inside ``axes`` by one legend below the figure (entries deduplicated by
    label; the title of the first; at most ``ncols`` columns, as many as fit: ``fit.fitted_legend``), with the
    key of the special-point markers (``markers``)."""
    handles, title = {}, None
    for ax in axes:
        legend = ax.get_legend()
        if legend is None:
            continue
        title = title or legend.get_title().get_text()
        for handle, text in zip(legend.legend_handles, legend.get_texts()):
            handles.setdefault(text.get_text(), handle)
        legend.remove()
    handles |= {h.get_label(): h for h in MARKER_KEY} if markers else {}
    fitted_legend(fig, list(handles.values()), list(handles), min(ncols, len(handles)), title=title,
                  loc="outside lower center")


MARKER_KEY = [Line2D([], [], linestyle="none", marker=m, markerfacecolor="0.7", markeredgecolor="k",
                     markeredgewidth=0.5, label=text)
              for m, text in (("o", "LP fold"), ("s", "TP turn in λ2(0)"), ("D", "BP branch point"), ("X", "EP end"))]


def _scratch_axes():
    """An Axes of a figure that is never saved: the unused panel of a two-panel kind."""
    return Figure().add_subplot()


def _letter(ax, index: int, text: str):
    """The panel's title: its letter and what it shows (in place of the kind's own title)."""
    ax.set_title("")
    ax.set_title(f"({'abcdefgh'[index]}) {text}", loc="left")


def curve_panels(kind: str, panel: int | None) -> Callable:
    """A draw function for Figs. 2–8: a 2×2 grid of P against ``kind`` (``pressure-pole``, or ``pressure-equator``
    with ``panel`` 0 for λ2(π/2), 1 for λ1(π/2)), rows SPOM1 then TPOM1 (Fig. 2: four materials), columns primary
    and pear branches (Fig. 2: all branches in one panel)."""

    def draw(runs, fig, reading):
        axes = fig.subplots(2, 2).ravel()
        groups = _material_groups(runs)
        columns = len(groups) == 2
        targets = []
        for row, (material, members) in enumerate(groups.items()):
            for col, select in enumerate((primary_only, pear_only) if columns else (None,)):
                ax = axes[2 * row + col] if columns else axes[row]
                sources = [select(r) for r in members] if select else members
                sources = [s for s in sources if s["branches"]]
                if not sources:
                    ax.text(0.5, 0.5, "no pear branch traced", transform=ax.transAxes, ha="center")
                    ax.set_xlabel(_x_label(kind, panel))
                    continue
                pair = [_scratch_axes(), _scratch_axes()]
                pair[panel or 0] = ax
                plot(sources, kind, axes=ax if panel is None else pair, stability=reading)
                ax.set_ylabel(P_LABEL)  # pressure-equator labels only its first panel
                targets += [ax] if panel is None else pair
                which = ("primary", "pear-shaped")[col] if columns else ""
                _letter(ax, 2 * row + col if columns else row, f"{material} {which}".strip())
        shared_legend(fig, targets)
        fig.suptitle(_coils_line(runs))

    return draw


def _material_groups(runs) -> dict:
    groups = {}
    for run in runs:
        groups.setdefault(stored_scene(run).material.name, []).append(run)
    return groups


def _coils_line(runs) -> str:
    return "; ".join(dict.fromkeys(describe_scene(stored_scene(r)).partition(", ")[2] for r in runs))


def _x_label(kind, panel):
    return {None: r"pole stretch $\lambda_2(0)$ (top)", 0: r"equator stretch $\lambda_2(\pi/2)$ (circumferential)",
            1: r"equator stretch $\lambda_1(\pi/2)$ (meridional)"}[panel]


# --- numbered configurations -------------------------------------------------------------------------------

CONTROL = {Reading.VOLUME: Control.VOLUME, Reading.FREE_VOLUME: Control.VOLUME, Reading.GAS: Control.GAS,
           Reading.FREE_GAS: Control.GAS}  # the control of a reading; the others: pressure
SNAP_READINGS = (Reading.PRESSURE, Reading.VOLUME, Reading.GAS, Reading.FREE, Reading.FREE_VOLUME, Reading.FREE_GAS,
                 Reading.AXISYMMETRIC)


def snap_throughs(run: dict, reading: Reading = Reading.PRESSURE) -> list:
    """The snap-throughs of a stored run with stability read as ``reading`` (``analysis.picture.find_snaps`` on
    the stored flags or blocks, ``plotting.stable_points``): at equal value of the reading's control (P, V or
    n = P V) to the stable point of lowest energy that control minimises (``analysis.branches.control.minimised_energy``),
    E the Galerkin energy of the stored unknowns. Branches without stability data are left out, and so are
    surface branches (m ≥ 1: no Galerkin unknowns); ``pressure`` of each result is the control value."""
    if reading not in SNAP_READINGS:
        raise PlotError(f"--stability {reading.value}: no snap-through search for this reading (one of "
                        f"{', '.join(r.value for r in SNAP_READINGS)})")
    scene = stored_scene(run)
    control = CONTROL.get(reading, Control.PRESSURE)
    curves = []
    for name, data in run["branches"].items():
        stable = stable_points(data, reading)
        if stable is None or data["attrs"].get("m", 0):
            continue
        disc = branch_discretisation(data)
        eq, M, chi = Equilibrium(scene, disc), data["attrs"]["M"], data["attrs"]["chi"]
        P, V = data["pressure"], data["volume"]
        voltage = data.get("voltage", np.zeros_like(P))
        E = np.array([eq.energy(X[:disc.size], Parameters(p, M, chi, phi)) for X, p, phi in
                      zip(data["unknowns"], P, voltage)])
        q = voltage if data["attrs"].get("parameter") == "voltage" else control_values(P, V, control)
        special = [(Kind(s["kind"]), Status(s["status"]), s["index"], X)
                   for s, X in zip(data["special_points"], data["special_unknowns"])]
        curves.append(Curve(name, q, stable, minimised_energy(E, P, V, control),
                            located_folds(disc, special, control)))
    return find_snaps(curves)


def numbered_configurations(run: dict, first: int = 1, snaps: bool = True,
                            reading: Reading = Reading.PRESSURE) -> dict[int, Configuration]:
    """The paper's numbered configurations of a run by number (module docstring): ``first`` primary and
    ``first`` + 1 pear-shaped at P*, ``first`` + 2 the last primary point, then each snap-through's (from, to)
    pair under ``reading`` (``snap_throughs``). Without a pear branch there is no ``first`` + 1, and P* is the
    middle of the primary pressure range."""
    branches = run["branches"]
    primary = branches["primary"]
    pear = next((name for name in branches if name.startswith("pear") and not name.endswith("_mirror")), None)
    turning = [s["index"] for s in primary["special_points"] if s["kind"] == "TP"]
    before = slice(0, turning[0] + 1 if turning else len(primary["pressure"]))
    P = primary["pressure"]
    target = 0.5 * (branches[pear]["pressure"].min() + branches[pear]["pressure"].max()) if pear else np.median(P)
    chosen = {first: ("primary", int(np.abs(P[before] - target).argmin())), first + 2: ("primary", len(P) - 1)}
    if pear:
        chosen[first + 1] = (pear, int(np.abs(branches[pear]["pressure"] - target).argmin()))
    pairs = [(s.from_branch, s.from_index, s.to_branch, s.to_index)
             for s in (snap_throughs(run, reading) if snaps else ()) if s.to_branch]
    for k, (source, i, target_branch, j) in enumerate(pairs):
        chosen[first + 3 + 2 * k] = (source, int(i))
        chosen[first + 4 + 2 * k] = (target_branch, int(j))
    return {n: Configuration(branch, index, str(n), CONFIGURATION_COLORS[(n - 1) % len(CONFIGURATION_COLORS)])
            for n, (branch, index) in sorted(chosen.items())}


CONFIGURATION_COLORS = ("C0", "C1", "C2", "C3", "C4", "C5", "C6", "C8", "C9")  # one per number; no grey (C7)


def pick(configurations: dict, *numbers) -> list[Configuration]:
    """The configurations with these numbers that exist."""
    return [configurations[n] for n in numbers if n in configurations]


def mark_configurations(ax, run: dict, configurations):
    """The configurations' numbers at their (λ2(0), P) on a pressure-pole panel."""
    for c in configurations:
        data = run["branches"][c.branch]
        x, y = data["lam2_top"][c.index], data["pressure"][c.index]
        ax.plot(x, y, "o", markersize=3.5, markerfacecolor=c.color or "w", markeredgecolor="k", markeredgewidth=0.6)
        ax.annotate(c.label, (x, y), xytext=(3, 3), textcoords="offset points", fontsize="small", weight="bold")


def configurations_figure(two_coils: bool) -> Callable:
    """Figs. 9 and 10: (a) P against λ2(0) with the numbered configurations marked, (b) the shapes, (c), (d) σθ
    and σφ (Fig. 9: shapes 1–3, stresses 1, 2 and 3; Fig. 10: 8 and 9, stresses 8 and 9)."""

    def draw(runs, fig, reading):
        run = runs[0]
        numbered = numbered_configurations(run, first=8 if two_coils else 1, snaps=not two_coils, reading=reading)
        shapes = pick(numbered, 8, 9) if two_coils else pick(numbered, 1, 2, 3)
        groups = [pick(numbered, 8), pick(numbered, 9)] if two_coils else [pick(numbered, 1, 2), pick(numbered, 3)]
        panels = fig.subplot_mosaic([["a", "b"], ["c0", "d0"], ["c1", "d1"]], height_ratios=[1.4, 1, 1])
        plot(run, "pressure-pole", axes=panels["a"], stability=reading)
        mark_configurations(panels["a"], run, pick(numbered, 8, 9) if two_coils else numbered.values())
        _letter(panels["a"], 0, "equilibrium curves")
        plot(run, "shapes", points=shapes, axes=panels["b"])
        _letter(panels["b"], 1, "shapes")
        for k, (group, column) in enumerate(zip(groups, "cd")):
            pair = [panels[f"{column}0"], panels[f"{column}1"]]
            if group:
                plot(run, "stresses", points=group, axes=pair)
            else:
                _absent(pair, "configuration not traced")
            _letter(pair[0], 2 + k, f"stresses, configuration {', '.join(c.label for c in group) or '–'}")
        shared_legend(fig, list(panels.values()), ncols=3)
        fig.suptitle(describe_scene(stored_scene(run)) + f", M = {run['branches']['primary']['attrs']['M']:g}",
                     fontsize="small")

    return draw


def _absent(axes, text: str):
    """Empty θ panels that say why (the labels as if drawn)."""
    for ax in axes:
        ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center")
        ax.set_xlabel(r"material coordinate $\theta$ (rad)")


def per_point_columns(kind: str, rows: int) -> Callable:
    """Figs. 11 and 12: ``kind`` (field: H_θ and H_ζ; curvature: κ) of configurations (a) 1, 2, (b) 3 of the
    single-coil run and (c) 8, 9 of the two-coil run."""

    def draw(runs, fig, reading):
        single, double = runs
        one = numbered_configurations(single, snaps=False)
        two = numbered_configurations(double, first=8, snaps=False)
        columns = [(single, pick(one, 1, 2)), (single, pick(one, 3)), (double, pick(two, 8, 9))]
        axes = fig.subplots(rows, 3, squeeze=False)
        for k, (run, group) in enumerate(columns):
            if group:
                plot(run, kind, points=group, axes=list(axes[:, k]) if rows > 1 else axes[0, k])
            else:
                _absent(axes[:, k], "configuration not traced")
            word = "config." if fig.get_size_inches()[0] < COMPACT_WIDTH else "configuration"
            _letter(axes[0, k], k, f"{word} {', '.join(c.label for c in group) or '–'}")
        shared_legend(fig, axes.ravel(), ncols=3, markers=False)
        fig.suptitle(f"{describe_scene(stored_scene(single))}; {_coils_line([double])}")

    return draw


# --- energy landscape --------------------------------------------------------------------------------------

LANDSCAPE_OFFSET = 0.01  # |P − P_cr| of Fig. 13, toward the side of the pear branch
AMPLITUDE_NORMALISATION = (r"$\Lambda=\varphi\cdot(u-u_s)$, $\varphi$ the unit vector (Euclidean norm of the "
                           r"Legendre coefficients) from the symmetric state $u_s$ to the pear state at that $P$")
# (no spaces inside the math: draw_energy wraps it at spaces)


def offset_landscape(run: dict, bp: dict, offset: float = LANDSCAPE_OFFSET) -> Landscape:
    """``analysis.switching.landscape`` at P = P_bp ± ``offset`` next to the pear branch point ``bp`` of the primary branch:
    on the side of the pear branch whose end lies nearest the point (its first or last 15 points), the pear state
    and the symmetric state at that P solved from the nearest stored points (the primary's within 5 of the
    point's index), on the pear branch's discretisation. LandscapeError if there is no pear branch or a solve
    fails."""
    scene, primary = stored_scene(run), run["branches"]["primary"]
    ends = [(abs(data["pressure"][end] - bp["pressure"]), name, end) for name, data in run["branches"].items()
            if name != "primary" and not name.endswith(MIRROR) and not data["attrs"].get("m", 0)
            for end in (0, len(data["pressure"]) - 1)]
    if not ends:
        raise LandscapeError("no pear branch traced")
    _, name, end = min(ends)
    pear = run["branches"][name]
    near = np.arange(len(pear["pressure"]))[:15] if end == 0 else np.arange(len(pear["pressure"]))[-15:]
    P = bp["pressure"] + np.sign(np.mean(pear["pressure"][near]) - bp["pressure"]) * offset
    disc, primary_disc = branch_discretisation(pear), branch_discretisation(primary)
    eq, params = Equilibrium(scene, disc), Parameters(P, primary["attrs"]["M"], primary["attrs"]["chi"])
    guess = near[np.argmin(np.abs(pear["pressure"][near] - P))]
    u_pear = state_at(eq, params, pear["unknowns"][guess][:disc.size], P, scene.solver)
    around = np.arange(max(0, bp["index"] - 4), min(len(primary["pressure"]), bp["index"] + 6))
    start = around[np.argmin(np.abs(primary["pressure"][around] - P))]
    u_sym = state_at(eq, params, primary_disc.transfer(primary["unknowns"][start][:primary_disc.size], disc), P,
                     scene.solver)
    return landscape(eq, params, u_sym, u_pear, scene.solver)


def draw_energy(runs, fig, reading):
    """Fig. 13: ΔΠ(Λ) at LANDSCAPE_OFFSET from each pear pitchfork of the single-coil run (one panel each, by
    decreasing pressure: P_cr1 then P_cr2; ``offset_landscape``), its equilibria Λ* marked."""
    run = runs[0]
    points = sorted((s for s in run["branches"]["primary"]["special_points"]
                     if s["kind"] == "BP" and s["block"] == "odd_held" and np.isfinite(s["E4"])),
                    key=lambda s: -s["pressure"])
    axes = fig.subplots(1, max(2, len(points)), squeeze=False)[0]
    for k, ax in enumerate(axes):
        ax.set_xlabel(r"amplitude $\Lambda$ along the pear direction")
        ax.set_ylabel(r"$\Delta\Pi = E(\Lambda) - E(u_s)$ (per $2\pi$)")
        if k >= len(points):
            _letter(ax, k, f"$P_{{cr{k + 1}}}$: no classified branch point")
            continue
        s = points[k]
        kind = s["classification"].removeprefix("pitchfork-")
        try:
            land = offset_landscape(run, s)
        except LandscapeError as e:
            _letter(ax, k, f"$P_{{cr{k + 1}}}$ = {s['pressure']:.5g}, {kind}")
            ax.text(0.5, 0.5, f"not drawn: {e}", transform=ax.transAxes, ha="center", fontsize="x-small")
            continue
        _letter(ax, k, f"$P_{{cr{k + 1}}}$ = {s['pressure']:.4g}, {kind}\n"
                       f"at P = {land.pressure:.4g} ({land.pressure - s['pressure']:+.2g})")
        ax.axhline(0.0, color="0.6", linewidth=0.6)
        ax.plot(land.amplitude, land.energy, color="C0")
        for lam in land.equilibria:
            energy = np.interp(lam, land.amplitude, land.energy)
            ax.plot(lam, energy, "o", markersize=3.5, markerfacecolor="w", markeredgecolor="k")
            ax.annotate(f"{lam:.3g}", (lam, energy), xytext=(0, 4), textcoords="offset points", ha="center",
                        fontsize="x-small")
        ax.margins(y=0.12)  # room for the labels of Λ* at the extremes
    width = fig.get_size_inches()[0]
    fig.suptitle(f"{describe_scene(stored_scene(run))}, M = {run['branches']['primary']['attrs']['M']:g}; "
                 r"$\Lambda^*$ marked" + "\n" + textwrap.fill(AMPLITUDE_NORMALISATION, int(SUPTITLE_CHARS * width)),
                 fontsize="x-small")


SUPTITLE_CHARS = 22  # characters of the x-small suptitle per inch of width (wrapping)


# --- the figures -------------------------------------------------------------------------------------------

SINGLE_COIL = "spom1_paper_coil"  # the coil inferred from the paper's critical M (a = 1.961 at height 0: docs/paper.md)
SINGLE_COIL_REACH = (("continuation.stop_stretch", 6.0),)  # the isola reaches λ2(0) = 5.4 (spom1.toml)


def _family(single_coil: bool, quick: bool) -> tuple[Case, ...]:
    """SPOM1 then TPOM1: M = 0 (field-free scenes; not in quick runs) and the M values with one coil
    (SINGLE_COIL, its material replaced for TPOM1) or the paper's two coils (the shipped scenes)."""
    values = QUICK_M_VALUES if quick else M_VALUES
    cases = []
    for material in ("spom1", "tpom1"):
        cases += [] if quick else [Case(material)]
        if single_coil:
            preset = () if material == "spom1" else (("material.preset", "TPOM1"),)
            cases += [Case(SINGLE_COIL, preset + (("field.M", M),) + SINGLE_COIL_REACH) for M in values]
        else:
            cases += [Case(f"{material}_two_coils_M{M:g}") for M in values]
    return tuple(cases)


SINGLE_COIL_M0001 = Case(SINGLE_COIL, (("field.M", 0.001),) + SINGLE_COIL_REACH)
TWO_COILS_M0001 = Case("spom1_two_coils_M0.001")


def figures(quick: bool = False) -> dict[str, PaperFigure]:
    """Every figure of the paper by name (``quick``: fewer M values, for tests)."""
    one, two = _family(True, quick), _family(False, quick)
    return {f.name: f for f in (
        PaperFigure("fig2", "P against the pole stretch at M = 0: SPOM1, SPOM2, TPOM1, TPOM2",
                    tuple(Case(m) for m in ("spom1", "spom2", "tpom1", "tpom2")),
                    curve_panels("pressure-pole", None), 0.9),
        PaperFigure("fig3", "one coil: P against λ2(0), SPOM1 and TPOM1, primary and pear branches, several M",
                    one, curve_panels("pressure-pole", None), 1.0),
        PaperFigure("fig4", "one coil: P against λ2(π/2)", one, curve_panels("pressure-equator", 0), 1.0),
        PaperFigure("fig5", "one coil: P against λ1(π/2)", one, curve_panels("pressure-equator", 1), 1.0),
        PaperFigure("fig6", "two coils: P against λ2(0)", two, curve_panels("pressure-pole", None), 1.0),
        PaperFigure("fig7", "two coils: P against λ2(π/2)", two, curve_panels("pressure-equator", 0), 1.0),
        PaperFigure("fig8", "two coils: P against λ1(π/2)", two, curve_panels("pressure-equator", 1), 1.0),
        PaperFigure("fig9", "one coil, SPOM1, M = 0.001: configurations 1–7, shapes, stresses",
                    (SINGLE_COIL_M0001,), configurations_figure(False), 1.25),
        PaperFigure("fig10", "two coils, SPOM1, M = 0.001: configurations 8, 9, shapes, stresses",
                    (TWO_COILS_M0001,), configurations_figure(True), 1.25),
        PaperFigure("fig11", "applied field H_θ, H_ζ of configurations 1, 2 | 3 | 8, 9",
                    (SINGLE_COIL_M0001, TWO_COILS_M0001), per_point_columns("field", 2), 0.65),
        PaperFigure("fig12", "Gaussian curvature κ of configurations 1, 2 | 3 | 8, 9",
                    (SINGLE_COIL_M0001, TWO_COILS_M0001), per_point_columns("curvature", 1), 0.45),
        PaperFigure("fig13", f"energy landscape {LANDSCAPE_OFFSET:g} off the pear pitchforks, one coil, SPOM1, "
                    "M = 0.001",
                    (SINGLE_COIL_M0001,), draw_energy, 0.5),
    )}


COMPACT_WIDTH = 5.0  # inches: narrower figures (one column) get the symbols as axis labels, smaller markers
SHORT_LABELS = {  # the kinds' axis labels -> their symbols (units: docs/plots.md, stated in the caption)
    P_LABEL: r"$P$", r"pole stretch $\lambda_2(0)$ (top)": r"$\lambda_2(0)$",
    r"equator stretch $\lambda_2(\pi/2)$ (circumferential)": r"$\lambda_2(\pi/2)$",
    r"equator stretch $\lambda_1(\pi/2)$ (meridional)": r"$\lambda_1(\pi/2)$",
    r"material coordinate $\theta$ (rad)": r"$\theta$", r"$\pm\rho/R_0$ (distance from the axis)": r"$\pm\rho/R_0$",
    r"$\eta/R_0$ (height)": r"$\eta/R_0$", r"$\sigma_\theta$ / ($\mu$/2)": r"$\sigma_\theta$",
    r"$\sigma_\phi$ / ($\mu$/2)": r"$\sigma_\phi$", r"$H_\theta$ / ($I/4\pi R_0$)": r"$H_\theta$",
    r"$H_\zeta$ / ($I/4\pi R_0$)": r"$H_\zeta$", r"Gaussian curvature $\kappa R_0^2$": r"$\kappa R_0^2$",
    r"amplitude $\Lambda$ along the pear direction": r"$\Lambda$",
    r"$\Delta\Pi = E(\Lambda) - E(u_s)$ (per $2\pi$)": r"$\Delta\Pi$",
}
COMPACT_MARKER = 3.0  # points
COMPACT_HEIGHT = 1.5  # a narrow figure's height in units of ``PaperFigure.height`` × width: its panels stacked


def compact(fig):
    """Fit a narrow figure: axis labels by their symbols (SHORT_LABELS), special-point markers COMPACT_MARKER
    points."""
    for ax in fig.axes:
        ax.set_xlabel(SHORT_LABELS.get(ax.get_xlabel(), ax.get_xlabel()))
        ax.set_ylabel(SHORT_LABELS.get(ax.get_ylabel(), ax.get_ylabel()))
        for line in ax.get_lines():
            if line.get_marker() not in ("None", "", None):
                line.set_markersize(min(line.get_markersize(), COMPACT_MARKER))


def draw_figure(figure: PaperFigure, runs: list[dict], width: float = TWO_COLUMNS,
                reading: Reading = Reading.PRESSURE) -> Figure:
    """The Figure of ``figure`` from its runs, ``width`` inches wide (below COMPACT_WIDTH: ``compact``, and
    COMPACT_HEIGHT times taller for its width; titles wrapped to fit: ``fit.fit_titles``), drawn and saved in the
    journal style (``style``)."""
    height = figure.height * width * (COMPACT_HEIGHT if width < COMPACT_WIDTH else 1.0)
    fig = JournalFigure(figsize=(width, height), layout="constrained")
    with journal_style(), labels.unlabelled():  # markers only: their key is in the legend
        figure.draw(runs, fig, Reading(reading))
    if width < COMPACT_WIDTH:
        compact(fig)
    fit_titles(fig)
    return fig


