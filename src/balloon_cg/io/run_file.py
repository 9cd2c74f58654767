"""Run files (HDF5, format "balloon-cg/1"): traced branches with their provenance.

Layout::

    /                      attrs: format, scene_name, scene_toml, package_version, generated_digest,
                                  tolerance, created (UTC ISO 8601), command, + extra_attrs
    /branches/<name>/      attrs: stop_reason, wall_time, degree, symmetric, pin_translation,
                                  kernel_class, kernel_signature, M, chi
        pressure, lam2_north, lam2_south, eta_north, eta_south,
        lam1_equator, lam2_equator, converged, residual, error_estimate,
        newton_iterations, solved_degree                   (n_points,)
        unknowns                                           (n_points, n + 1): Legendre unknowns u, then P
        theta                                              (n_theta,): linspace(0, π)
        profiles/lam1, profiles/lam2, profiles/rho, profiles/eta     (n_points, n_theta)
        special_points/kind, index, note, pressure, lam2_north, lam2_south, eta_north, eta_south   (n_special,)
        special_points/unknowns                            (n_special, n + 1)

A fold (LP, TP) lies between points ``index`` and ``index + 1``; its own X is in special_points/unknowns.
Files are written atomically (temporary file in the same directory, then os.replace).
"""
import datetime
import errno
import os
import secrets
import shlex
import sys
from pathlib import Path

import h5py
import numpy as np

import balloon_cg

from ..model.kernels import generated_digest
from ..galerkin.profiles import equator_values, profiles, theta_grid

FORMAT = "balloon-cg/1"
POLES = ("lam2_north", "lam2_south", "eta_north", "eta_south")
SPECIAL_NUMBERS = ("pressure", "E2", "E3", "E4") + POLES


class RunFileError(ValueError):
    """A file that is not a readable balloon-cg run file."""


def write_run(path, scene, branches, force: bool = False, extra_attrs: dict | None = None,
              snaps: list | None = None) -> Path:
    """Write the branches traced for ``scene`` to ``path`` atomically; returns the path.

    An existing file is kept unless ``force`` (FileExistsError); on any failure the existing file is
    untouched and the temporary file removed. ``extra_attrs`` are added to (or override, except ``format``)
    the root attributes. Raises ValueError if a branch holds a point that is not a converged solution.
    """
    path = check_output(path, force)
    names = [b.name for b in branches]
    if len(set(names)) != len(names):
        raise ValueError(f"branch names must be distinct, got {names}")
    for branch in branches:
        _check_converged(branch)
    attrs = _root_attrs(scene) | dict(extra_attrs or {})
    if attrs["format"] != FORMAT:
        raise ValueError(f"extra_attrs may not change format (= {FORMAT!r})")
    tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp"
    try:
        with h5py.File(tmp, "x") as f:
            f.attrs.update(attrs)
            group = f.create_group("branches")
            for order, branch in enumerate(branches):
                _write_branch(group.create_group(branch.name), branch, theta_grid(scene.output.theta_points))
                group[branch.name].attrs["order"] = order
            if snaps is not None:
                _write_snaps(f.create_group("snap_throughs"), snaps)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def check_output(path, force: bool) -> Path:
    """``path`` as a Path, if a run file may be written there (else FileExistsError, FileNotFoundError, …)."""
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    if not path.parent.is_dir():
        raise FileNotFoundError(errno.ENOENT, "no such directory", str(path.parent))
    if path.exists() and not force:
        raise FileExistsError(errno.EEXIST, "already exists (use --force to overwrite it)", str(path))
    return path


def converged(branch) -> np.ndarray:
    """Per point: Newton converged (the branch's flag), with finite unknowns and residual."""
    return branch.converged & np.isfinite(branch.X).all(axis=1) & np.isfinite(branch.residual)


def _check_converged(branch):
    bad = np.flatnonzero(~converged(branch))
    if bad.size:
        raise ValueError(f"branch {branch.name!r}: points {bad.tolist()} are not converged solutions; not written")


def _root_attrs(scene) -> dict:
    return {
        "format": FORMAT,
        "scene_name": scene.name,
        "scene_toml": scene.text,
        "package_version": balloon_cg.__version__,
        "generated_digest": generated_digest(),
        "tolerance": scene.solver.tol,
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": shlex.join(sys.argv),
    }


def _write_branch(group, branch, theta):
    disc, kernels = branch.disc, branch.equilibrium.kernels
    group.attrs.update({
        "stop_reason": branch.stop_reason,
        "wall_time": branch.wall_time,
        "degree": disc.degree,
        "symmetric": disc.symmetric,
        "pin_translation": disc.pin_translation,
        "quadrature": disc.quadrature,
        "map_centres": np.array(disc.mapping.centres if disc.mapping else [], dtype=float),
        "map_widths": np.array(disc.mapping.widths if disc.mapping else [], dtype=float),
        "kernel_class": kernels.name,
        "kernel_signature": kernels.signature,
        "M": branch.params.M,
        "chi": branch.params.chi,
    })
    columns = {
        "pressure": branch.pressure,
        **branch.pole_values(),
        **equator_values(branch),
        "converged": converged(branch),
        "residual": branch.residual,
        "error_estimate": branch.error_estimate,
        "newton_iterations": branch.iterations,
        "solved_degree": branch.degree,
        "unknowns": branch.X,
        "theta": theta,
    }
    for name, data in columns.items():
        group.create_dataset(name, data=data)
    shapes = group.create_group("profiles")
    for name, data in profiles(branch, theta).items():
        shapes.create_dataset(name, data=data, compression="gzip", shuffle=True)
    _write_special(group.create_group("special_points"), branch)
    if getattr(branch, "stability", None):
        _write_stability(group.create_group("stability"), branch)
    if getattr(branch, "parent", None):
        group.attrs["parent_branch"], group.attrs["parent_branch_point"] = branch.parent


