"""The Python API (docs/api.md): a scene in, a ``Result`` out.

    trace(scene) -> Result             the primary branch
    analyse(scene) -> Result           the whole picture: stability, branch points, pear branches, snap-throughs
    load(path) -> Result               a run file (a sweep file: SweepResult; a curve file: CurveResult)
    plot(source, what, ax=None) -> matplotlib Figure, from Results or run files

A ``Result`` is plain data: the content of its run file (``image``, the bytes of the HDF5 file that ``save``
writes, and the same content read into arrays, ``run``, laid out as ``io.run_file.read_run`` returns it) and,
when it was computed in this process, the analysis objects (``picture``: branches with their assessments).
Tables come from the same content: ``to_dataframe`` (pandas) and ``to_xarray`` (xarray; named dimensions and
units, read from the file image through h5netcdf), both from the optional extra ``balloon-cg[analysis]``.
"""
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..analysis.picture import Phase
from ..io.hdf5 import atomic_bytes, command_line
from ..io.layout import file_kind
from ..io.parents import parent_label
from ..io.run_file import RunFileError, read_run, read_run_image, run_image, stored_scene
from ..numerics.interrupt import stop_on_signals
from ..scene import Scene, SceneError, Shape, load_scene
from ..scene.tables import startable
from .progress import PhaseBars
from .tables import SpecialPoints, counted, html_table, optional


@dataclass(frozen=True, repr=False)
class BranchData:
    """One stored branch of a run (``result.branches[name]``).

    ``data`` is its read_run() dict (per-point arrays, 'attrs', 'profiles', 'special_points', 'stability');
    ``branch['pressure']`` indexes it and ``len(branch)`` is its number of points. A surface branch (``m`` ≥ 1,
    analysis.results.SurfaceBranch) holds 'coefficients', 'volume', 'centroid', 'tilt' instead of the Legendre
    unknowns and profiles (docs/hdf5.md).

    Examples
    --------
    >>> primary = result.branches["primary"]
    >>> primary["pressure"].max(), primary.special_points.kinds()
    """

    name: str
    data: dict
    born_at: int | None = None  # the label of the point it leaves from (io.parents; None: the primary branch)

    def __getitem__(self, key: str):
        return self.data[key]

    def __len__(self) -> int:
        return len(self.data["pressure"])

    @property
    def attrs(self) -> dict:
        """The branch's stored attributes (docs/hdf5.md: degree, stop_reason, M, m, parent_branch, …)."""
        return self.data["attrs"]

    @property
    def special_points(self) -> SpecialPoints:
        """The branch's special points, one table (app.tables.SpecialPoints: a dict per point)."""
        return SpecialPoints(self.data["special_points"])

    @property
    def m(self) -> int:
        """The azimuthal number: 0 for an axisymmetric branch, m ≥ 1 for a surface branch."""
        return int(self.attrs.get("m", 0))

    @property
    def parent(self) -> tuple | None:
        """(branch name, branch point number) the branch leaves from; None for the primary branch."""
        if "parent_branch" not in self.attrs:
            return None
        return self.attrs["parent_branch"], int(self.attrs["parent_branch_point"])

    def columns(self) -> dict:
        """The per-point columns.

        Returns
        -------
        dict
            Every 1-D per-point dataset (name -> array), the centroid of a surface branch as centroid_x,
            centroid_y, centroid_z, and the stability flags stable_*.
        """
        n = len(self)
        flat = {k: v for k, v in self.data.items()
                if isinstance(v, np.ndarray) and v.shape == (n,) and k != "point"}
        centroid = {f"centroid_{axis}": self.data["centroid"][:, k] for k, axis in enumerate("xyz")
                    if "centroid" in self.data}
        flags = {k: v for k, v in self.data.get("stability", {}).items() if k.startswith("stable")}
        return flat | centroid | flags

    def to_dataframe(self):
        """The branch as a table.

        Returns
        -------
        pandas.DataFrame
            One row per point (index ``point``), the ``columns``.

        Raises
        ------
        ImportError
            Without pandas (``pip install 'balloon-cg[analysis]'``).
        """
        pd = optional("pandas", "to_dataframe")
        return pd.DataFrame(self.columns()).rename_axis("point")

    def summary(self) -> dict:
        """One row about the branch (its line in ``Result``'s HTML table).

        Returns
        -------
        dict
            branch, m, points, P min, P max, λ2(0) min, λ2(0) max, the kinds of its special points, its parent
            branch and the label of the point it leaves from.
        """
        P, north = self.data["pressure"], self.data["lam2_top"]
        parent = self.parent
        return {"branch": self.name, "m": self.m, "points": len(self), "P min": P.min(), "P max": P.max(),
                "λ2(0) min": north.min(), "λ2(0) max": north.max(),
                "special points": " ".join(s["kind"] for s in self.data["special_points"]),
                "parent": f"{parent[0]}, from label {self.born_at}" if self.born_at is not None else ""}

    def __repr__(self):
        P, north, special = self.data["pressure"], self.data["lam2_top"], len(self.data["special_points"])
        return (f"BranchData({self.name!r}, {counted(len(self), 'point')}, P {P.min():.4g}..{P.max():.4g}, "
                f"λ2(0) {north.min():.4g}..{north.max():.4g}, {counted(special, 'special point')})")

    def _repr_html_(self):
        head = html_table([self.summary()], repr(self))
        return head and head + (self.special_points._repr_html_() if self.data["special_points"] else "")


