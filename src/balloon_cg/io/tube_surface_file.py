"""A tube's or a capsule's non-axisymmetric branches in its run file (analysis/surface/meridian/trace.py; docs/hdf5.md
"Tube run files", "Run files"): /surface_branches/<name>/ with the attributes ``m``, ``orders``, ``n_phi``, ``degree``
(the final basis: tube/surface/basis.py, a capsule's analysis/surface/meridian/capsule.py, refined along the branch
from the parent's discretisation; a capsule's also ``mode_degree``, its perturbation bases' degree, and ``equator``,
whether it keeps the states even in z), ``parent_branch``, ``parent_zero`` (the zero's order among the parent's
located zeros of block m, as ``inspect`` lists them; a capsule's: its number among the parent's branch points, as
in its name m<m>_bp<k>), ``stop_code``,
``stop_message``, ``limited`` (the basis reached its cap with estimates above solver.max_error; absent before it),
``image_of`` (only on a branch that is the image of another under the rotation by π/m about the axis:
analysis/surface/meridian/rotation.py; its name);
per point ``coefficients`` (n, size: c of the basis), ``pressure``, ``volume`` (V/V0), ``amplitude`` (φᵀ G c_m),
``reaction`` (the held centroid's τ), ``error_estimate``, ``lowest`` (n, 3: the mirror sector's lowest eigenvalues
under pressure control) and ``unstable_pressure``, ``unstable_volume``, ``unstable_gas``; its folds in P:
``fold_index``, ``fold_pressure``; its UZ points (``[[events]]``; absent without them): ``event_index``,
``event_pressure``, ``event_volume`` (V/V0), ``event_located``, ``event_coefficients`` (events, size) and the
attribute ``event_notes``.
Files before them have no /surface_branches (read as {})."""
import numpy as np

from .hdf5 import checksummed, plain
from ..scene.loading import Control
from ..scene.tables import Shape

GROUP = "surface_branches"
POINT_COLUMNS = ("pressure", "volume", "amplitude", "reaction", "error_estimate")
SURFACE_VARIABLES = {  # (units, long_name, description) of each dataset, as io/schema.py's VARIABLES
    "point": ("", "point index", "index of the point along the branch, in continuation order (0: the zero)"),
    "coefficient": ("", "coefficient index", "order 0's unknowns u, then (R, T, Z) per order m ≥ 1 (docs/hdf5.md)"),
    "eigenvalue": ("", "eigenvalue index", "0: the lowest eigenvalue of the mirror sector, 1: the next, …"),
    "fold": ("", "fold index", "index of the located fold in P along the branch"),
    "coefficients": ("1", "surface coefficients c", "c of the branch's final basis (docs/hdf5.md)"),
    "pressure": ("1", "pressure P", "P = P̄ R0 / (T0 μ/2)"),
    "volume": ("1", "volume ratio V/V0", "the enclosed volume over the reference one"),
    "amplitude": ("1", "amplitude", "φᵀ G c_m along the zero's critical mode"),
    "reaction": ("1", "gauge reaction τ", "the first held zero mode's multiplier (0 at an equilibrium)"),
    "error_estimate": ("1", "discretisation error estimate", "the shape's resolution policy's estimate (docs/hdf5.md)"),
    "lowest": ("1", "lowest eigenvalues", "the mirror sector's lowest eigenvalues under pressure control"),
    **{f"unstable_{c.value}": ("", f"unstable directions, {c.value} control", "negative eigenvalues of the mirror "
                               "sector") for c in Control},
    "fold_index": ("", "fold after point", "the fold in P lies between points fold_index and fold_index + 1"),
    "fold_pressure": ("1", "fold pressure P", "P at the located fold"),
    "event": ("", "event index", "index of the UZ point ([[events]]) along the branch"),
    "event_index": ("", "event after point", "the UZ point lies between points event_index and event_index + 1"),
    "event_pressure": ("1", "event pressure P", "P at the UZ point"),
    "event_volume": ("1", "event volume ratio V/V0", "V/V0 at the UZ point"),
    "event_located": ("", "event located", "1: Newton landed on the value; 0: the linear interpolant"),
    "event_coefficients": ("1", "event surface coefficients c", "c of the UZ point on the branch's final basis"),
}


