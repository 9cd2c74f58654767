"""Figures from run files or results in memory (docs/plots.md). Every plot function returns a matplotlib Figure:
a new one on the Agg canvas (no pyplot, no global backend state; save it with ``figure.savefig(path)``: a
``style.JournalFigure``, saved in the journal style), or,
given ``axes``, the figure of the caller's Axes (one Axes, or a sequence for the kinds with several panels),
drawn into them with the legend inside the first.

Curves of branches (pressure-pole, pressure-equator: P against a stretch; voltage-pole, voltage-equator: the
voltage Φ̄ against a stretch, for runs continued in the voltage at fixed P) and the energy landscape draw every
branch of every file (or the one named); a branch curve whose ordinate is not the branch's continuation parameter
(a constant) is refused (``check_ordinate``); the per-point kinds (shapes, stresses, field, curvature) draw chosen
points of one branch per file (default: primary), or chosen ``Configuration`` s of several branches. One colour
per drawn branch, labelled by M (branch attrs; a dielectric branch also by its fixed Φ̄ or P), plus the branch
name when a file holds several; a mirror-image branch (``<name>_mirror``) takes its partner's colour, drawn
thinner and lighter. Several files: a colour family per branch kind (primary, pear, free pear, m = 1, …) and a
shade per file, so that kinds never share a colour (``family_colors``). Branch curves are solid where stable and dashed where unstable under the chosen stability
``Reading`` (default: the run's loading control, balloon held at its centre), named in the legend title; without
stability data all solid, and the legend title says so. Titles name the material and the coils. Special points
are marked and labelled with their label in the file and their kind ("2 LP", "3 pitchfork-super": ``labels``).
Surface branches (m ≥ 1, states on the whole sphere) are drawn by the pole curves and the energy landscape,
labelled 'm = 1 from 5' (their parent point's label), and left out of the other branch and per-point kinds;
``surface`` (3D) and ``stretch-map`` (λ1, λ2 over (φ, θ)) draw one of their states; a capsule's (over (θ, φ):
``meridian_branches``) are drawn by the same code, but for stretch-map.
The θ plots limit y to the bulk of the data when a near-wire spike would flatten the rest (``robust_limits``).
Units are nondimensional (MODEL.md §2): P = P̄R0/(T0 μ/2), Φ̄ = (Φ/H)√(ε/μ), lengths in R0, stresses in μ/2,
field in I/(4π R0).
"""
import contextvars
import enum
import re
from dataclasses import dataclass
from pathlib import Path

import h5py
import matplotlib
import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator
from scipy.interpolate import PchipInterpolator

from .quantities import branch_discretisation, postprocess, surface
from .fit import MAX_WIDTH, MIN_WIDTH, NARROW, covers, fit_width, fitted_size
from .labels import label_points
from .meridian_branches import stored_meridian_basis, with_meridian_branches
from .style import JournalFigure, journal_style
from ..analysis.results import Block
from ..galerkin.profiles import EQUATOR
from ..io.curve_file import curve_meetings, read_curve
from ..io.layout import FileError, check_input, file_kind, reading
from ..io.parents import non_axisymmetric, parent_label
from ..io.run_file import read_run, stored_basis, stored_scene
from ..io.sweep_file import read_sweep
from ..model.meridian import hoop, reference_height
from ..scene.tables import Shape
from ..scene.validation import did_you_mean

NORMAL_FORM = ("E2", "E3", "E4")
DEFAULT_POINTS = 5
THETA_SAMPLES = 721  # θ values of the per-point curves, evaluated from the Legendre series (finer than stored)
MARKERS = {"LP": "o", "TP": "s", "EP": "X"}  # branch points and other kinds: "D"

P_LABEL = r"pressure $P = \bar{P}R_0/(T_0\mu/2)$"
VOLTAGE_LABEL = r"voltage $\bar\Phi = (\Phi/H)\sqrt{\varepsilon/\mu}$"
THETA_LABEL = r"material coordinate $\theta$ (rad)"


MIRROR_SUFFIX = "_mirror"  # analysis.picture names the mirror image of pear branch <name> <name>_mirror


class PlotError(ValueError):
    """A figure that cannot be drawn from the given files (missing branch, data or point)."""


class Reading(enum.StrEnum):
    """Which stability flag draws a branch solid (stable) or dashed (docs/hdf5.md, stability/).

    The stored flags: ``pressure`` stable_pressure (balloon held at its centre, pressure control), ``volume``
    stable_volume (held, volume control: the gas enclosed), ``free`` stable_pressure_free (axial translation
    included, pressure control), ``free-volume`` stable_volume_free, ``gas`` stable_gas (held, gas control: a
    fixed amount of isothermal gas), ``free-gas`` stable_gas_free. ``axisymmetric`` is the paper's reading:
    held, pressure control, the axisymmetric blocks only (lowest_even and lowest_odd_held, or lowest_all_held
    off the equator-symmetric layout), i.e. the m ≥ 1 blocks ignored.
    """

    PRESSURE = "pressure"
    VOLUME = "volume"
    FREE = "free"
    FREE_VOLUME = "free-volume"
    GAS = "gas"
    FREE_GAS = "free-gas"
    AXISYMMETRIC = "axisymmetric"

    @property
    def meaning(self) -> str:
        return READING_MEANINGS[self]

    @classmethod
    def parse(cls, text: str) -> "Reading":
        """The reading named ``text`` (PlotError naming the allowed ones otherwise)."""
        try:
            return cls(text)
        except ValueError:
            raise PlotError(f"--stability {text!r}: not a stability reading (choose one of "
                            f"{', '.join(r.value for r in cls)})") from None

    @classmethod
    def of_run(cls, run: dict) -> "Reading":
        """The held reading of a run's loading control (root attribute ``control``; pressure when absent)."""
        return cls(run["attrs"].get("control", cls.PRESSURE.value))


READING_MEANINGS = {
    Reading.PRESSURE: "pressure control, held at centre",
    Reading.VOLUME: "volume control, held at centre",
    Reading.FREE: "pressure control, free balloon",
    Reading.FREE_VOLUME: "volume control, free balloon",
    Reading.GAS: "gas control, held at centre",
    Reading.FREE_GAS: "gas control, free balloon",
    Reading.AXISYMMETRIC: "axisymmetric modes only (paper)",
}
FLAGS = {Reading.PRESSURE: "stable_pressure", Reading.VOLUME: "stable_volume",
         Reading.FREE: "stable_pressure_free", Reading.FREE_VOLUME: "stable_volume_free", Reading.GAS: "stable_gas",
         Reading.FREE_GAS: "stable_gas_free"}
AXISYMMETRIC_BLOCKS = (("lowest_even", "lowest_odd_held"), ("lowest_all_held",))


VOLTAGE_MEANINGS = {  # the pressure readings on a voltage branch: P is fixed, Φ̄ the control
    Reading.PRESSURE: "voltage control at fixed P, held at centre",
    Reading.FREE: "voltage control at fixed P, free balloon",
}


@dataclass(frozen=True)
class Ordinate:
    """The y quantity of a branch curve: the continuation ``parameter`` it must be (the stored branch attribute
    ``parameter``: "P", "voltage" or "M"), its per-point and special-point ``column``, its axis ``label``, its
    ``symbol`` in legends and the ``prefix`` of the kinds that draw it ("<prefix>-pole", "<prefix>-equator")."""

    parameter: str
    column: str
    label: str
    symbol: str
    prefix: str


PRESSURE_ORDINATE = Ordinate("P", "pressure", P_LABEL, "P", "pressure")
VOLTAGE_ORDINATE = Ordinate("voltage", "voltage", VOLTAGE_LABEL, r"$\bar\Phi$", "voltage")
FIELD_ORDINATE = Ordinate("M", "M", "field $M = I^2/(16\\pi^2 R_0^2 \\mu)$", "M", "M")  # continue --parameter M
ORDINATES = {o.parameter: o for o in (PRESSURE_ORDINATE, VOLTAGE_ORDINATE, FIELD_ORDINATE)}


def ordinate_of(data: dict) -> Ordinate:
    """A stored branch's continuation parameter as an Ordinate (P for files without the attribute)."""
    return ORDINATES[data["attrs"].get("parameter", "P")]


def stable_points(data: dict, reading: Reading) -> np.ndarray | None:
    """The per-point stability of a stored branch under ``reading`` (None when the branch has no such data):
    a stored flag, or for ``axisymmetric`` the lowest eigenvalue of every axisymmetric block > 0."""
    stability = data.get("stability", {})
    if reading != Reading.AXISYMMETRIC:
        flag = stability.get(FLAGS[reading])
        return None if flag is None else np.asarray(flag, dtype=bool)
    for blocks in AXISYMMETRIC_BLOCKS:
        if all(block in stability for block in blocks):
            return np.all([stability[block][:, 0] > 0 for block in blocks], axis=0)
    return None


@dataclass(frozen=True)
class Configuration:
    """A point to draw in the per-point kinds: point ``index`` (negative: from the end) of branch ``branch``,
    named ``label`` in the legend (e.g. the paper's configuration numbers), drawn in ``color`` (default: the
    next colour of the cycle), so that one configuration keeps its colour across figures."""

    branch: str
    index: int
    label: str
    color: str = ""


def named_points(points) -> bool:
    """Whether ``points`` is a non-empty sequence of Configurations (not indices)."""
    return isinstance(points, (list, tuple)) and len(points) > 0 and all(isinstance(p, Configuration) for p in points)