@dataclass(frozen=True, repr=False)
class Result:
    """A computed or loaded run: what ``analyse``, ``trace`` and ``load`` return.

    ``scene`` the Scene; ``image`` the bytes of its run file (what ``save`` writes); ``run`` the same content as
    arrays (io.run_file.read_run's layout); ``picture`` the analysis objects when computed in this process (else
    None). Tables: ``branches``, ``special_points``, ``to_dataframe``, ``to_xarray``; the verdict:
    ``complete``, ``incomplete``, ``interrupted``. A notebook shows it as a table of its branches.

    Examples
    --------
    >>> result = bc.analyse("spom1")
    >>> result.to_dataframe().groupby("branch").pressure.max()
    >>> result.special_points.to_dataframe().query("kind == 'BP'")
    """

    scene: Scene
    image: bytes
    run: dict
    picture: object = None

    @classmethod
    def of(cls, scene: Scene, branches, snaps=None, found=None, picture=None, command: str = "",
           clock=None) -> "Result":
        image = run_image(scene, branches, {"command": command or command_line()}, snaps, found, clock,
                          None if picture is None else picture.meridian_surface)
        return cls(scene, image, read_run_image(image, scene.name), picture)

    @property
    def branches(self) -> dict[str, BranchData]:
        """The stored branches by name, the primary branch first."""
        return {name: BranchData(name, data, parent_label(self.run, name))
                for name, data in self.run["branches"].items()}

    @property
    def special_points(self) -> SpecialPoints:
        """Every special point of every branch as one table (app.tables.SpecialPoints: a dict of the stored
        columns per point, with 'branch'; ``.to_dataframe()``, ``.to_xarray()``)."""
        return SpecialPoints({"branch": name, **s} for name, b in self.run["branches"].items()
                             for s in b["special_points"])

    @property
    def snap_throughs(self) -> list[dict]:
        """The snap-throughs under the loading control (dicts: from_branch, from_index, pressure, to_branch,
        to_index; docs/hdf5.md)."""
        return self.run["snap_throughs"]

    @property
    def geometry(self) -> dict:
        """The reference shape and its parameters: the scene's [geometry] table (shape with aspect, or a capsule's
        length); also the attributes of every ``to_xarray`` Dataset."""
        return self.scene.geometry.to_table()

    @property
    def complete(self) -> bool:
        """Every branch reached its requested end, every special point is located, stability is settled."""
        return bool(self.run["attrs"].get("complete", False))

    @property
    def incomplete(self) -> list[str]:
        """What is incomplete, one line each ('gap (branch: message)')."""
        a = self.run["attrs"]
        return [f"{gap} ({branch}: {message})" for gap, branch, message in
                zip(a.get("incomplete_gaps", []), a.get("incomplete_branches", []), a.get("incomplete_messages", []))]

    @property
    def interrupted(self) -> bool:
        """A signal (SIGINT/SIGTERM) stopped the computation: what is stored ends early."""
        return "interrupted" in self.run["attrs"].get("incomplete_gaps", [])

    def to_dataframe(self, table: str = "points"):
        """The run as one tidy table.

        Parameters
        ----------
        table : str, optional
            ``"points"`` (default): one row per point of every branch, or ``"special"``: one row per special
            point (``special_points.to_dataframe()``).

        Returns
        -------
        pandas.DataFrame
            For ``"points"``: columns branch, m (0: axisymmetric, m ≥ 1: a surface branch), point, then the
            per-point columns; a column a branch does not have is NaN in its rows.

        Raises
        ------
        ValueError
            Another ``table``.
        ImportError
            Without pandas (``pip install 'balloon-cg[analysis]'``).
        """
        pd = optional("pandas", "to_dataframe")
        if table == "special":
            return self.special_points.to_dataframe()
        if table != "points":
            raise ValueError(f"table = {table!r}: must be 'points' or 'special'")
        frames = [b.to_dataframe().reset_index().assign(branch=name, m=b.m) for name, b in self.branches.items()]
        if not frames:  # nothing stored (a file written before run files needed their primary branch)
            return pd.DataFrame(columns=["branch", "m", "point"])
        frame = pd.concat(frames, ignore_index=True)
        return frame[["branch", "m", *[c for c in frame.columns if c not in ("branch", "m")]]]

    def to_xarray(self, branch: str = "primary", part: str = "points"):
        """One branch as an xarray Dataset, read from the file image with named dimensions and units.

        Parameters
        ----------
        branch : str, optional
            The branch's name (default ``"primary"``).
        part : str, optional
            ``"points"`` (default): dims point, unknown, theta (the per-point columns, profiles, stability and
            natural frequencies, dims eigenvalue, frequency; a surface branch: point, coefficient, axis, eigenvalue),
            or ``"special"``: the special points, dim special.

        Returns
        -------
        xarray.Dataset
            Its attributes: the branch's and the reference shape's (``geometry``: shape, aspect or length).

        Raises
        ------
        KeyError
            No such branch.
        ValueError
            Another ``part``.
        """
        optional("h5netcdf", "to_xarray")
        xr = optional("xarray", "to_xarray")
        if branch not in self.run["branches"]:
            raise KeyError(f"no branch {branch!r} (branches: {', '.join(self.run['branches'])})")
        data = self.run["branches"][branch]
        groups = {"points": [""] + [f"/{g}" for g in ("profiles", "stability", "frequencies") if g in data],
                  "special": ["/special_points"]}
        if part not in groups:
            raise ValueError(f"part = {part!r}: must be 'points' or 'special'")
        parts = []
        for group in groups[part]:
            with xr.open_dataset(io.BytesIO(self.image), engine="h5netcdf", group=f"branches/{branch}{group}") as ds:
                parts.append(ds.load())
        return xr.merge(parts, combine_attrs="override").assign_attrs(self.geometry)

    def save(self, path, force: bool = False) -> Path:
        """Write the run file, atomically.

        Parameters
        ----------
        path : str or Path
            The run file to write (HDF5, docs/hdf5.md).
        force : bool, optional
            Replace an existing file (default False: FileExistsError).

        Returns
        -------
        Path
            ``path``.
        """
        try:
            return atomic_bytes(path, self.image, force)
        except FileExistsError as e:
            raise FileExistsError(e.errno, "already exists (save(..., force=True) replaces it)", e.filename) from None

    def __repr__(self):
        branches = self.run["branches"]
        points = sum(len(b["pressure"]) for b in branches.values())
        n = len(self.incomplete)
        state = "complete" if self.complete else f"incomplete: {counted(n, 'part')}"
        shape = "" if self.scene.geometry.shape == Shape.SPHERE else f"{self.scene.geometry.describe()}; "
        return (f"Result({self.scene.name!r}: {shape}{counted(len(branches), 'branch', 'branches')}, "
                f"{counted(points, 'point')}, {counted(len(self.special_points), 'special point')}, "
                f"{counted(len(self.snap_throughs), 'snap-through')}; {state})")

    def _repr_html_(self):
        return html_table([b.summary() for b in self.branches.values()], repr(self))


