"""Special points as one table, and the HTML tables a notebook shows for results (``_repr_html_``).

``SpecialPoints`` is the list of special points of a run or branch (a list of dicts, one per point, the stored
columns of docs/hdf5.md with ``branch``) that reads as a table: ``to_dataframe()`` one row per special point,
``to_xarray()`` the same along the dimension ``special`` with units and long names (io.schema), a repr of one line
and an HTML table in a notebook. ``html_table`` renders rows through pandas (the ``[analysis]`` extra); without
pandas a ``_repr_html_`` returns None, which IPython takes as "no HTML" and shows the one-line repr.
"""
import importlib
from collections import Counter

from ..io.schema import VARIABLES

EXTRA = "pip install 'balloon-cg[analysis]'"
ORDER = ("branch", "kind", "classification", "block", "m", "status", "index", "pressure", "voltage", "lam2_top",
         "lam2_bottom", "eta_top", "eta_bottom", "E2", "E3", "E4", "uncertainty", "reason", "stop_code", "note")
MAX_ROWS = 60  # an HTML table longer than this shows its head and tail (pandas' max_rows)


def optional(module: str, what: str):
    """The module, or ImportError naming what needs it and the extra that installs it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(f"{what} needs {module}, which is not installed: {EXTRA}") from None


def counted(n: int, noun: str, plural: str = "") -> str:
    """'1 point', '3 points' ('branch', 'branches': the plural given)."""
    return f"{n} {noun if n == 1 else plural or noun + 's'}"


def html_table(rows: list[dict], caption: str = "") -> str | None:
    """An HTML table of ``rows`` (dicts with the same keys) under ``caption``; None without pandas."""
    try:
        import pandas as pd
    except ImportError:
        return None
    from html import escape

    table = pd.DataFrame(rows).to_html(index=False, max_rows=MAX_ROWS, float_format="{:.6g}".format, na_rep="",
                                       border=0)
    return f"<p>{escape(caption)}</p>{table}" if caption else table


class SpecialPoints(list):
    """Special points, one dict per point, readable as one table (``Result.special_points``,
    ``BranchData.special_points``).

    The keys are docs/hdf5.md's special_points columns (kind, classification, block, m, status, index, pressure,
    the pole values, E2, E3, E4, …), and ``branch`` for the points of a whole run. A notebook shows the table.

    Examples
    --------
    >>> folds = result.special_points.to_dataframe().query("kind == 'LP'")
    >>> result.special_points.to_xarray().pressure
    """

    def columns(self) -> list[str]:
        """The keys of the points, in ORDER first."""
        keys = list(dict.fromkeys(k for point in self for k in point))
        return [k for k in ORDER if k in keys] + [k for k in keys if k not in ORDER]

    def to_dataframe(self):
        """The special points as a table.

        Returns
        -------
        pandas.DataFrame
            One row per special point (index ``special``): branch, kind, classification, block, m, status, index,
            pressure, the pole values, E2, E3, E4, uncertainty, reason, stop_code, note.
        """
        pd = optional("pandas", "to_dataframe")
        return pd.DataFrame(list(self), columns=self.columns()).rename_axis("special")

    def to_xarray(self):
        """The special points as an xarray Dataset.

        Returns
        -------
        xarray.Dataset
            The columns of ``to_dataframe`` along the dimension ``special``, with units and long names as in the
            files.
        """
        optional("xarray", "to_xarray")
        ds = self.to_dataframe().to_xarray()
        for name in ds.data_vars:
            if name in VARIABLES:
                units, long_name, description = VARIABLES[name]
                ds[name].attrs.update({"long_name": long_name, "description": description} |
                                      ({"units": units} if units else {}))
        return ds

    def kinds(self) -> str:
        """The kinds and how many of each, in order of first appearance ('2 EP, 1 LP, 3 BP')."""
        counts = Counter(point["kind"] for point in self)
        return ", ".join(f"{n} {kind}" for kind, n in counts.items())

    def __repr__(self):
        return f"SpecialPoints({counted(len(self), 'point')}{': ' + self.kinds() if self else ''})"

    def _repr_html_(self):
        return html_table([{k: point.get(k) for k in self.columns()} for point in self], repr(self))