STABILITY_FLAGS = {
    "stable_pressure": "held at the centre (axial translation excluded), pressure control",
    "stable_volume": "held at the centre, volume control (volume-preserving perturbations)",
    "stable_pressure_free": "free balloon (axial translation included), pressure control",
    "stable_volume_free": "free balloon, volume control",
}


def _write_stability(group, branch):
    """Flags per point (what each means is in the dataset's 'meaning' attribute) and lowest eigenvalues."""
    results = branch.stability
    for name, meaning in STABILITY_FLAGS.items():
        group.create_dataset(name, data=np.array([getattr(a, name) for a in results], dtype=bool))
        group[name].attrs["meaning"] = meaning
    for block in results[0].blocks:
        values = np.array([a.blocks[block] for a in results])
        group.create_dataset(f"lowest_{block}", data=values)
    group.attrs["unsettled_points"] = np.asarray(getattr(branch, "unsettled", []), dtype=np.int64)


def _write_snaps(group, snaps):
    """Snap-throughs under pressure control: from (branch, index) at pressure P to (branch, index) or none."""
    text = h5py.string_dtype()
    for key in ("from_branch", "to_branch"):
        group.create_dataset(key, data=np.array([s[key] for s in snaps], dtype=object), dtype=text)
    for key in ("from_index", "to_index"):
        group.create_dataset(key, data=np.array([s[key] for s in snaps], dtype=np.int64))
    group.create_dataset("pressure", data=np.array([s["pressure"] for s in snaps], dtype=float))


def _write_special(group, branch):
    special = branch.special
    X = np.array([s.X for s in special]).reshape(len(special), branch.X.shape[1])
    text = h5py.string_dtype()
    group.create_dataset("kind", data=np.array([s.kind for s in special], dtype=object), dtype=text)
    group.create_dataset("index", data=np.array([s.index for s in special], dtype=np.int64))
    group.create_dataset("note", data=np.array([s.note for s in special], dtype=object), dtype=text)
    group.create_dataset("pressure", data=X[:, -1])
    for n, name in enumerate(("E2", "E3", "E4")):
        group.create_dataset(name, data=np.array([s.E[n] for s in special], dtype=float))
    for name, values in branch.pole_values(X).items():
        group.create_dataset(name, data=values)
    group.create_dataset("unknowns", data=X)


def read_run(path) -> dict:
    """Summary of a run file: {'path', 'scene_name', 'attrs', 'branches': {name: branch}}.

    Each branch is a dict of its attrs ('attrs'), its per-point arrays and 'theta', 'profiles' (dict of
    arrays), 'special_points' (list of dicts: kind, index, note, pressure, pole values) and 'special_unknowns'
    (their X rows).
    Raises FileNotFoundError, IsADirectoryError, or RunFileError for a file that is not a balloon-cg/1 run file.
    """
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    if not path.exists():
        raise FileNotFoundError(errno.ENOENT, "no such file", str(path))
    try:
        f = h5py.File(path, "r")
    except OSError:
        raise RunFileError(f"{path}: not a readable HDF5 file") from None
    with f:
        fmt = f.attrs.get("format")
        if fmt != FORMAT:
            found = "no format attribute" if fmt is None else f"format {fmt!r}"
            raise RunFileError(f"{path}: not a balloon-cg run file ({found}, expected {FORMAT!r})")
        try:
            attrs = {k: _plain(v) for k, v in f.attrs.items()}
            return {
                "path": str(path),
                "scene_name": attrs["scene_name"],
                "attrs": attrs,
                "branches": {name: _read_branch(f["branches"][name]) for name in _branch_order(f["branches"])},
                "snap_throughs": _read_snaps(f.get("snap_throughs")),
            }
        except KeyError as e:
            raise RunFileError(f"{path}: damaged balloon-cg run file (missing {e})") from None


def _read_branch(group) -> dict:
    data = {name: group[name][()] for name, item in group.items() if isinstance(item, h5py.Dataset)}
    data["attrs"] = {k: _plain(v) for k, v in group.attrs.items()}
    data["profiles"] = {name: item[()] for name, item in group["profiles"].items()}
    sp = group["special_points"]
    columns = {
        "kind": sp["kind"].asstr()[()],
        "index": sp["index"][()],
        "note": sp["note"].asstr()[()],
        **{name: sp[name][()] for name in SPECIAL_NUMBERS},
    }
    data["special_points"] = [{k: _plain(v[i]) for k, v in columns.items()} for i in range(sp["kind"].shape[0])]
    data["special_unknowns"] = sp["unknowns"][()]
    if "stability" in group:
        data["stability"] = {name: item[()] for name, item in group["stability"].items()}
    return data


def _branch_order(group) -> list:
    """Branch names in the order they were written (the primary branch first)."""
    return sorted(group, key=lambda name: group[name].attrs.get("order", 0))


def _read_snaps(group) -> list:
    if group is None:
        return []
    columns = {k: (group[k].asstr()[()] if k.endswith("branch") else group[k][()]) for k in group}
    n = len(columns.get("pressure", []))
    return [{k: _plain(v[i]) for k, v in columns.items()} for i in range(n)]


def _plain(value):
    """numpy scalars as Python numbers/bools, for printing and JSON."""
    return value.item() if isinstance(value, np.generic) else value