def _scene(scene) -> Scene:
    """A scene a new run may start: a Scene checked as new input is (``startable``: one read from a file's stored text
    is not), or a path loaded."""
    return startable(scene) if isinstance(scene, Scene) else load_scene(scene)


def computed(scene: Scene, primary_only: bool = False, pear: bool = True, progress: bool = False):
    """(branches, snap-throughs, incomplete entries, picture, clock) of ``scene``, one progress bar per phase: the
    primary branch only (snap-throughs and picture None; a field that is not axisymmetric has no other branches
    yet: its picture), or the whole picture (analysis.picture.analyse; its
    axisymmetric branches, then its surface branches); ``clock`` the seconds of each phase (analysis.timing,
    started here: the writer adds its own). With [dynamics] frequencies = true the axisymmetric branches get their
    natural frequencies (dynamics.frequencies.attach_to: not after a signal, and a signal during them stops
    them)."""
    from ..analysis.picture import Picture, analyse as analyse_picture
    from ..analysis.branches.primary import trace_primary
    from ..analysis.timing import Clock, Step
    from ..dynamics.frequencies import attach_to

    clock = Clock()
    with PhaseBars(scene.name, progress) as bars:
        if primary_only and scene.field.is_axisymmetric:
            with clock.step(Step.TRACE):
                branches = [trace_primary(scene, progress=bars.ticker(Phase.PRIMARY))]
            bars.finish(Phase.PRIMARY, len(branches[0].X))
            traced = Picture(branches, clock=clock)  # for its verdict: what is incomplete, a signal's phase
            attach_to(traced, scene.dynamics)
            return branches, None, traced.incomplete, None, clock
        picture = analyse_picture(scene, bars, pear=pear, clock=clock)
        attach_to(picture, scene.dynamics)
        return picture.branches + picture.surface_branches, picture.snaps, picture.incomplete, picture, clock