@dataclass
class StoredBranch:
    """One branch of a run (``run``: read_run() output, from a file or from memory) with its per-point
    stability under the chosen reading (None if the run has none), a label and a colour for legends."""

    run: dict
    name: str
    stable: np.ndarray | None
    label: str = ""
    color: str = "C0"
    reading: Reading = Reading.PRESSURE

    @property
    def mirror(self) -> bool:
        """Whether this is the mirror image (about the equator) of another pear branch."""
        return self.name.endswith(MIRROR_SUFFIX)

    @property
    def data(self) -> dict:
        return self.run["branches"][self.name]

    @property
    def M(self) -> float:
        return float(self.data["attrs"]["M"])

    @property
    def m(self) -> int:
        """The azimuthal number: 0 for an axisymmetric branch, m ≥ 1 for a surface branch (docs/hdf5.md)."""
        return int(self.data["attrs"].get("m", 0))

    @property
    def surface(self) -> bool:
        """Whether it is a surface branch (traced on the whole sphere, or a capsule's over (θ, φ): its basis
        attributes, docs/hdf5.md)."""
        return non_axisymmetric(self.data["attrs"])

    @property
    def surface_name(self) -> str:
        """The legend name of a surface branch: 'm = 1 from 5' (the label of its parent point), 'whole sphere' for
        the primary branch of a field that is not axisymmetric."""
        if not self.data["attrs"]["parent_branch"]:
            return "whole sphere"
        return f"m = {self.m} {self.born}".rstrip()

    @property
    def born(self) -> str:
        """'from 5': the label of the point the branch leaves from (``io.parents``), '' for the primary branch."""
        label = parent_label(self.run, self.name)
        return "" if label is None else f"from {label}"

    @property
    def ordinate(self) -> Ordinate:
        return ordinate_of(self.data)

    @property
    def parameter_values(self) -> np.ndarray:
        """The continuation parameter at every point (P, or Φ̄ on a voltage branch)."""
        return self.data[self.ordinate.column]

    @property
    def fixed(self) -> str:
        """The parameter held fixed on a dielectric branch, for legends ('Φ̄ = 0.3' on a pressure branch,
        'P = 0.5' on a voltage branch); '' without the dielectric term."""
        if not self.data["attrs"].get("electric", False):
            return ""
        if self.ordinate == VOLTAGE_ORDINATE:
            return f"P = {self.data['pressure'][0]:g}"
        return f"{VOLTAGE_ORDINATE.symbol} = {self.data['voltage'][0]:g}"

    @property
    def meaning(self) -> str:
        """What the stability reading means on this branch (VOLTAGE_MEANINGS on a voltage branch)."""
        if self.ordinate == VOLTAGE_ORDINATE:
            return VOLTAGE_MEANINGS.get(self.reading, self.reading.meaning)
        return self.reading.meaning

    @property
    def coils(self):
        return stored_scene(self.run).field.coils

    @property
    def bifurcations(self) -> list:
        """Special points with finite normal-form coefficients E2, E3, E4."""
        return [s for s in self.data["special_points"]
                if all(np.isfinite(s.get(k, np.nan)) for k in NORMAL_FORM)]


    @property
    def source(self) -> str:
        """The run's file, or its scene name for a run in memory."""
        return self.run["path"] or self.run["scene_name"]


def as_run(source) -> dict:
    """A run (read_run() output): ``source`` itself if it is one, else read from the file it names; a capsule's
    non-axisymmetric branches among its branches (``meridian_branches``: drawn as the sphere's surface branches)."""
    return with_meridian_branches(source if isinstance(source, dict) else read_run(source))


def load_branches(source, branch: str | None = None, reading: Reading | None = None) -> list[StoredBranch]:
    """The branches of a run or run file (all, primary first, or the one named), with their stability under
    ``reading`` (None: the run's control, ``Reading.of_run``)."""
    run = as_run(source)
    if not run["branches"]:  # a two-parameter curve file is a run file without branches
        raise PlotError(f"{run['path'] or run['scene_name']}: no branches to draw (a two-parameter curve file: its "
                        "kind is phase)")
    reading = Reading.of_run(run) if reading is None else Reading.parse(reading)
    names = sorted(run["branches"], key=lambda name: name != "primary") if branch is None else [branch]
    if branch is not None and branch not in run["branches"]:
        raise PlotError(f"{run['path'] or run['scene_name']}: no branch {branch!r} "
                        f"(branches: {', '.join(run['branches'])})")
    loaded = []
    for name in names:
        data = run["branches"][name]
        stable = stable_points(data, reading)
        n = len(data["pressure"])
        if stable is not None and stable.shape != (n,):
            raise PlotError(f"{run['path']}: branch {name}: the {reading.value} stability has shape {stable.shape}, "
                            f"expected ({n},)")
        loaded.append(StoredBranch(run, name, stable, reading=reading))
    return loaded


def branch_title(branch: "StoredBranch") -> str:
    """A stored branch's name as legends show it, by the label of the point it leaves from (``io.parents``):
    'pear_2' → 'pear from 3', 'pear_2_mirror' → 'pear from 3, mirror image', 'pear_free_4' → 'free pear from 6'
    (analysis.picture's names), any other name with spaces for underscores."""
    pear = re.fullmatch(r"pear(_free)?_\d+(_mirror)?", branch.name)
    if pear and branch.born:
        return f"{'free ' * bool(pear[1])}pear {branch.born}" + ", mirror image" * bool(pear[2])
    return branch.name.replace("_", " ")


def branch_kind(branch: "StoredBranch") -> str:
    """What a branch is, for colour families and legends of several files: 'primary', 'pear', 'free pear'
    (analysis.picture's pear_<n>, pear_free_<n> and their mirror images), 'm = 1' (a surface branch; 'whole
    sphere' the primary branch of a field that is not axisymmetric), any other its name without indices."""
    if branch.surface:
        return f"m = {branch.m}" if branch.data["attrs"]["parent_branch"] else "whole sphere"
    pear = re.fullmatch(r"pear(_free)?_\d+(_mirror)?", branch.name)
    if pear:
        return "free pear" if pear[1] else "pear"
    return re.sub(r"(_\d+)*(_mirror)?$", "", branch.name).replace("_", " ")


#: a matplotlib sequential colour map per branch kind (``branch_kind``); kinds not named take the spare ones in turn
FAMILIES = {"primary": "Blues", "whole sphere": "Blues", "pear": "Oranges", "free pear": "Greens", "m = 1": "Purples",
            "m = 2": "Reds"}
SPARE_FAMILIES = ("Greys", "YlOrBr", "PuRd", "BuGn")
SHADES = (0.9, 0.45)  # the darkest and the lightest shade of a family: the first file's and the last's


def family_colors(kinds: list, files: int) -> dict:
    """{(kind, file): colour}: each kind's family (FAMILIES, else the SPARE_FAMILIES in order), one shade per file
    from the darkest to the lightest (SHADES; one file: the middle)."""
    spare = iter(SPARE_FAMILIES * len(kinds))
    maps = {kind: FAMILIES.get(kind) or next(spare) for kind in kinds}
    shades = np.linspace(*SHADES, files) if files > 1 else [np.mean(SHADES)]
    return {(kind, n): matplotlib.colors.to_hex(matplotlib.colormaps[maps[kind]](shade))
            for kind in kinds for n, shade in enumerate(shades)}


def _label(branches: list[StoredBranch]) -> list[StoredBranch]:
    """Set each branch's legend label and colour. One file: a colour per branch (a mirror image, or a surface
    branch's rotation by π, sharing its partner's), labelled 'M = …, <branch title>' (``branch_title``) when
    there are several, a surface branch 'm = 1 from 5' (the label of its parent point). Several files: a colour
    family per branch kind (``branch_kind``, ``family_colors``: primary blue, pear orange, free pear green, m = 1
    purple, …), a shade per file, labelled 'M = …' and, where several kinds are drawn, the kind ('M = 0.002, free
    pear'), with the scene name where two files share an M (branches of one kind told apart by their curves and
    labelled points). A dielectric branch adds its fixed parameter ('M = 0, Φ̄ = 0.3', 'M = 0, P = 0.5'); a
    branch in M (continue --parameter M) is labelled by its fixed P."""

    def key(b):  # a branch in M at fixed P: that P
        held = f"P = {b.data['pressure'][0]:g}" if b.ordinate == FIELD_ORDINATE else f"M = {b.M:g}"
        return ", ".join([held] + [b.fixed] * bool(b.fixed))

    files = {}
    for b in branches:
        files.setdefault(id(b.run), []).append(b)
    by_M = {}
    for path, members in files.items():
        by_M.setdefault(key(members[0]), []).append(path)
    for b in branches:
        label = key(b)
        if len(by_M[label]) > 1:
            label += f" ({b.run['scene_name']})"
        if len(files) == 1 and b.surface:  # a surface branch: by its mode and parent, never its internal name
            label = b.surface_name
        elif len(files) == 1 and len(files[id(b.run)]) > 1:
            label += f", {branch_title(b)}"
        b.label = label
    if len(files) > 1:
        kinds = list(dict.fromkeys(branch_kind(b) for b in branches))
        colors = family_colors(kinds, len(files))
        order = list(files)
        for b in branches:
            b.color = colors[branch_kind(b), order.index(id(b.run))]
            b.label += f", {branch_kind(b)}" * (len(kinds) > 1)
        return branches
    colors = {}
    for b in branches:
        partner = b.data["attrs"].get("reflection_of") or b.name if b.surface else b.name.removesuffix(MIRROR_SUFFIX)
        b.color = colors.setdefault(partner, f"C{len(colors) % 10}")
    return branches


def applicable_kinds(branches) -> list[str]:
    """The KINDS that can be drawn for these branches (the branch curves of their continuation parameter, field
    needs coils, energy needs normal-form data)."""
    prefixes, curves = {b.ordinate.prefix for b in branches}, {o.prefix for o in ORDINATES.values()}
    return [kind for kind in KINDS
            if kind != "phase" and (kind.split("-")[0] not in curves or prefixes == {kind.split("-")[0]})
            and (kind != "field" or any(b.coils for b in branches))
            and (kind != "energy" or any(b.bifurcations for b in branches))
            and (kind != "frequencies" or any("frequencies" in b.data for b in branches))
            and (kind != "modes" or any(b.data.get("modes") for b in branches))
            and (kind not in SURFACE_KINDS or any(b.surface for b in branches))]


