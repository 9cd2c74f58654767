"""A tube run file in Python (``balloon_cg.load(tube)``, io/tube_file.py): its branches and the onset curve of
``critical`` as tables (``to_dataframe``) and as xarray Datasets (``to_xarray``), the shape and its parameters,
Maxwell's pressure and the stage a signal stopped (``interrupted``)."""
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..io.tube_file import ACCURACY, CREST, CURVE_COLUMNS, HOOP, POINT_COLUMNS, VOLTAGE, read_tube_run
from .tables import html_table, optional

PARTS = ("points", "special")
SPECIAL_COLUMNS = ("kind", "block", "status", "note", "index", "pressure", VOLTAGE, "volume", "smallest_stress", CREST)


@dataclass(frozen=True, repr=False)
class TubeResult:
    """A loaded tube run file: ``path`` and ``run`` (io.tube_file.read_tube_run's dict).

    Examples
    --------
    >>> tube = bc.load("tube.h5")
    >>> tube.to_dataframe().groupby("branch").pressure.max(), tube.maxwell_pressure
    >>> tube.to_xarray("bulge").volume.plot()
    """

    path: str
    run: dict

    @classmethod
    def read(cls, path) -> "TubeResult":
        """A tube run file, read and checked.

        Parameters
        ----------
        path : str or Path
            A tube run file (format ``balloon-cg-tube/1``).

        Returns
        -------
        TubeResult

        Raises
        ------
        FileError
            Not a readable tube run file (io.tube_file.TubeFileError, one line naming the file and what is wrong).
        """
        return cls(str(path), read_tube_run(path))

    @property
    def geometry(self) -> dict:
        """The reference tube: shape, length, ends, axial_stretch (None: closed ends, the distance free)."""
        a = self.run["attrs"]
        held = None if math.isnan(a["axial_stretch"]) else float(a["axial_stretch"])
        return {"shape": a["shape"], "length": float(a["length"]), "ends": a["ends"], "axial_stretch": held}

    @property
    def maxwell_pressure(self) -> float | None:
        """Maxwell's pressure of the uniform closed tube (None: none, the ends held, or coils acting)."""
        p = self.run["attrs"]["maxwell_pressure"]
        return None if math.isnan(p) else float(p)

    @property
    def interrupted(self) -> str | None:
        """The stage a signal stopped (``primary``, ``bulge``, ``onset``), None where the work is whole."""
        return self.run["attrs"]["interrupted"] or None

    def to_dataframe(self, table: str = "points"):
        """The file as one tidy table.

        Parameters
        ----------
        table : str, optional
            ``"points"`` (default): one row per point of every branch (branch, point, the per-point columns);
            ``"special"``: one row per located point (branch, kind, block, status, note: a UZ point's event, index,
            pressure, voltage on a voltage continuation, volume, smallest_stress, crest_height); ``"onset"``: one
            row per point of the onset curve of ``critical`` (the parameter under its own name, pressure, volume,
            crest_height, hoop_stretch: the onset's largest radius).

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ValueError
            Another ``table``.
        KeyError
            ``"onset"`` of a file without an onset curve.
        """
        pd = optional("pandas", "to_dataframe")
        if table == "onset":
            return pd.DataFrame(self._onset_columns()).rename_axis("point")
        if table not in PARTS:
            raise ValueError(f"table = {table!r}: must be 'points', 'special' or 'onset'")
        frames = [pd.DataFrame({"branch": name, **(self._points(b) if table == "points" else self._special(b))})
                  .rename_axis("point").reset_index() for name, b in self.run["branches"].items()]
        frame = pd.concat(frames, ignore_index=True)
        return frame if table == "points" else frame.drop(columns="point")

    def to_xarray(self, branch: str = "primary", part: str = "points"):
        """A branch, or the onset curve, as an xarray Dataset; the shape's parameters, Maxwell's pressure, the stop
        and the interruption are attributes.

        Parameters
        ----------
        branch : str, optional
            The branch's name (default ``"primary"``), or ``"onset"``: the onset curve of ``critical`` (dims point,
            unknown, mode; ``part`` is not read).
        part : str, optional
            ``"points"`` (default): dims point, unknown (the per-point columns and ``unknowns``, u of
            galerkin/interval.py), or ``"special"``: the located points, dims special, unknown.

        Returns
        -------
        xarray.Dataset
            Its attributes: the shape's parameters, Maxwell's pressure, the branch's stop, ``interrupted``.

        Raises
        ------
        KeyError
            No branch of that name (``"onset"``: no onset curve in the file).
        ValueError
            Another ``part``.
        """
        xr = optional("xarray", "to_xarray")
        attrs = {k: ("" if v is None else v) for k, v in self.geometry.items()}
        attrs |= {"maxwell_pressure": self.run["attrs"]["maxwell_pressure"],
                  "interrupted": self.run["attrs"]["interrupted"], "degree": int(self.run["attrs"]["degree"])}
        if branch == "onset":
            onset = self._onset()
            data = {k: ("point", v) for k, v in self._onset_columns().items()}
            data |= {"unknowns": (("point", "unknown"), onset["unknowns"]),
                     "modes": (("point", "mode"), onset["modes"])}
            return xr.Dataset(data, attrs=attrs | onset["attrs"])
        if branch not in self.run["branches"]:
            raise KeyError(f"no branch {branch!r} (branches: {', '.join(self.run['branches'])}"
                           f"{', onset' if self.run['onset'] is not None else ''})")
        if part not in PARTS:
            raise ValueError(f"part = {part!r}: must be 'points' or 'special'")
        b = self.run["branches"][branch]
        attrs |= b["attrs"]
        if part == "points":
            data = {k: ("point", v) for k, v in self._points(b).items()}
            return xr.Dataset(data | {"unknowns": (("point", "unknown"), b["unknowns"])}, attrs=attrs)
        data = {k: ("special", np.asarray(v)) for k, v in self._special(b).items()}
        unknowns = b["special_unknowns"].reshape(len(b["special_points"]), b["unknowns"].shape[1])
        return xr.Dataset(data | {"unknowns": (("special", "unknown"), unknowns)}, attrs=attrs)

    @staticmethod
    def _points(b: dict) -> dict:
        return {c: b[c] for c in (*POINT_COLUMNS, CREST, VOLTAGE, *ACCURACY, "lowest_even", "lowest_odd") if c in b}

    @staticmethod
    def _special(b: dict) -> dict:
        columns = [c for c in SPECIAL_COLUMNS if all(c in s for s in b["special_points"])]
        return {c: [s[c] for s in b["special_points"]] for c in columns}

    def _onset(self) -> dict:
        if self.run["onset"] is None:
            raise KeyError(f"{Path(self.path).name} has no onset curve (written by `balloon-cg critical`)")
        return self.run["onset"]

    def _onset_columns(self) -> dict:
        onset = self._onset()
        return {onset["attrs"]["parameter"]: onset["q"]} | {c: onset[c] for c in (*CURVE_COLUMNS, HOOP) if c != "q"}

    def __repr__(self):
        g = self.geometry
        branches = ", ".join(f"{name} ({len(b['pressure'])} points, stop {b['attrs']['stop_code']})"
                             for name, b in self.run["branches"].items())
        onset = "" if self.run["onset"] is None else f", onset in {self.run['onset']['attrs']['parameter']}"
        stopped = "" if self.interrupted is None else f", interrupted in {self.interrupted}"
        return f"TubeResult({Path(self.path).name!r}: tube L = {g['length']:g}, {g['ends']} ends; {branches}" \
               f"{onset}{stopped})"

    def _repr_html_(self):
        return html_table([{"branch": name, "points": len(b["pressure"]), "stop": b["attrs"]["stop_code"],
                            "special points": len(b["special_points"])} for name, b in self.run["branches"].items()],
                          repr(self))