def trace(scene, progress: bool = False) -> Result:
    """The primary branch of a scene.

    Ctrl-C (SIGINT) stops it at the next point and returns what is finished, flagged incomplete.

    Parameters
    ----------
    scene : Scene or str or Path
        A Scene, a TOML file, or the name of a shipped scene (``shipped_scenes()``).
    progress : bool, optional
        Draw a progress bar (default False).

    Returns
    -------
    Result
        The primary branch alone.

    Examples
    --------
    >>> result = bc.trace("spom1")
    """
    scene = _scene(scene)
    with stop_on_signals():
        branches, snaps, found, _, clock = computed(scene, primary_only=True, progress=progress)
    return Result.of(scene, branches, snaps, found, command=f"balloon_cg.trace({scene.name!r})", clock=clock)


def analyse(scene, pear: bool = True, progress: bool = False) -> Result:
    """The whole picture of a scene.

    The primary branch, the stability of every point, branch points located and classified, pear branches,
    surface branches, snap-throughs (analysis.picture). Ctrl-C (SIGINT) stops at the next point and returns
    what is finished, flagged incomplete.

    Parameters
    ----------
    scene : Scene or str or Path
        A Scene, a TOML file, or the name of a shipped scene (``shipped_scenes()``).
    pear : bool, optional
        Trace the pear branches (default True).
    progress : bool, optional
        One progress bar per phase (default False; a widget in a notebook).

    Returns
    -------
    Result

    Examples
    --------
    >>> scene = bc.Scene.from_toml("spom1_two_coils_M0.002").with_overrides({"M": 0.001})
    >>> result = bc.analyse(scene, progress=True)
    >>> result.save("two_coils_M0.001.h5")
    """
    scene = _scene(scene)
    with stop_on_signals():
        branches, snaps, found, picture, clock = computed(scene, pear=pear, progress=progress)
    return Result.of(scene, branches, snaps, found, picture, command=f"balloon_cg.analyse({scene.name!r})",
                     clock=clock)