def plot(sources, what: str | None, points=None, branch: str | None = None, axes=None,
         stability: Reading | None = None, width: float | None = None) -> Figure:
    """The figure of kind ``what`` (one of KINDS) for ``sources``: runs (read_run() output) or run files, one
    or a list (``phase``: curve or sweep files). ``what`` None: the pole curve of the first run's continuation
    parameter (``pressure-pole``, or ``voltage-pole`` for a run continued in the voltage); ``phase`` for a sweep or
    curve file.

    ``branch``: the branch to draw (default: all branches for the branch curves and the energy, 'primary' for
    the per-point kinds). ``points``: indices (negative count from the end) of the configurations drawn by the
    per-point kinds (default: DEFAULT_POINTS spread along the branch), or ``Configuration`` s (each names its
    branch; ``branch`` is then ignored). ``axes``: draw into these matplotlib Axes (one, or as many as the kind
    has panels) instead of a new figure. ``stability``: the Reading that draws curves solid or dashed (None: each
    run's loading control). ``width``: a new figure's width in inches (``fit.fit_width``: its legend under the
    panels, its titles wrapped; MIN_WIDTH to MAX_WIDTH). Drawn in the journal style (``style``); a new figure is
    also saved in it.
    """
    if width is not None and not MIN_WIDTH <= width <= MAX_WIDTH:
        raise PlotError(f"width {width:g}: must be in [{MIN_WIDTH:g}, {MAX_WIDTH:g}] inches (3.5 one column, 7.2 two)")
    if width is not None and axes is not None:
        raise PlotError("width: the figure of the Axes given has its own size (set it with fig.set_size_inches)")
    token = WIDTH.set(width)
    try:
        with journal_style():
            fig = _draw(sources, what, points, branch, axes, stability)
            if width is not None:
                fit_width(fig, width)
            if axes is not None:
                _journal_family(axes)
    finally:
        WIDTH.reset(token)
    return fig


def _journal_family(axes) -> None:
    """The caller's Axes with the journal style's font family (the current one, inside ``journal_style``) on their
    tick labels, axis labels and title, as on everything the plot drew into them: one family in the figure (their
    sizes stay the caller's)."""
    family = matplotlib.rcParams["font.family"]
    for ax in np.ravel(np.asarray(axes, dtype=object)):
        ax.tick_params(labelfontfamily=family)
        labels = [getattr(ax, name).label for name in ("xaxis", "yaxis", "zaxis") if hasattr(ax, name)]
        for text in [ax.title, *labels]:
            text.set_fontfamily(family)


WIDTH = contextvars.ContextVar("width", default=None)  # plot's width: a new figure is made at it (``sized``)


def sized(figsize):
    """A new figure's size: ``figsize`` (each kind's own) scaled to the width ``plot`` was asked for, if any
    (``fit.fitted_size``), so that it is laid out at that size from the start."""
    width = WIDTH.get()
    return figsize if width is None or figsize is None else fitted_size(figsize, width)




def _draw(sources, what, points, branch, axes, stability) -> Figure:
    """``plot`` in the current matplotlib style."""
    sources = [sources] if isinstance(sources, (str, Path, dict)) else list(sources)
    if what is None and not isinstance(sources[0], dict) and file_kind(sources[0]) in ("sweep", "curve"):
        what = "phase"  # what a sweep or curve file draws
    if what is None:
        sources = [as_run(s) for s in sources]
        stored = list(sources[0]["branches"].values())  # none in a curve file: load_branches says so in one line
        what = f"{ordinate_of(stored[0]).prefix}-pole" if stored else "pressure-pole"
    if what not in KINDS:
        raise PlotError(f"unknown plot kind {what!r}{did_you_mean(what, KINDS)}; choose one of {', '.join(KINDS)}")
    if what == "phase":
        return plot_phase(sources, axes)
    if what in SURFACE_KINDS:
        return KINDS[what][0](*surface_state(sources, points, branch, what), axes=axes)
    draw, per_point = KINDS[what]
    configurations = per_point and named_points(points)
    names = list(dict.fromkeys(p.branch for p in points)) if configurations else [
        "primary" if per_point and branch is None else branch]
    branches = [b for source in sources for name in names for b in load_branches(source, name, stability)]
    if what not in SURFACE_DRAWN:  # the axisymmetric kinds: surface branches have no profiles or equator ring
        named = [b for b in branches if b.surface and (branch is not None or configurations)]
        if named:
            raise PlotError(f"{named[0].source}: branch {named[0].name} is a surface branch (m = {named[0].m}): "
                            f"{what} draws axisymmetric branches; draw it with {', '.join(SURFACE_DRAWN)}, "
                            f"{' or '.join(SURFACE_KINDS)}")
        branches = [b for b in branches if not b.surface]
    branches = _label(branches)
    return draw(branches, points, axes=axes) if per_point else draw(branches, axes=axes)


def _panels(axes, count: int, figsize, **subplots):
    """(figure, ``count`` Axes, own): a new constrained-layout Figure with ``count`` panels (own = True), or
    the caller's ``axes`` (one Axes or a sequence of ``count``) and their figure."""
    if axes is None:
        fig = JournalFigure(figsize=sized(figsize), layout="constrained")
        return fig, np.atleast_1d(fig.subplots(**subplots) if subplots else fig.add_subplot()), True
    given = list(np.ravel(np.asarray(axes, dtype=object)))
    if len(given) != count:
        raise PlotError(f"this figure has {count} panel{'s' * (count > 1)}: give a sequence of {count} matplotlib "
                        f"Axes (got {len(given)})")
    if not all(hasattr(a, "plot") and hasattr(a, "figure") for a in given):
        raise PlotError(f"not matplotlib Axes: {', '.join(type(a).__name__ for a in given)}")
    return given[0].figure, np.array(given, dtype=object), False


def _legend(fig, axes, own: bool, loc: str, **options):
    """The legend: outside the axes of an own figure; in the caller's first Axes where it finds room (matplotlib's
    'best'), else under it, below its tick and axis labels (``covers``: it would hide a curve or a label, or reach
    out of the Axes)."""
    if own:
        fig.legend(loc=f"outside {loc}", **options)
        return
    options.pop("ncols", None)
    ax = axes[0]
    legend = ax.legend(**options)
    if covers(legend, ax):
        legend.remove()
        depth = (ax.get_window_extent().y0 - ax.get_tightbbox().y0) / fig.dpi  # inches: its tick and axis labels
        below = ax.transAxes + matplotlib.transforms.ScaledTranslation(0.0, -depth, fig.dpi_scale_trans)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=below, borderaxespad=0.3, **options)


def _suptitle(fig, axes, own: bool, text: str):
    if own:
        fig.suptitle(text)
    else:
        axes[0].set_title(text)


# --- branch curves -----------------------------------------------------------------------------------------

def describe_scene(scene) -> str:
    """The material and the coils of a scene, for titles: 'SPOM1, no field', 'TPOM1, one coil a = 4, h = 0',
    'SPOM1, two coils a = 1.732, h = ±1' (M is in the legend)."""
    coils = scene.field.coils
    if not coils:
        return f"{scene.material.name}, no field"
    radii = sorted({c.radius for c in coils})
    count = {1: "one coil", 2: "two coils"}.get(len(coils), f"{len(coils)} coils")
    if not all(c.is_coaxial for c in coils):
        off = "off the axis: " + "; ".join(f"centre ({', '.join(f'{v:.3g}' for v in c.centre)}), normal "
                                           f"({', '.join(f'{v:.3g}' for v in c.normal)})" for c in coils[:2])
        return f"{scene.material.name}, {count} a = {'/'.join(f'{a:.4g}' for a in radii)} {off}"
    heights = sorted({abs(c.height) for c in coils})
    height = "±" * (len(coils) == 2 * len(heights) and heights[0] > 0) + "/".join(f"{h:.4g}" for h in heights)
    return f"{scene.material.name}, {count} a = {'/'.join(f'{a:.4g}' for a in radii)}, h = {height}"


def _title(branches) -> str:
    return "; ".join(dict.fromkeys(describe_scene(stored_scene(b.run)) for b in branches))


def _curve(ax, x, y, stable, color, linestyle="-", mirror=False):
    """A branch curve: solid where stable, dashed where unstable (stable None: the given linestyle throughout);
    a mirror image thinner and lighter."""
    style = {"color": color, "linewidth": 0.9 if mirror else 1.4, "alpha": 0.55 if mirror else 1.0}
    if stable is None:
        ax.plot(x, y, linestyle=linestyle, **style)
        return
    edges = np.flatnonzero(np.diff(stable.astype(int))) + 1
    for start, end in zip(np.r_[0, edges], np.r_[edges, len(x)]):
        piece = slice(start, min(end + 1, len(x)))  # one shared point joins the pieces
        ax.plot(x[piece], y[piece], linestyle="-" if stable[start] else "--", **style)


def special_label(s: dict) -> str:
    """A stored special point's label: its classification (pitchfork-super, …) if it has one, else its kind;
    with its azimuthal number for m ≥ 1 ("BP m=1")."""
    return (s["classification"] or s["kind"]) + (f" m={s['m']}" if s["m"] else "")


def _special(ax, branch: StoredBranch, x, y, color) -> list:
    """Mark the special points at (x, y) (one entry per special point); returns them for labels.label_points."""
    marks = []
    for s, xs, ys in zip(branch.data["special_points"], x, y):
        ax.plot(xs, ys, MARKERS.get(s["kind"], "D"), color=color, markersize=6, markeredgecolor="k",
                markeredgewidth=0.5)
        marks.append((ax, int(s["label"]), special_label(s), xs, ys, color))
    return marks


def _branch_legend(fig, axes, own, branches, extra=()):
    """Legend right of the axes: one line per drawn branch (a mirror image as its partner's 'mirror') plus
    ``extra`` handles; the title tells what the line styles mean under which stability reading."""
    with_stability = [b.stable is not None for b in branches]
    meaning = branches[0].meaning if branches else Reading.PRESSURE.meaning
    if all(with_stability):
        title = f"solid: stable, dashed: unstable\n({meaning})"
    elif any(with_stability):
        title = f"solid: stable or not computed,\ndashed: unstable ({meaning})"
    else:
        title = "stability not computed (all solid)"
    handles = {}
    for b in branches:  # several files: one entry per file and branch kind (its label)
        handles.setdefault(b.label, Line2D([], [], color=b.color, label=b.label, linewidth=0.9 if b.mirror else 1.4,
                                           alpha=0.55 if b.mirror else 1.0))
    handles = list(handles.values())
    if any(b.mirror for b in branches) and len({id(b.run) for b in branches}) > 1:
        handles.append(Line2D([], [], color="0.4", linewidth=0.9, alpha=0.55, label="mirror-image branch"))
    _legend(fig, axes, own, "right upper", handles=handles + list(extra), title=title)


