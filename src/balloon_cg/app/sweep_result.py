"""A sweep file in Python (``balloon_cg.load(sweep)``): its members and one table of what each found.

``SweepResult.to_dataframe()`` has one row per member (index ``member``): the varied scene keys (dotted, as
the members' overrides name them), ``complete``, the primary branch's fold (``P_LP``, ``lam2_LP``: its first LP),
the critical pressures of the pear-shaped instability (``P_cr1`` ≥ ``P_cr2``: the branch points of the odd held
block, as in the paper) and every branch point of the primary branch in stored order (``P_BP1``, ``block_BP1``,
``classification_BP1``, ``m_BP1``, …); NaN where a member has none (a primary-only sweep has no branch
points). ``to_xarray()`` is the same table as an xarray Dataset along ``member``. Members are
``SweepMember`` s: overrides, attributes and branches (``BranchData``), each group of the file readable with
xarray (``to_xarray``).
"""
from dataclasses import dataclass
from pathlib import Path


from ..io.parents import parent_label
from ..io.sweep_file import member_row, read_sweep
from ..io.tube_file import tube_row
from .api import BranchData
from .tables import html_table, optional

@dataclass(frozen=True, repr=False)
class SweepMember:
    """One member of a sweep: ``index``, its ``overrides`` (dotted key -> value), ``attrs`` (verdict,
    provenance), ``branches`` (name -> BranchData; a tube's: io.tube_file.read_tube's branch dicts) and ``path``, the
    sweep file."""

    index: int
    overrides: dict
    attrs: dict
    branches: dict
    path: str

    @property
    def complete(self) -> bool:
        return bool(self.attrs.get("complete", False))

    def to_xarray(self, branch: str = "primary", group: str = ""):
        """The xarray Dataset of one stored group of a branch (``group``: '', 'profiles', 'stability',
        'special_points'), with its named dimensions and units."""
        optional("h5netcdf", "to_xarray")
        xr = optional("xarray", "to_xarray")
        if branch not in self.branches:
            raise KeyError(f"member {self.index}: no branch {branch!r} (branches: {', '.join(self.branches)})")
        where = "/".join(filter(None, ("members", str(self.index), "branches", branch, group)))
        with xr.open_dataset(self.path, engine="h5netcdf", group=where) as ds:
            return ds.load()

    def row(self) -> dict:
        """This member's line of ``SweepResult.to_dataframe`` (``io.sweep_file.member_row``, as the file's root
        table; a tube's: ``io.tube_file.tube_row``)."""
        if self.attrs.get("shape") == "tube":
            return self.overrides | {"complete": self.complete} | tube_row({"attrs": self.attrs,
                                                                            "branches": self.branches})
        primary = self.branches.get("primary")
        return member_row(self.overrides, self.complete, primary.special_points if primary is not None else [])

    def __repr__(self):
        state = "complete" if self.complete else "incomplete"
        return f"SweepMember({self.index}, {self.overrides}, {len(self.branches)} branches, {state})"


@dataclass(frozen=True, repr=False)
class SweepResult:
    """A loaded sweep file (``load(sweep)``): ``path``, ``attrs`` (root attributes: scene, vary, mode) and
    ``members`` (index -> SweepMember: overrides, attrs, branches as BranchData, ``to_xarray`` of a stored group).
    A notebook shows it as the table of ``to_dataframe``.

    Examples
    --------
    >>> sweep = bc.load("sweep.h5")
    >>> sweep.to_dataframe()[["field.M", "P_LP", "P_cr1", "P_cr2"]]
    >>> sweep.members[0].branches["primary"].special_points
    """

    path: str
    attrs: dict
    members: dict

    @classmethod
    def read(cls, path) -> "SweepResult":
        sweep = read_sweep(path)
        members = {index: SweepMember(index, m["overrides"], m["attrs"],
                                      m["branches"] if m["attrs"].get("shape") == "tube" else
                                      {name: BranchData(name, data, parent_label(m, name))
                                       for name, data in m["branches"].items()},
                                      str(path))
                   for index, m in sweep["members"].items()}
        return cls(str(path), sweep["attrs"], members)

    def to_dataframe(self):
        """What each member found, one row per member.

        Returns
        -------
        pandas.DataFrame
            Index ``member``; the varied keys (dotted, as the overrides name them), ``complete``, the primary
            branch's first fold ``P_LP``, ``lam2_LP``, the critical pressures of the pear-shaped instability
            ``P_cr1`` ≥ ``P_cr2``, and every branch point of the primary branch in stored order (``P_BP1``,
            ``block_BP1``, ``classification_BP1``, ``m_BP1``, …); NaN where a member has none.
        """
        pd = optional("pandas", "to_dataframe")
        return pd.DataFrame([m.row() for m in self.members.values()],
                            index=pd.Index(list(self.members), name="member"))

    def to_xarray(self):
        """``to_dataframe`` as an xarray Dataset.

        Returns
        -------
        xarray.Dataset
            The same columns along the dimension ``member``.
        """
        optional("xarray", "to_xarray")
        return self.to_dataframe().to_xarray()

    def __repr__(self):
        done = sum(m.complete for m in self.members.values())
        return (f"SweepResult({Path(self.path).name!r}: {self.attrs.get('scene_name')}, {len(self.members)} of "
                f"{self.attrs.get('members')} members ({done} complete), mode {self.attrs.get('mode')})")

    def _repr_html_(self):
        """The table of ``to_dataframe``, a row per member."""
        return html_table([{"member": index} | m.row() for index, m in self.members.items()], repr(self))
