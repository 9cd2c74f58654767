"""A tube's non-axisymmetric branches in its run file (tube/surface/branch.py; docs/hdf5.md "Tube run files"):
/surface_branches/<name>/ with the attributes ``m``, ``orders``, ``n_phi``, ``degree`` (the final basis: tube/
surface/basis.py, refined along the branch from the parent's discretisation), ``parent_branch``, ``parent_zero`` (the
zero's order among the parent's located zeros of block m, as ``inspect`` lists them), ``stop_code``,
``stop_message``, ``limited`` (the basis reached its cap with estimates above solver.max_error; absent before it);
per point ``coefficients`` (n, size: c of the basis), ``pressure``, ``volume`` (V/V0), ``amplitude`` (φᵀ G c_m),
``reaction`` (the held centroid's τ), ``error_estimate``, ``lowest`` (n, 3: the mirror sector's lowest eigenvalues
under pressure control) and ``unstable_pressure``, ``unstable_volume``, ``unstable_gas``; its folds in P:
``fold_index``, ``fold_pressure``.
Files before them have no /surface_branches (read as {})."""
import numpy as np

from .hdf5 import checksummed, plain
from ..scene.loading import Control

GROUP = "surface_branches"
POINT_COLUMNS = ("pressure", "volume", "amplitude", "reaction", "error_estimate")


def write_surface_branches(f, branches: dict | None) -> None:
    """``branches`` (name -> MeridianSurfaceBranch) under ``f``/surface_branches; nothing where None or empty."""
    for name, branch in (branches or {}).items():
        group = f.create_group(f"{GROUP}/{name}")
        basis = branch.basis
        group.attrs.update({"m": branch.m, "orders": np.array(basis.orders, dtype=int), "n_phi": basis.n_phi,
                            "degree": basis.disc.degree, "parent_branch": branch.parent[0],
                            "parent_zero": branch.parent[1], "stop_code": branch.stop.code.value,
                            "stop_message": branch.stop.message, "limited": branch.limited})
        checksummed(group, "coefficients", branch.coefficients)
        for column in POINT_COLUMNS:
            checksummed(group, column, getattr(branch, column))
        checksummed(group, "lowest", branch.lowest)
        for control in Control:
            checksummed(group, f"unstable_{control.value}", branch.unstable[control])
        checksummed(group, "fold_index", np.array([i for i, _ in branch.folds], dtype=int))
        checksummed(group, "fold_pressure", np.array([p for _, p in branch.folds], dtype=float))


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
        out[name] = branch
    return out