def check_ordinate(branches, ordinate: Ordinate, kind: str) -> None:
    """Refuse a branch curve whose y quantity is not the continuation parameter of every drawn branch (it would
    be a constant: P on a voltage branch, Φ̄ on a pressure branch), in one line naming the kind to draw."""
    for b in branches:
        if b.ordinate != ordinate:
            held = b.fixed or "no voltage"
            raise PlotError(f"{b.source}: branch {b.name} is continued in {b.ordinate.column} ({held}): {kind} "
                            f"draws branches continued in {ordinate.column}; draw {b.ordinate.prefix}-"
                            f"{kind.split('-', 1)[1]}")


def _pole_curves(branches, ordinate: Ordinate, axes=None) -> Figure:
    """The parameter (P or Φ̄, ``ordinate``) against the north pole stretch λ2(0); the south pole λ2(π) dotted
    where it differs."""
    check_ordinate(branches, ordinate, f"{ordinate.prefix}-pole")
    fig, panels, own = _panels(axes, 1, (8.4, 4.8))
    ax = panels[0]
    extra, marks = [], []
    drawn = {(id(b.run), b.name) for b in branches}
    for b in branches:
        d, color, y = b.data, b.color, b.parameter_values
        if b.surface and (id(b.run), d["attrs"].get("reflection_of")) in drawn:
            continue  # a surface branch's image under the rotation about the axis: its source's curve and points
        _curve(ax, d["lam2_top"], y, b.stable, color, mirror=b.mirror)
        scale = np.abs(d["lam2_top"]).max()
        partner = (id(b.run), b.name.removesuffix(MIRROR_SUFFIX) if b.mirror else b.name + MIRROR_SUFFIX)
        # a pear branch's south pole is its mirror image's north pole: drawn already when that one is
        if partner not in drawn and np.abs(d["lam2_bottom"] - d["lam2_top"]).max() > 1e-8 * scale:
            _curve(ax, d["lam2_bottom"], y, None, color, linestyle=":")
            extra = [Line2D([], [], color="k", linestyle=":", label=r"bottom pole $\lambda_2(\pi)$")]
        special = d["special_points"]
        marks += _special(ax, b, [s["lam2_top"] for s in special], [s[ordinate.column] for s in special], color)
    ax.set_xlabel(r"pole stretch $\lambda_2(0)$ (top)")
    ax.set_ylabel(ordinate.label)
    ax.set_title(_title(branches))
    _branch_legend(fig, panels, own, branches, extra)
    label_points(marks)
    return fig


def _equator_curves(branches, ordinate: Ordinate, axes=None) -> Figure:
    """The parameter (P or Φ̄, ``ordinate``) against λ2(π/2) and against λ1(π/2) at the equator (two panels)."""
    check_ordinate(branches, ordinate, f"{ordinate.prefix}-equator")
    fig, axes, own = _panels(axes, 2, (12, 4.5), nrows=1, ncols=2, sharey=True)
    marks = []
    for b in branches:
        d, color = b.data, b.color
        at_equator = surface(branch_discretisation(d), d["special_unknowns"], EQUATOR, stored_scene(b.run).geometry)
        special_y = [s[ordinate.column] for s in d["special_points"]]
        for ax, key in zip(axes, ("lam2", "lam1")):
            _curve(ax, d[f"{key}_equator"], b.parameter_values, b.stable, color, mirror=b.mirror)
            marks += _special(ax, b, at_equator[key][:, 0], special_y, color)
    axes[0].set_xlabel(r"equator stretch $\lambda_2(\pi/2)$ (circumferential)")
    axes[1].set_xlabel(r"equator stretch $\lambda_1(\pi/2)$ (meridional)")
    axes[0].set_ylabel(ordinate.label)
    _suptitle(fig, axes, own, _title(branches))
    _branch_legend(fig, axes, own, branches)
    label_points(marks)
    return fig


def plot_pressure_pole(branches, axes=None) -> Figure:
    """P against the north pole stretch λ2(0) (``_pole_curves``)."""
    return _pole_curves(branches, PRESSURE_ORDINATE, axes)


def plot_voltage_pole(branches, axes=None) -> Figure:
    """Φ̄ against the north pole stretch λ2(0) of branches continued in the voltage (``_pole_curves``)."""
    return _pole_curves(branches, VOLTAGE_ORDINATE, axes)


def plot_pressure_equator(branches, axes=None) -> Figure:
    """P against λ2(π/2) and λ1(π/2) (``_equator_curves``)."""
    return _equator_curves(branches, PRESSURE_ORDINATE, axes)


def plot_voltage_equator(branches, axes=None) -> Figure:
    """Φ̄ against λ2(π/2) and λ1(π/2) of branches continued in the voltage (``_equator_curves``)."""
    return _equator_curves(branches, VOLTAGE_ORDINATE, axes)


# --- configurations (per point) ----------------------------------------------------------------------------

def select_points(data: dict, points=None) -> np.ndarray:
    """Indices of the points of a stored branch to draw: ``points`` checked (negative count from the end), or
    DEFAULT_POINTS spread evenly in arclength along the (λ2(0), p) curve (p the continuation parameter, P or Φ̄),
    each scaled by its range."""
    n = len(data["pressure"])
    if points is not None and (np.ndim(points) != 1 or len(points) == 0
                               or not all(isinstance(p, (int, np.integer)) for p in points)):
        raise PlotError(f"points = {points!r}: expected a non-empty list of point indices, e.g. [0, 10, -1]")
    if points is None:
        path = np.stack([data["lam2_top"], data[ordinate_of(data).column]])
        span = np.ptp(path, axis=1, keepdims=True)
        step = np.hypot(*(np.diff(path, axis=1) / np.where(span > 0, span, 1.0)))
        length = np.r_[0.0, np.cumsum(step)]
        targets = np.linspace(0.0, length[-1], min(n, DEFAULT_POINTS))
        return np.unique(np.abs(length[:, None] - targets).argmin(axis=0))
    bad = [p for p in points if not -n <= p < n]
    if bad:
        raise PlotError(f"point {bad[0]} does not exist: the branch has {n} points (indices 0..{n - 1})")
    return np.array([p % n for p in points], dtype=int)


def _configurations(branches, points):
    """[(label, colour, quantities row dict, branch)] for the chosen points of every branch (``points``:
    indices, or Configurations naming their branches and labels)."""
    named = named_points(points)
    several = len(branches) > 1 and not named
    rows = []
    for b in branches:
        chosen = [p for p in points if p.branch == b.name] if named else []
        indices = select_points(b.data, [p.index for p in chosen] if named else points)
        q = postprocess(b.run, b.name, indices, np.linspace(0.0, np.pi, THETA_SAMPLES))
        for j, index in enumerate(q["points"]):
            name = f"{chosen[j].label}:" if named else f"#{index}"
            value = f"{b.ordinate.symbol} = {q[b.ordinate.column][j]:.4g}"
            label = (f"{b.label}: " if several else "") + f"{name}  {value}, $\\lambda_2(0)$ = {q['lam2'][j, 0]:.4g}"
            row = {k: v[j] for k, v in q.items() if k not in ("theta", "points")}
            color = (chosen[j].color if named else "") or f"C{len(rows) % 10}"
            rows.append((label, color, row | {"theta": q["theta"]}, b, chosen[j] if named else None))
    if named:  # in the order given
        rows.sort(key=lambda row: points.index(row[4]))
    return [row[:4] for row in rows]


def _per_point_title(branches) -> str:
    if len(branches) == 1:
        return f"{_title(branches)}, M = {branches[0].M:g}"
    return _title(branches)


def _point_legend(fig, axes, own, handles):
    _legend(fig, axes, own, "lower center", handles=handles, ncols=2)


def _theta_axes(branches, ylabels, height=5.0, axes=None):
    fig, axes, own = _panels(axes, len(ylabels), (7.5, height), nrows=len(ylabels), ncols=1, sharex=True,
                             squeeze=False)
    axes = axes.ravel()
    for ax, label in zip(axes, ylabels):
        ax.set_ylabel(label)
        ax.axhline(0.0, color="0.6", linewidth=0.6)
    for ax in axes[-1:] if own else axes:  # the caller's Axes need not share x
        ax.set_xlabel(THETA_LABEL)
        ax.set_xlim(0.0, np.pi)
        ax.set_xticks(np.linspace(0, np.pi, 5), ["0", "π/4", "π/2", "3π/4", "π"])
    _suptitle(fig, axes, own, _per_point_title(branches))
    return fig, axes, own


ROBUST_PERCENTILES = (1.0, 99.0)  # the bulk of the values of a θ plot
ROBUST_SPREAD = 5.0  # the full range must exceed the bulk's range this many times before y is limited


def robust_limits(ax, curves) -> bool:
    """Limit ax's y range to the bulk of ``curves`` (arrays of values) when a spike, e.g. a stress
    concentration next to a coil wire, would flatten the rest: when max − min of all values exceeds ROBUST_SPREAD
    times the ROBUST_PERCENTILES range, y spans that range widened by a quarter each side (and 0), and a note in
    the axes names the clipped extremes. Returns whether it limited."""
    values = np.concatenate([np.ravel(c) for c in curves])
    values = values[np.isfinite(values)]
    if values.size == 0:
        return False
    low, high = np.percentile(values, ROBUST_PERCENTILES)
    if np.ptp(values) <= ROBUST_SPREAD * max(high - low, 1e-300):
        return False
    margin = 0.25 * (high - low)
    ax.set_ylim(min(low - margin, 0.0), max(high + margin, 0.0))
    ax.text(0.99, 0.97, f"clipped: range {values.min():.3g} .. {values.max():.3g}", transform=ax.transAxes,
            ha="right", va="top", fontsize="x-small", color="0.35")
    return True


