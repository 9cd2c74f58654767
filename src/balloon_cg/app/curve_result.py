"""A two-parameter curve file in Python (``balloon_cg.load(curve)``), named after the parameter it follows.

``CurveResult.parameter`` is q's name (M, alpha1, Jm, mu[0]: ``analysis.critical.second_parameter``); ``to_dataframe``
has one row per point of every curve in the file (columns ``curve``, the parameter under its own name, pressure,
the pole stretches, newton_iterations, residual); ``critical`` maps each curve to its critical value of the
parameter (NaN unless the curve ended in the merge of the two pitchforks).
"""
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from ..io.curve_file import read_curve
from ..io.layout import reading
from .tables import html_table, optional

COLUMNS = ("pressure", "lam2_top", "lam2_bottom", "newton_iterations", "residual")


@dataclass(frozen=True, repr=False)
class CurveResult:
    """A loaded two-parameter curve file (``load(curve)``): ``path``, ``parameter`` (the name of q: M, alpha1,
    Jm, mu[0], …) and ``curves`` (name -> read_curve dict).

    Examples
    --------
    >>> curve = bc.load("critical_M.h5")
    >>> curve.parameter, curve.critical
    >>> curve.to_dataframe().plot(x=curve.parameter, y="pressure")
    """

    path: str
    parameter: str
    curves: dict

    @classmethod
    def read(cls, path) -> "CurveResult":
        with h5py.File(path, "r") as f, reading(path):
            names = list(f["two_parameter"])
        curves = {name: read_curve(path, name) for name in names}
        parameters = {c["attrs"]["parameter"] for c in curves.values()}
        return cls(str(path), "/".join(sorted(parameters)), curves)

    @property
    def critical(self) -> dict:
        """The critical value of the parameter per curve: where its two pitchforks merge (NaN if they do not)."""
        return {name: float(c["attrs"]["critical_q"]) for name, c in self.curves.items()}

    def to_dataframe(self):
        """The curves as one table.

        Returns
        -------
        pandas.DataFrame
            One row per point of every curve: ``curve``, the parameter under its own name (``M``, ``alpha1``,
            …), pressure, lam2_top, lam2_bottom, newton_iterations, residual.
        """
        pd = optional("pandas", "to_dataframe")
        frames = [pd.DataFrame({"curve": name, c["attrs"]["parameter"]: c["q"]} | {k: c[k] for k in COLUMNS})
                  for name, c in self.curves.items()]
        return pd.concat(frames, ignore_index=True).rename_axis("point")

    def __repr__(self):
        curves = ", ".join(f"{name} ({len(c['q'])} points, critical {self.parameter} = {self.critical[name]:.6g})"
                           if np.isfinite(self.critical[name]) else f"{name} ({len(c['q'])} points)"
                           for name, c in self.curves.items())
        return f"CurveResult({Path(self.path).name!r} in {self.parameter}: {curves})"

    def _repr_html_(self):
        """A row per curve: its points, how it ended, the critical value of the parameter."""
        return html_table([{"curve": name, "points": len(c["q"]), "end": c["attrs"]["end"],
                            f"critical {self.parameter}": self.critical[name]} for name, c in self.curves.items()],
                          repr(self))