def continue_from(path, label: int, parameter: str | None = None, direction: float = 1.0,
                  overrides: dict | None = None):
    """Restart from a labelled special point of a run file (``balloon-cg continue``, app.restart).

    Ctrl-C (SIGINT) stops it at the next point.

    Parameters
    ----------
    path : str or Path
        A run file written by ``run`` (``inspect`` lists its labels).
    label : int
        The special point's label.
    parameter : str, optional
        A second parameter (a scene key, as for ``critical``); default None: the branch's own parameter.
    direction : float, optional
        A fold curve starts with the parameter increasing (1, default) or decreasing (-1).
    overrides : dict, optional
        Scene keys to set for what is traced (``continue --set``): continuation, solver, stability, surface,
        loading and events keys only (``{"continuation.max_points": 800}``; None restores a default).

    Returns
    -------
    Result or FoldCurve or TwoParameterCurve
        Without ``parameter``, the branch through the point (a Result whose branch is ``primary``, assessed and its
        branch points located if the stored branch was; from a point of a pear branch, that branch under its name
        after its parent ``primary`` as read), or at a branch point the branches bifurcating there (a
        Result of the point's branch as read, not assessed, and of them, assessed: ``pear_<n>`` and
        ``pear_<n>_mirror`` at a pear point, ``m<m>_bp<k>`` and its other direction at a held m ≥ 1 point);
        from a fold (LP, LV, LN) or a pear pitchfork (held or free) in ``parameter``, the two-parameter curve
        (``end``, ``critical``, ``meetings``: where a fold meets a pitchfork or branch point, ``q``, ``pressure``).

    Raises
    ------
    ValueError
        A label or parameter it cannot start from (app.restart.RestartError,
        analysis.critical.second_parameter.UnknownParameter).
    RuntimeError
        At a branch point, no bifurcating branch started (the reasons named).

    Examples
    --------
    >>> curve = bc.continue_from("gent.h5", 2, parameter="material.parameters.Jm", direction=-1)
    """
    from ..analysis.picture import Picture
    from ..analysis.results import Kind
    from ..io.run_file import read_run
    from .restart import find_label, restart, with_settings

    start = with_settings(find_label(read_run(path), int(label)), overrides or {})
    with stop_on_signals():
        result = restart(start, parameter, direction)
    command = f"balloon_cg.continue_from({str(path)!r}, {label})"
    if isinstance(result, Picture):
        branches = result.branches + result.surface_branches
        if len(branches) == 1 and start.point.kind == Kind.BP:
            raise RuntimeError(f"no branch started at label {label}: " + "; ".join(
                f"{name}: {reason}" for name, reason in result.not_started))
        return Result.of(branches[0].scene, branches, result.snaps, result.incomplete, result, command=command)
    return result


def load(path):
    """What a balloon-cg file holds.

    Parameters
    ----------
    path : str or Path
        A run, sweep, two-parameter curve or tube run file.

    Returns
    -------
    Result or SweepResult or CurveResult or TubeResult
        The ``Result`` of a run file, the ``SweepResult`` of a sweep file (its members and a table of what each
        found), the ``CurveResult`` of a curve file (named after its parameter), the ``TubeResult`` of a tube run
        file (app/tube_result.py).

    Raises
    ------
    FileNotFoundError
        No such file (IsADirectoryError: a folder).
    FileError
        A damaged or foreign file, or a stored scene that does not parse (io.layout.FileError: RunFileError,
        SweepFileError, CurveFileError; one line naming the file and what is wrong).

    Examples
    --------
    >>> table = bc.load("sweep.h5").to_dataframe()[["field.M", "P_cr1"]]
    """
    kind = file_kind(path, RunFileError)
    if kind == "sweep":
        from .sweep_result import SweepResult
        return SweepResult.read(path)
    if kind == "curve":
        from .curve_result import CurveResult
        return CurveResult.read(path)
    if kind == "tube":
        from .tube_result import TubeResult
        return TubeResult.read(path)
    run = read_run(path)
    try:
        scene = stored_scene(run)
    except SceneError as e:
        raise RunFileError(path, f"the stored scene_toml is not a valid scene ({e})") from None
    return Result(scene, Path(path).read_bytes(), run)