def plot_shapes(branches, points=None, axes=None) -> Figure:
    """Deformed meridian sections (ρ, η) and their mirror (−ρ, η), equal aspect, coils at (±a, h)."""
    fig, panels, own = _panels(axes, 1, (6.4, 7.6))
    ax = panels[0]
    ax.set_aspect("equal")
    meridian = np.linspace(0, np.pi, 100)  # the reference's, mirrored
    handles = []
    for geometry in dict.fromkeys(stored_scene(b.run).geometry for b in branches):  # each reference drawn once
        radius, height = hoop(geometry, np.cos(meridian), np.sin(meridian)), reference_height(geometry, meridian)
        ax.plot(np.r_[radius, -radius[::-1]], np.r_[height, height[::-1]], color="0.6", linewidth=0.8, linestyle=":")
        shape = "" if geometry.shape == Shape.SPHERE else f", {geometry.describe()}"
        handles.append(Line2D([], [], color="0.6", linewidth=0.8, linestyle=":",
                              label=f"undeformed ($R_0$ = 1{shape})"))
    for label, color, q, _ in _configurations(branches, points):
        ax.fill(np.r_[q["rho"], -q["rho"][::-1]], np.r_[q["eta"], q["eta"][::-1]], fill=False, edgecolor=color,
                linewidth=1.4)  # one closed outline: no seam at the poles
        handles.append(Line2D([], [], color=color, label=label))
    coils = {(c.radius, c.height, np.sign(c.current)) for b in branches for c in b.coils}
    for a, h, sign in coils:
        ax.plot([a, -a], [h, h], linestyle="none", marker="o", markersize=9, markerfacecolor="w", color="k")
        for x in (a, -a):  # a positive current flows along +e_φ: into the (x, z) plane at x = a, out at x = −a
            ax.plot(x, h, linestyle="none", color="k", markersize=4, marker="x" if x * sign > 0 else ".")
    if coils:
        handles.append(Line2D([], [], linestyle="none", marker="o", markerfacecolor="w", color="k",
                              label="coil wire (· current out of, × into the plane)"))
    ax.set_xlabel(r"$\pm\rho/R_0$ (distance from the axis)")
    ax.set_ylabel(r"$\eta/R_0$ (height)")
    ax.set_title(_per_point_title(branches))
    _point_legend(fig, panels, own, handles)
    return fig


def plot_stresses(branches, points=None, axes=None) -> Figure:
    """σ_θ and σ_φ against θ: elastic stresses solid; with the paper's magnetic additions dashed (M > 0)."""
    fig, axes, own = _theta_axes(branches, [r"$\sigma_\theta$ / ($\mu$/2)", r"$\sigma_\phi$ / ($\mu$/2)"], 7.2, axes)
    handles, curves = [], {ax: [] for ax in axes}
    for label, color, q, b in _configurations(branches, points):
        for ax, key in zip(axes, ("sigma_theta", "sigma_phi")):
            ax.plot(q["theta"], q[key], color=color, linewidth=1.4)
            curves[ax].append(q[key])
            if b.M > 0:
                ax.plot(q["theta"], q[key] + q[f"{key}_paper"], color=color, linewidth=1.0, linestyle="--")
                curves[ax].append(q[key] + q[f"{key}_paper"])
        handles.append(Line2D([], [], color=color, label=label))
    for ax, values in curves.items():
        robust_limits(ax, values)
    handles.append(Line2D([], [], color="k", label="elastic"))
    if any(b.M > 0 for b in branches):
        handles.append(Line2D([], [], color="k", linestyle="--", label="elastic + paper's magnetic terms"))
    _point_legend(fig, axes, own, handles)
    return fig


def plot_field(branches, points=None, axes=None) -> Figure:
    """Applied field on the deformed surface: H_θ (meridional tangent) and H_ζ (outward normal) against θ."""
    if not any(b.coils for b in branches):
        raise PlotError("no coils in these run files: the applied field is zero everywhere")
    fig, axes, own = _theta_axes(branches, [r"$H_\theta$ / ($I/4\pi R_0$)", r"$H_\zeta$ / ($I/4\pi R_0$)"], 7.2,
                                 axes)
    handles, curves = [], ([], [])
    for label, color, q, _ in _configurations([b for b in branches if b.coils], points):
        for ax, values, key in zip(axes, curves, ("H_theta", "H_zeta")):
            ax.plot(q["theta"], q[key], color=color, linewidth=1.4)
            values.append(q[key])
        handles.append(Line2D([], [], color=color, label=label))
    for ax, values in zip(axes, curves):
        robust_limits(ax, values)
    _point_legend(fig, axes, own, handles)
    return fig


def plot_curvature(branches, points=None, axes=None) -> Figure:
    """Gaussian curvature κ R0² of the deformed surface against θ."""
    fig, axes, own = _theta_axes(branches, [r"Gaussian curvature $\kappa R_0^2$"], axes=axes)
    ax = axes[0]
    handles, curves = [], []
    for label, color, q, _ in _configurations(branches, points):
        ax.plot(q["theta"], q["gaussian_curvature"], color=color, linewidth=1.4)
        curves.append(q["gaussian_curvature"])
        handles.append(Line2D([], [], color=color, label=label))
    robust_limits(ax, curves)
    _point_legend(fig, axes, own, handles)
    return fig


# --- surface branches (one state on the whole sphere) ------------------------------------------------------

SURFACE_SAMPLES = (61, 121)  # (θ, φ) values of the drawn surface, poles and both ends of φ included


def surface_state(sources, points, branch: str | None, what: str) -> tuple:
    """(StoredBranch, point index) of the state the surface kinds draw: point ``points[0]`` (one index, or one
    Configuration naming its branch) of the surface branch ``branch`` (default: the first surface branch of the
    file), by default its last point (the state the branch reaches: where it stops or rejoins)."""
    if len(sources) != 1:
        raise PlotError(f"{what} draws one state of one run file (got {len(sources)} files)")
    if named_points(points):
        branch, points = points[0].branch, [p.index for p in points]
    run = as_run(sources[0])
    source = run["path"] or run["scene_name"]
    if branch is None:
        branch = next((name for name, d in run["branches"].items() if non_axisymmetric(d["attrs"])), None)
        if branch is None:
            raise PlotError(f"{source}: no surface branch (m ≥ 1) in this file: {what} draws a state of a "
                            "non-axisymmetric branch (shapes draws axisymmetric ones)")
    stored = _label(load_branches(run, branch))[0]
    if not stored.surface:
        raise PlotError(f"{source}: branch {branch} is axisymmetric (m = 0): {what} draws surface branches "
                        "(draw it with shapes)")
    if points is not None and np.ndim(points) == 1 and len(points) > 1:
        raise PlotError(f"{what} draws one state: give one point (got {len(points)})")
    if what == "stretch-map" and "orders" in stored.data["attrs"]:
        raise PlotError(f"{source}: branch {branch} is a capsule's (over (θ, φ)): stretch-map draws the sphere's "
                        "surface branches (a capsule's: not built; draw it with surface)")
    n = len(stored.data["pressure"])
    index = int(select_points(stored.data, points)[0]) if points is not None else n - 1
    return stored, index


def stored_state(branch: StoredBranch, index: int) -> tuple:
    """(basis, coefficients) of point ``index`` of a stored surface branch, its basis rebuilt from its attributes:
    a SphericalBasis (io.run_file.stored_basis), a capsule's CapsuleSurfaceBasis (``stored_meridian_basis``)."""
    attrs = branch.data["attrs"]
    basis = (stored_meridian_basis(branch.run, branch.name) if "orders" in attrs else
             stored_basis(attrs, branch.source))
    return basis, branch.data["coefficients"][index]


def _state_title(branch: StoredBranch, index: int) -> str:
    d = branch.data
    return (f"{_title([branch])}, M = {branch.M:g}\n{branch.label}: #{index}  "
            f"{branch.ordinate.symbol} = {d[branch.ordinate.column][index]:.4g}, "
            f"$\\lambda_2(0)$ = {d['lam2_top'][index]:.4g}, "
            + (f"tilt {d['tilt'][index]:.1f}°" if "tilt" in d else f"$V/V_0$ = {d['volume'][index]:.4g}"))


def surface_grid(basis, c, samples: tuple = SURFACE_SAMPLES) -> np.ndarray:
    """x (3, n_θ, n_φ) of the state c on a (θ, φ) grid of ``samples`` values from pole to pole and from φ = 0 to
    2π (``SphericalBasis.grid_values``: each block's θ-series once per ring, the poles included)."""
    return basis.grid_values(c, np.cos(np.linspace(0.0, np.pi, samples[0])), np.linspace(0.0, 2 * np.pi, samples[1]))


def plot_surface(branch: StoredBranch, index: int, axes=None) -> Figure:
    """One state of a surface branch as a 3D surface (mplot3d) with its material lines θ, φ = multiples of 30°,
    equal axis scales, the coils as circles of radius a at height h; in a figure of its own also its section by the
    mirror plane y = 0 beside it (``_mirror_section``) (docs/plots.md)."""
    from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers the 3d projection)

    if axes is None:  # at a narrow width (fit.NARROW) the section under the surface, else beside it
        narrow = WIDTH.get() is not None and WIDTH.get() < NARROW
        fig = JournalFigure(figsize=sized((5.4, 9.0) if narrow else (10.0, 5.4)), layout="constrained")
        fig.get_layout_engine().set(wspace=0.08)  # the layout does not see mplot3d's z label: room for it
        ax, own = fig.add_subplot(2 if narrow else 1, 1 if narrow else 2, 1, projection="3d"), True
        _mirror_section(fig.add_subplot(2 if narrow else 1, 1 if narrow else 2, 2), branch, index)
    else:
        fig, (ax,), own = _panels(axes, 1, None)
        if getattr(ax, "name", "") != "3d":
            raise PlotError("surface draws into a 3D Axes: give one made with projection='3d'")
    x = surface_grid(*stored_state(branch, index))
    ax.plot_surface(*x, color=branch.color, alpha=0.85, rcount=x.shape[1], ccount=x.shape[2], linewidth=0,
                    shade=True)
    step = (x.shape[1] - 1) // 6, (x.shape[2] - 1) // 12  # the material lines θ, φ = multiples of 30°
    ax.plot_wireframe(*x, rstride=step[0], cstride=step[1], color="0.25", linewidth=0.3)
    handles = [Line2D([], [], color=branch.color, linewidth=6, alpha=0.85, label=f"#{index} of {branch.label}")]
    extent = np.abs(x).max()
    for coil in branch.coils:
        wire = wire_points(coil)
        ax.plot(*wire, color="k", linewidth=1.4)
        extent = max(extent, np.abs(wire).max())
    if branch.coils:
        handles.append(Line2D([], [], color="k", linewidth=1.4, label="coil wire"))
    ax.set(xlim=(-extent, extent), ylim=(-extent, extent), zlim=(-extent, extent))
    ax.set_box_aspect((1.0, 1.0, 1.0))
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):  # mplot3d's default ticks crowd at a journal column
        axis.set_major_locator(MaxNLocator(4))
    ax.set_xlabel(r"$x/R_0$")
    ax.set_ylabel(r"$y/R_0$")
    ax.set_zlabel(r"$z/R_0$")
    if own:  # the 3D Axes' own title is clipped by the constrained layout beside a second panel
        fig.suptitle(_state_title(branch, index))
    else:
        ax.set_title(_state_title(branch, index))
    _point_legend(fig, [ax], own, handles)
    return fig