def write_surface_branches(f, branches: dict | None) -> None:
    """``branches`` (name -> MeridianSurfaceBranch) under ``f``/surface_branches; nothing where None or empty."""
    for name, branch in (branches or {}).items():
        group = f.create_group(f"{GROUP}/{name}")
        basis = branch.basis
        group.attrs.update({"m": branch.m, "orders": np.array(basis.orders, dtype=int), "n_phi": basis.n_phi,
                            "degree": basis.disc.degree, "parent_branch": branch.parent[0],
                            "parent_zero": branch.parent[1], "stop_code": branch.stop.code.value,
                            "stop_message": branch.stop.message, "limited": branch.limited})
        if branch.image_of:
            group.attrs["image_of"] = branch.image_of
        if basis.shape == Shape.CAPSULE:
            group.attrs.update({"mode_degree": basis.mode_degree, "equator": basis.equator})
        checksummed(group, "coefficients", branch.coefficients)
        for column in POINT_COLUMNS:
            checksummed(group, column, getattr(branch, column))
        checksummed(group, "lowest", branch.lowest)
        for control in Control:
            checksummed(group, f"unstable_{control.value}", branch.unstable[control])
        checksummed(group, "fold_index", np.array([i for i, _ in branch.folds], dtype=int))
        checksummed(group, "fold_pressure", np.array([p for _, p in branch.folds], dtype=float))
        if branch.events:  # the UZ points: absent without [[events]] (and in files before them)
            for column, kind in (("index", int), ("pressure", float), ("volume", float), ("located", int)):
                checksummed(group, f"event_{column}", np.array([getattr(e, column) for e in branch.events], dtype=kind))
            checksummed(group, "event_coefficients", np.array([e.coefficients for e in branch.events]))
            group.attrs["event_notes"] = [e.note for e in branch.events]
        _described(group, branch)


def _described(group, branch) -> None:
    """Every dataset of ``group`` described (SURFACE_VARIABLES) and attached to its dimension scales (netCDF-4: the
    group opens alone in xarray): ``point`` (``fold`` for the folds), and ``coefficient`` or ``eigenvalue``."""
    items = list(group.items())
    scales = {}
    for name, length in (("point", len(branch.pressure)), ("coefficient", branch.coefficients.shape[1]),
                         ("eigenvalue", branch.lowest.shape[1]), ("fold", len(branch.folds)),
                         *((("event", len(branch.events)),) if branch.events else ())):
        scales[name] = checksummed(group, name, np.arange(length, dtype=np.int64))
        scales[name].make_scale(name)
        _describe(scales[name], name)
    for name, item in items:
        item.dims[0].attach_scale(scales["fold" if name.startswith("fold_") else "event" if name.startswith("event_")
                                         else "point"])
        if item.ndim == 2:
            item.dims[1].attach_scale(scales["coefficient" if name.endswith("coefficients") else "eigenvalue"])
        _describe(item, name)


def _describe(dataset, name: str) -> None:
    units, long_name, description = SURFACE_VARIABLES[name]
    dataset.attrs.update(({"units": units} if units else {}) | {"long_name": long_name, "description": description})


def read_surface_branches(f, path, error) -> dict:
    """{name: {'attrs', 'coefficients', the point columns, 'lowest', 'unstable_<control>', 'folds': [(index, P)]}}
    of ``f``/surface_branches ({} without it); ``error`` (TubeFileError) naming a missing or misshapen dataset."""
    out = {}
    for name, group in f.get(GROUP, {}).items():
        columns = ("coefficients", *POINT_COLUMNS, "lowest", *(f"unstable_{c.value}" for c in Control),
                   "fold_index", "fold_pressure")
        missing = [c for c in columns if c not in group]
        if missing:
            raise error(path, f"/{GROUP}/{name}: missing {', '.join(missing)}")
        branch = {"attrs": {k: v.tolist() if isinstance(v, np.ndarray) else plain(v) for k, v in group.attrs.items()}}
        branch |= {c: group[c][()] for c in columns}
        n = branch["coefficients"].shape[0]
        for column in columns[1:-2]:
            if branch[column].shape[0] != n:
                raise error(path, f"/{GROUP}/{name}/{column}: {branch[column].shape[0]} rows, expected {n}")
        branch["folds"] = list(zip(branch.pop("fold_index").tolist(), branch.pop("fold_pressure").tolist()))
        branch["events"] = _events(group, branch["attrs"])
        out[name] = branch
    return out


def _events(group, attrs: dict) -> list:
    """[{'after_point', 'pressure', 'volume', 'note', 'located', 'coefficients'}] of a branch's UZ points ([] without
    them)."""
    if "event_index" not in group:
        return []
    columns = [group[f"event_{c}"][()].tolist() for c in ("index", "pressure", "volume", "located")]
    return [{"after_point": i, "pressure": P, "volume": V, "note": note, "located": bool(located), "coefficients": c}
            for i, P, V, located, note, c in zip(*columns, attrs.pop("event_notes"), group["event_coefficients"][()])]