def plot(source, what: str | None = None, ax=None, points=None, branch: str | None = None,
         stability: str | None = None, width: float | None = None):
    """A figure from Results or run files, in the journal style.

    Parameters
    ----------
    source : Result, SweepResult, CurveResult, TubeResult, str or Path, or a list of them
        What to draw (several: one curve set each): a run, a loaded sweep or curve file (``load``), a file's path;
        a tube run (a TubeResult or its file) alone, on a Figure of its own.
    what : str, optional
        The kind (docs/plots.md; a tube's: post.tube_plots.TUBE_KINDS); None: the pole curve of the continuation
        parameter, ``pressure-pole`` or, for a run continued in the voltage, ``voltage-pole``; ``phase`` for a sweep
        or curve; ``pressure-volume`` for a tube.
    ax : matplotlib Axes or sequence of Axes, optional
        Draw into these (a sequence for the kinds with several panels); None: a new Figure.
    points : list of int, optional
        Point indices for shapes, stresses, field, curvature, surface, stretch-map.
    branch : str, optional
        The branch to draw (default: as docs/plots.md says per kind).
    stability : str, optional
        The reading that draws curves solid (stable) or dashed (post.plotting.Reading); None: each run's
        loading control.
    width : float, optional
        A new figure's width in inches (3.5 one journal column, 7.2 two): laid out at it, its legend under the
        panels, its titles and labels fitted (not with ``ax``: your figure has its size).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    PlotError
        A figure that cannot be drawn from the given sources (missing branch, data or point, bad ``ax``).

    Examples
    --------
    >>> fig = bc.plot(result, "pressure-pole", width=3.5)
    >>> fig.savefig("pressure-pole.pdf")
    """
    from ..post.plotting import plot as draw

    sources = source if isinstance(source, (list, tuple)) else [source]
    tube = _tube_run(sources, ax)
    if tube is not None:
        from ..post.tube_plots import tube_figure
        return tube_figure(tube, what or "pressure-volume", stability, branch, points, width or 3.5)
    return draw([_drawable(s) for s in sources], what, points, branch, axes=ax, stability=stability, width=width)


def _tube_run(sources: list, ax) -> dict | None:
    """The run of a tube source of ``plot`` (a TubeResult or a tube run file's path: post.tube_plots draws it, alone
    and on a Figure of its own; PlotError otherwise), None where no source is a tube's."""
    from ..io.tube_file import read_tube_run
    from ..post.plotting import PlotError
    from .tube_result import TubeResult

    tubes = [s for s in sources if isinstance(s, TubeResult)
             or isinstance(s, (str, Path)) and Path(s).is_file() and file_kind(s) == "tube"]
    if not tubes:
        return None
    if len(sources) > 1:
        raise PlotError(f"plot draws a tube run alone; got {len(sources)} sources")
    if ax is not None:
        raise PlotError("ax: a tube run's figure is drawn on a Figure of its own (set its size with width)")
    return tubes[0].run if isinstance(tubes[0], TubeResult) else read_tube_run(tubes[0])


def _drawable(source):
    """What ``post.plotting.plot`` draws for one source of ``plot``: a Result's run, a loaded sweep's or curve's
    file (``load``), a path; PlotError (one line) for anything else."""
    from ..post.plotting import PlotError
    from .curve_result import CurveResult
    from .sweep_result import SweepResult

    if isinstance(source, Result):
        return source.run
    if isinstance(source, (SweepResult, CurveResult)):
        return Path(source.path)
    if isinstance(source, (str, Path)):
        return source
    raise PlotError(f"plot draws a Result, a loaded sweep or curve (bc.load) or the path of a balloon-cg file; "
                    f"got {type(source).__name__}")