def _mirror_section(ax, branch: StoredBranch, index: int) -> None:
    """The section of the state by the plane y = 0 (the branches' mirror plane: it holds the axis and the sideways
    displacement of an m = 1 state), the meridians φ = 0 and π, with that of point 0 (the branch point, dashed) and
    the coil wires where they cross the plane."""
    theta = np.linspace(0.0, np.pi, 181)
    start = "point 0 (branch point)" if branch.data["attrs"]["parent_branch"] else "point 0 (start)"
    for i, style, label in ((0, "--", start), (index, "-", f"#{index}")):
        basis, c = stored_state(branch, i)
        x = np.concatenate([basis.point_values(c, theta, np.full_like(theta, phi))[0] for phi in (0.0, np.pi)],
                           axis=1)
        order = np.r_[np.arange(theta.size), np.arange(2 * theta.size - 1, theta.size - 1, -1)]  # round the section
        ax.plot(x[0, order], x[2, order], style, color=branch.color, linewidth=1.2, label=label)
    crossings = np.hstack([_plane_crossings(wire_points(coil, 4000)) for coil in branch.coils] or [np.zeros((3, 0))])
    if crossings.size:
        ax.plot(crossings[0], crossings[2], "o", color="k", markersize=4, linestyle="none", label="coil wire")
    ax.set_aspect("equal")
    ax.set_xlabel(r"$x/R_0$")
    ax.set_ylabel(r"$z/R_0$")
    ax.set_title("section y = 0")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))  # beside the section, not over it


def wire_points(coil, count: int = 200) -> np.ndarray:
    """Points (3, count) of a loop's wire: c + a (cos ψ e1 + sin ψ e2), (e1, e2, n) right-handed (MODEL.md §9)."""
    n = np.array(coil.normal)
    e1 = np.cross(n, [0.0, 1.0, 0.0] if abs(n[1]) < 0.9 else [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    psi = np.linspace(0.0, 2 * np.pi, count)
    return np.array(coil.centre)[:, None] + coil.radius * (np.outer(e1, np.cos(psi)) + np.outer(e2, np.sin(psi)))


def _plane_crossings(wire: np.ndarray) -> np.ndarray:
    """Where a closed polyline (3, n) crosses the plane y = 0 (linear between its samples), (3, k)."""
    y0, y1 = wire[1, :-1], wire[1, 1:]
    k = np.flatnonzero((y0 == 0) | (y0 * y1 < 0))
    t = np.where(y1[k] != y0[k], y0[k] / (y0[k] - y1[k]), 0.0)
    return wire[:, k] + t * (wire[:, k + 1] - wire[:, k])


def principal_stretches(state: np.ndarray) -> tuple:
    """(λ1, λ2) at every node of a node state (9 rows x, a_θ, a_φ; a_φ = ∂x/∂φ / sin θ, so that both are unit on
    the reference sphere; a spheroid's state ``SphericalBasis.framed``): the square roots of the eigenvalues of
    C = [[a_θ·a_θ, a_θ·a_φ], [a_θ·a_φ, a_φ·a_φ]],
    λ1 the one whose principal direction is nearer the meridian (the larger when a_θ·a_θ ≥ a_φ·a_φ): on an
    axisymmetric state the meridional and the hoop stretch."""
    a_theta, a_phi = state[3:6], state[6:9]
    a, b, d = (np.einsum("in,in->n", u, v) for u, v in ((a_theta, a_theta), (a_theta, a_phi), (a_phi, a_phi)))
    mean, radius = (a + d) / 2, np.sqrt(((a - d) / 2) ** 2 + b * b)
    larger, smaller = np.sqrt(mean + radius), np.sqrt(np.maximum(mean - radius, 0.0))
    meridional = a >= d
    return np.where(meridional, larger, smaller), np.where(meridional, smaller, larger)


def _cell_edges(nodes: np.ndarray, low: float, high: float) -> np.ndarray:
    """Edges of the cells around sorted ``nodes``: midway between neighbours, ``low`` and ``high`` at the ends."""
    return np.r_[low, (nodes[1:] + nodes[:-1]) / 2, high]


def _colour_range(values: np.ndarray) -> tuple:
    """(vmin, vmax) of a map: its range, widened to ±0.5 % about its value when it is constant to rounding (a
    sphere), so that the colour bar does not show rounding noise."""
    low, high = float(values.min()), float(values.max())
    if high - low <= 1e-9 * max(1.0, abs(high)):
        middle = (low + high) / 2
        return middle - 0.005 * abs(middle), middle + 0.005 * abs(middle)
    return low, high


def plot_stretch_map(branch: StoredBranch, index: int, axes=None) -> Figure:
    """λ1 and λ2 (``principal_stretches``) of one state of a surface branch as maps over (φ, θ) at the nodes of
    its basis (the stored ones: where the kernels evaluate the state), each node's value on the cell around it
    (from the poles to the midpoints between nodes), north pole at the top, two panels."""
    fig, axes, own = _panels(axes, 2, (10.5, 4.2), nrows=1, ncols=2, sharey=True)
    basis, c = stored_state(branch, index)
    lam1, lam2 = (v.reshape(basis.n_theta, basis.n_phi)
                  for v in principal_stretches(basis.framed(basis.node_state(c))))
    theta = _cell_edges(np.arccos(basis.nodes["cos_theta"]), 0.0, np.pi)
    # uniform nodes φ_k = k 2π/N_φ: the cells (k ∓ ½) 2π/N_φ, node 0 again after the last, clipped to [0, 2π]
    phi = (np.arange(basis.n_phi + 2) - 0.5) * 2 * np.pi / basis.n_phi
    for ax, values, name in zip(axes, (lam1, lam2), (r"$\lambda_1$ (nearer the meridian)",
                                                      r"$\lambda_2$ (nearer the hoop direction)")):
        low, high = _colour_range(values)
        mesh = ax.pcolormesh(phi, theta, np.c_[values, values[:, :1]], shading="flat", cmap="viridis", vmin=low,
                             vmax=high)
        fig.colorbar(mesh, ax=ax, shrink=0.9, label=name.split(" (")[0])
        ax.set_title(name)
        ax.set_xlabel(r"material angle $\phi$ (rad)")
        ax.set_xlim(0.0, 2 * np.pi)
        ax.set_xticks(np.linspace(0, 2 * np.pi, 5), ["0", "π/2", "π", "3π/2", "2π"])
    axes[0].set_ylabel(THETA_LABEL)
    axes[0].set_ylim(np.pi, 0.0)  # the north pole at the top
    axes[0].set_yticks(np.linspace(0, np.pi, 5), ["0", "π/4", "π/2", "3π/4", "π"])
    _suptitle(fig, axes, own, _state_title(branch, index))
    return fig


# --- bifurcations ------------------------------------------------------------------------------------------

def _amplitude_range(e2, e3, e4) -> float:
    """Half-range of Λ: 1.5 × the quartic's own scale max(√|E2/E4|, |E3/E4|), clipped to [0.04, 0.5]
    (the coefficients are a local fit; bifurcation.classify samples |Λ| ≤ 0.04)."""
    scale = max(np.sqrt(abs(e2 / e4)), abs(e3 / e4)) if e4 != 0 else np.inf
    return float(np.clip(1.5 * scale, 0.04, 0.5))


FREQUENCY_STYLES = ("-", "--", "-.", ":")  # one per drawn branch


INSET_WIDTH = 0.9  # inches: the narrowest mode-shape inset of the frequency figure


def plot_frequencies(branches, axes=None) -> Figure:
    """The lowest squared natural frequency Ω² = ω² R0² ρ/μ of every stored block against the continuation
    parameter (P, Φ̄ or M), one colour per block and one line style per branch; the folds and branch points marked
    at Ω² = 0, where a block's Ω² passes through zero (docs/dynamics.md). Branches without frequencies are left
    out. Where the first drawn branch stores mode shapes ([dynamics] modes = true) and the figure is its own (no
    ``axes``), a strip of insets under it shows each block's lowest mode (``mode_points``: at the special point
    where that Ω² is nearest zero), framed in the block's colour."""
    drawn = [b for b in branches if "frequencies" in b.data]
    if not drawn:
        files = ", ".join(dict.fromkeys(str(b.source) for b in branches))
        raise PlotError(f"{files}: no stored frequencies (frequencies/ of a branch); run the scene with "
                        "[dynamics] frequencies = true")
    shown = mode_points(drawn[0]) if axes is None else []
    if shown:  # the insets in rows of as many as fit the width, each at least INSET_WIDTH wide
        width, height = sized((max(8.4, 1.2 * len(shown)), 6.6))
        columns = min(len(shown), max(1, int(width / INSET_WIDTH)))
        rows = -(-len(shown) // columns)
        fig = JournalFigure(figsize=(width, height * (3.0 + 1.2 * rows) / 4.2), layout="constrained")
        grid = fig.add_gridspec(1 + rows, columns, height_ratios=(3.0, *[1.2] * rows))
        panels, own = np.atleast_1d(fig.add_subplot(grid[0, :])), True
        insets = [fig.add_subplot(grid[1 + k // columns, k % columns]) for k in range(len(shown))]
    else:
        fig, panels, own = _panels(axes, 1, (8.4, 4.8))
        insets = []
    ax = panels[0]
    ax.axhline(0.0, color="0.6", linewidth=0.6)
    blocks = list(dict.fromkeys(block for b in drawn for block in b.data["frequencies"]))
    colours = {block: f"C{k % 10}" for k, block in enumerate(blocks)}
    marks = []
    for b, style in zip(drawn, FREQUENCY_STYLES * len(drawn)):
        for block, values in b.data["frequencies"].items():
            ax.plot(b.parameter_values, values[:, 0], style, color=colours[block], linewidth=1.2)
        crossing = [s for s in b.data["special_points"] if s["kind"] in ("LP", "LV", "LN", "BP")]
        for s in crossing:
            ax.plot(s[b.ordinate.column], 0.0, MARKERS.get(s["kind"], "D"), color="k", markersize=5)
            marks.append((ax, int(s["label"]), special_label(s), s[b.ordinate.column], 0.0, "k"))
    ax.set_xlabel(drawn[0].ordinate.label)
    ax.set_ylabel(r"$\Omega^2 = \omega^2 R_0^2 \rho/\mu$ (lowest of each block)")
    ax.set_title(_title(drawn))
    handles = [Line2D([], [], color=colours[block], label=block) for block in blocks]
    handles += [Line2D([], [], color="0.3", linestyle=style, label=b.label or b.name)
                for b, style in zip(drawn, FREQUENCY_STYLES * len(drawn))]
    _legend(fig, panels, own, "right upper", handles=handles, title="block; branch")
    label_points(marks)
    for inset, (block, n) in zip(insets, shown):
        b, s = drawn[0], drawn[0].data["special_points"][n]
        draw_mode(inset, b, n, block, b.data["modes"][block][n, 0], colours[block])
        inset.set_title(f"{block}: {s['label']} {s['kind']}", fontsize="x-small", color=colours[block])
        inset.set_xticks([]), inset.set_yticks([])
        for spine in inset.spines.values():
            spine.set_edgecolor(colours[block])
    return fig


def mode_points(b) -> list:
    """(block, special point number) for each block with stored mode shapes of the branch ``b``: the special point
    where the block's lowest Ω² is nearest zero among those with a stored shape (its own stability change where it
    has one)."""
    out = []
    for block, shapes in (b.data.get("modes") or {}).items():
        values = np.abs(b.data["special_frequencies"][block][:, 0])
        stored = np.isfinite(shapes[:, 0]).all(axis=(1, 2)) & np.isfinite(values)
        if stored.any():
            out.append((block, int(np.flatnonzero(stored)[np.argmin(values[stored])])))
    return out


STABILITY_CHANGES = ("LP", "LV", "LN", "BP")  # the special points where an Ω² of a block passes through zero
MODE_AMPLITUDE = 0.15  # the drawn mode's largest displacement, as a fraction of the outline's largest radius


def critical_modes(branches) -> list:
    """(branch, special point, its state's row, block, Ω², mode shape (3 × θ)) at every fold and branch point of
    the branches with stored mode shapes: the mode of the stored Ω² nearest zero over the blocks (the mode whose
    frequency vanishes there)."""
    found = []
    for b in branches:
        modes = b.data.get("modes") or {}
        for n, s in enumerate(b.data["special_points"]):
            if s["kind"] not in STABILITY_CHANGES or not modes:
                continue
            block, k = min(((block, int(np.nanargmin(np.abs(values[n])))) for block, values in
                            b.data["special_frequencies"].items() if np.isfinite(values[n]).any()),
                           key=lambda pair: abs(b.data["special_frequencies"][pair[0]][n, pair[1]]))
            found.append((b, s, n, block, b.data["special_frequencies"][block][n, k], modes[block][n, k]))
    return found


def plot_modes(branches, axes=None) -> Figure:
    """The mode shape of every fold and branch point (``critical_modes``): the special point's deformed meridian
    section (ρ, η) at φ = 0 and φ = π and the outline displaced by ± the mode (δρ, δz at φ = 0, times cos mφ = ±1
    at φ = π; δφ, in the plane of neither, is not drawn), scaled to MODE_AMPLITUDE of the largest radius; one
    panel per point (docs/dynamics.md). Runs without [dynamics] modes = true fail with a one-line message."""
    found = critical_modes(branches)
    if not found:
        files = ", ".join(dict.fromkeys(str(b.source) for b in branches))
        raise PlotError(f"{files}: no stored mode shapes at a fold or branch point (frequencies/modes_<block>); run "
                        "the scene with [dynamics] frequencies = true and modes = true")
    columns = min(3, len(found))
    rows = -(-len(found) // columns)
    fig, panels, own = _panels(axes, len(found), (2.6 * columns, 2.8 * rows), nrows=rows, ncols=columns,
                               squeeze=False)
    panels = np.ravel(panels)
    for ax in panels[len(found):]:
        ax.set_visible(False)
    for ax, (b, s, n, block, omega2, shape) in zip(panels, found):
        draw_mode(ax, b, n, block, shape)
        ax.set_title(f"{s['label']} {s['kind']}, {block}\n$\\Omega^2$ = {omega2:.1e}", fontsize="small")
        ax.set_xlabel(r"$\rho$")
        ax.set_ylabel(r"$\eta$")
    _suptitle(fig, panels, own, _title(branches))
    return fig


def draw_mode(ax, b, n: int, block: str, shape, color=None) -> None:
    """Special point ``n`` of the branch ``b``: its deformed meridian section (ρ, η) at φ = 0 and φ = π (black) and
    the outline displaced by ± the mode ``shape`` of ``block`` (δρ, δz at φ = 0, times cos mφ = ±1 at φ = π; δφ, in
    the plane of neither, is not drawn), scaled to MODE_AMPLITUDE of the largest radius, in ``color`` (default the
    branch's)."""
    d = b.data
    outline = surface(branch_discretisation(d), d["special_unknowns"][n], d["theta"], stored_scene(b.run).geometry)
    rho, eta = outline["rho"][0], outline["eta"][0]
    m = Block.order_of(block)
    scale = MODE_AMPLITUDE * rho.max() / max(np.abs(shape[:2]).max(), np.finfo(float).tiny)
    for side in (1.0, -1.0):  # φ = 0, φ = π (cos mφ = (−1)^m)
        turn = side ** m
        ax.plot(side * rho, eta, color="k", linewidth=1.0)
        for sign, style in ((1.0, "-"), (-1.0, "--")):
            ax.plot(side * (rho + sign * scale * turn * shape[0]), eta + sign * scale * turn * shape[1], style,
                    color=color or b.color, linewidth=0.9)
    ax.set_aspect("equal")


def plot_energy(branches, axes=None) -> Figure:
    """Energy landscape E(Λ) − E0 = E2Λ² + E3Λ³ + E4Λ⁴ along the critical mode at each branch point (the
    special points with finite E2, E3, E4, written by the stability analysis)."""
    if not any(b.bifurcations for b in branches):
        files = ", ".join(dict.fromkeys(str(b.source) for b in branches))
        raise PlotError(f"{files}: no bifurcation data (no special point with finite special_points/E2, E3, E4, "
                        "which the stability analysis writes); the energy landscape cannot be drawn")
    fig, (ax,), own = _panels(axes, 1, (6.4, 4.8))
    ax.axhline(0.0, color="0.6", linewidth=0.6)
    styles = ["-", "--", "-.", ":"]
    drawn = 0
    for b in branches:
        for s in b.bifurcations:
            e2, e3, e4 = (s[k] for k in NORMAL_FORM)
            amplitude = np.linspace(-1, 1, 401) * _amplitude_range(e2, e3, e4)
            energy = e2 * amplitude**2 + e3 * amplitude**3 + e4 * amplitude**4
            ax.plot(amplitude, energy, color=b.color, linestyle=styles[drawn % len(styles)], linewidth=1.4,
                    label=f"{b.label}: {special_label(s)} at {b.ordinate.symbol} = {s[b.ordinate.column]:.6g}\n"
                          f"E2 = {e2:.3g}, E3 = {e3:.3g}, E4 = {e4:.3g}")
            drawn += 1
    ax.set_xlabel(r"amplitude $\Lambda$ along the critical mode")
    ax.set_ylabel(r"$E(\Lambda) - E_0$ (per $2\pi$, units of $T_0 R_0^2 \mu/2$)")
    ax.set_title(_title(branches))
    _legend(fig, [ax], own, "lower center")  # an own figure's under the panel, not over the curves
    return fig


PARAMETER_LABELS = {"M": r"field intensity $M$", "alpha1": r"Ogden exponent $\alpha_1$ ($\sum\mu_i\alpha_i = 4$)"}


def plot_phase(paths, axes=None) -> Figure:
    """Phase diagram from two-parameter curves (files written by ``io.curve_file.write_curve``): the pear
    bifurcation pressure (or a fold curve's pressure) against the second parameter q; the two pitchforks of an
    isola meet where q turns back (the critical q, marked), as a fold curve's two folds do at its cusp; the region
    where the isola exists (q between its start and the critical value, P between the two pitchfork pressures),
    or where the balloon snaps through (between the two folds), is shaded."""
    fig, (ax,), own = _panels(axes, 1, (6.4, 4.6))
    parameters, kinds, open_folds = {}, set(), {}  # parameters: {scene key: (short name, [what is drawn in it])}
    if any(isinstance(path, dict) for path in paths):
        raise PlotError("phase draws curve files (balloon-cg critical) or sweep files, not runs")
    for path in paths:
        check_input(path)
        try:
            f = h5py.File(path, "r")
        except (OSError, RuntimeError):
            raise FileError(path, "not a readable HDF5 file") from None
        with f, reading(path):
            names = list(f.get("two_parameter", {}))
            is_sweep = "members" in f
        if is_sweep:
            key, kind = _sweep_phase(ax, path)
            parameters.setdefault(key, ("M" if key == "field.M" else key, []))[1].append(Path(path).stem)
            kinds.add(kind)
            continue
        if not names:
            raise PlotError(f"{path}: no two-parameter curve and no sweep members in this file (write one with "
                            "`balloon-cg critical` or `balloon-cg sweep`)")
        for name in names:
            curve = read_curve(path, name)
            q, P = curve["q"], curve["pressure"]
            short = curve["attrs"]["parameter"]
            key = curve["attrs"].get("parameter_key", "field.M" if short == "M" else short)  # older files: M, alpha1
            parameters.setdefault(key, (short, []))[1].append(f"{Path(path).stem}: {name}")
            folds = [(s["index"], q_s, s["pressure"]) for s, q_s in zip(curve["special_points"], curve["special_q"])
                     if s["kind"] == "LP"]
            dense_q, dense_P = smooth_curve(*_with_points(q, P, folds))
            line, = ax.plot(dense_q, dense_P, label=f"{Path(path).stem}: {name}")
            ax.plot(q, P, "o", markersize=2, color=line.get_color())
            critical = curve["attrs"].get("critical_q", np.nan)
            merges = [s for s in curve["special_points"] if s["kind"] == "LP"]
            of = curve["attrs"].get("of", "BP")
            kinds.add(of)
            if np.isfinite(critical) and merges:
                P_merge = merges[0]["pressure"]
                region = "isola exists" if of == "BP" else f"snap-through ({of}: two folds)"
                ax.fill(dense_q, dense_P, alpha=0.15, color=line.get_color(),  # closed at the start value q0
                        label=f"{region} (traced from {curve['attrs']['parameter']} = {curve['attrs']['q0']:g})")
                ax.plot(critical, P_merge, "o", color=line.get_color(),  # its value in the legend: inside the figure
                        label=f"{'critical' if of == 'BP' else 'cusp'} {curve['attrs']['parameter']} = {critical:.6g}")
            elif of != "BP":
                open_folds.setdefault(of, []).append((q, P))  # one parameter: checked below
            for meeting in curve_meetings(curve):  # a fold curve crosses this pitchfork curve, or a branch point
                ax.plot(meeting["q"], meeting["pressure"], "D", color=line.get_color(), markerfacecolor="none",
                        label=f"{meeting['kind']} {curve['attrs']['parameter']} = {meeting['q']:.6g}")
    for of, folds in open_folds.items():
        _shade_between_folds(ax, of, folds)
    if len(parameters) > 1:  # one q axis
        listed = "; ".join(f"{key} ({', '.join(drawn)})" for key, (_, drawn) in parameters.items())
        raise PlotError(f"phase draws the curves of one second parameter on one axis; these are in "
                        f"{len(parameters)}: {listed} (draw each parameter's files on their own)")
    [(parameter, _)] = parameters.values()
    ax.set_xlabel(PARAMETER_LABELS.get(parameter, parameter))
    ylabel, title = phase_titles(kinds)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    _legend(fig, [ax], own, "lower center")  # an own figure's under the panel, not over the curves
    return fig


def phase_titles(kinds: set) -> tuple[str, str]:
    """(y label, title) of a phase diagram of the curves of ``kinds`` (what they follow: BP, the pear pitchforks;
    LP, LV, LN, folds; "onset", a tube sweep's columns), naming only what is drawn."""
    folds = ", ".join(sorted(kinds - {"BP", "onset"}))
    P = r"pressure $P = \bar P R_0/(T_0\mu/2)$"
    if kinds == {"onset"}:
        return P, "the tube's onset of bulging, pressure maximum, bulge fold and Maxwell's pressure"
    if not folds:
        return "bifurcation " + P, "pear-shaped pitchforks (the isola lies between the two)"
    if "BP" not in kinds:
        return f"{P} at the fold ({folds})", f"fold curve ({folds}): snap-through between its two branches"
    return (f"{P} at the pitchfork (BP) or fold ({folds})",
            "pitchforks and folds (snap-through between a fold curve's two branches)")


def _shade_between_folds(ax, of: str, folds: list) -> None:
    """Shade the bistable region between two fold curves of one kind (``of``: LP, LV, LN), each traced on its own
    (the upper and the lower fold, e.g. ``continue`` from each, not met in a cusp): P between them over the q both
    span (PCHIP through their stored points), where each is single-valued in q (a curve that turns in q has its
    cusp or merge and is shaded whole). Under that control the balloon snaps through at one fold and back at the other: between them two stable states.
    With one such curve, or more than two, nothing is shaded."""
    if len(folds) != 2 or any(np.any(np.diff(q) == 0) or np.any(np.diff(np.sign(np.diff(q)))) for q, _ in folds):
        return
    low, high = max(q.min() for q, _ in folds), min(q.max() for q, _ in folds)
    if not low < high:
        return
    dense = np.union1d(np.linspace(low, high, 400), [x for q, _ in folds for x in q if low <= x <= high])
    edges = [PchipInterpolator(np.sort(q), P[np.argsort(q)])(dense) for q, P in folds]
    ax.fill_between(dense, edges[0], edges[1], alpha=0.15, color="0.5",
                    label=f"bistable: snap-through between the two {of} curves")


def _with_points(q, P, extra):
    """(q, P) with the points (index, q, P) of ``extra`` inserted after their ``index`` (located special points
    between two stored points: the fold of the curve in q, its apex)."""
    q, P = list(q), list(P)
    for index, q_s, P_s in sorted(extra, reverse=True):
        q.insert(index + 1, q_s)
        P.insert(index + 1, P_s)
    return np.array(q), np.array(P)


def smooth_curve(q, P, samples: int = 400):
    """The two-parameter curve through its points (q, P): q and P each interpolated in the cumulative chord
    length (both scaled by their ranges) by PCHIP, so that lines and shading follow the curve between its points
    rather than chords, without overshooting them (no spurious hooks where the points are sparse); fewer than 3
    points are returned as they are."""
    q, P = np.asarray(q, dtype=float), np.asarray(P, dtype=float)
    if q.size < 3:
        return q, P
    steps = np.hypot(np.diff(q) / (np.ptp(q) or 1.0), np.diff(P) / (np.ptp(P) or 1.0))
    keep = np.r_[True, steps > 0]  # repeated points (a located special point stored twice) once
    s = np.r_[0.0, np.cumsum(steps)][keep]
    dense = PchipInterpolator(s, np.column_stack([q, P])[keep])(np.linspace(0.0, s[-1], samples))
    return dense[:, 0], dense[:, 1]


TUBE_PHASE = (("P_onset", "onset of bulging (the first odd BP)", "o-"),
              ("P_max", "pressure maximum of the uniform tube (LP)", "s--"),
              ("P_LV", "the bulge's volume fold (LV)", "^-"),
              ("P_M", "Maxwell's pressure", "d:"))  # a tube sweep's columns (io/tube_file.tube_row) drawn by phase


def _sweep_phase(ax, path) -> tuple[str, str]:
    """Pear pitchfork pressures of every sweep member against the first varied key, and the primary branch's
    fold (LP, the pressure maximum); the isola region (two pitchforks) shaded between them, its edges
    interpolated between the members monotonically (PCHIP: no overshoot). A tube's sweep: its members' onset of
    bulging, pressure maximum, bulge fold and Maxwell pressure (``TUBE_PHASE``). Returns (the varied key (dotted),
    what is drawn: "BP" or "onset", ``phase_titles``)."""
    sweep = read_sweep(path)
    if sweep["attrs"].get("mode") == "primary-only":  # no stability, so no branch points: an empty diagram
        raise PlotError(f"{path}: a primary-only sweep has no branch points to draw (sweep without --primary-only)")
    members = sweep["members"].values()
    if members and all(m["attrs"].get("shape") == Shape.TUBE.value for m in members):
        from ..io.tube_file import tube_row  # here: a sphere's figures need none of the tube's modules

        rows = sorted(((float(next(iter(m["overrides"].values()))), tube_row(m)) for m in members),
                      key=lambda row: row[0])
        for column, label, style in TUBE_PHASE:
            values = np.array([row[column] for _, row in rows])
            if np.isfinite(values).any():
                ax.plot([q for q, _ in rows], values, style, ms=3, label=f"{Path(path).stem}: {label}")
        return next(iter(next(iter(members))["overrides"])), "onset"
    rows = []
    for name, member in sweep["members"].items():
        key, value = next(iter(member["overrides"].items()))
        primary = member["branches"]["primary"]
        if ordinate_of(primary) != PRESSURE_ORDINATE:
            raise PlotError(f"{path}: member {name} is continued in {ordinate_of(primary).column}: phase draws the "
                            "pitchfork pressures of pressure continuations")
        specials = primary["special_points"]
        pressures = sorted(s["pressure"] for s in specials if s["block"] == "odd_held")
        folds = [s["pressure"] for s in specials if s["kind"] == "LP"]
        rows.append((float(value), pressures, folds[0] if folds else np.nan))
    rows.sort(key=lambda r: r[0])
    for n in range(max((len(r[1]) for r in rows), default=0)):
        ax.plot([r[0] for r in rows if len(r[1]) > n], [r[1][n] for r in rows if len(r[1]) > n], "o-", ms=3,
                label=f"{Path(path).stem}: pear pitchfork {n + 1}")
    if any(np.isfinite(r[2]) for r in rows):
        ax.plot([r[0] for r in rows], [r[2] for r in rows], "s--", ms=3, color="0.3",
                label=f"{Path(path).stem}: fold (LP) of the primary branch")
    two = [r for r in rows if len(r[1]) >= 2]
    if len(two) >= 2:
        q = np.array([r[0] for r in two])
        dense = np.linspace(q[0], q[-1], 200)
        low, high = (PchipInterpolator(q, [r[1][k] for r in two])(dense) for k in (0, -1))
        ax.fill_between(dense, low, high, alpha=0.15, label="isola exists")
    return key, "BP"


KINDS = {
    "pressure-pole": (plot_pressure_pole, False),
    "pressure-equator": (plot_pressure_equator, False),
    "voltage-pole": (plot_voltage_pole, False),
    "voltage-equator": (plot_voltage_equator, False),
    "shapes": (plot_shapes, True),
    "stresses": (plot_stresses, True),
    "field": (plot_field, True),
    "curvature": (plot_curvature, True),
    "energy": (plot_energy, False),
    "frequencies": (plot_frequencies, False),
    "modes": (plot_modes, False),
    "phase": (plot_phase, False),
    "surface": (plot_surface, True),
    "stretch-map": (plot_stretch_map, True),
}
SURFACE_DRAWN = ("pressure-pole", "voltage-pole", "energy")  # the branch kinds that draw surface branches too
SURFACE_KINDS = ("surface", "stretch-map")  # one state of a surface branch
