"""Two-parameter curve files: a run file (same root attributes, empty /branches) with /two_parameter.

Layout::

    /                            attrs: as a run file (format, scene, provenance) + extra_attrs
    /branches/                   (empty: the file is also a readable run file)
    /two_parameter/<name>/       attrs: of, parameter, parameter_key, parameter_derivative, stop_reason, stop_code,
                                        end, end_description, q0, wall_time, degree, kernel_class, M, chi,
                                        critical_q (NaN unless end = isola_merge or cusp)
        <parameter>, pressure, lam2_top, lam2_bottom, newton_iterations, residual      (n_points,)
                        (<parameter>: q under its short name, alpha1, M, Jm, mu[0], with units and long_name;
                        files written before: q)
        unknowns (n_points, n + 1): u then P;  mode (n_points, m): φ on the odd perturbation block (BP), the
                                                   fold's tangent w = (v, μ) in the unknowns' layout (LP, LV, LN)
        special_points/ the run file's special-point columns (kind LP: the folds in q; status located only for
                        the verified merge of the two pitchforks or the verified cusp; kinds LP-BP, LV-BP, LN-BP:
                        the meetings of a fold and the pitchfork, analysis.critical.fold_meeting, or on a fold
                        curve the branch points it crosses, analysis.critical.fold_crossing), and <parameter>;
                        state/unknowns in the branch layout (u, P)

``of`` is what the curve follows: BP (pear pitchforks, group ``pear``; files without it), LP, LV or LN (a fold of
the primary branch in P, V or n, group named so: ``analysis.critical.fold_curve``). ``end`` is the curve's
``analysis.critical.pitchfork_curve.CurveEnd`` (how it ended: isola_merge, cusp (a fold curve's two folds merge), fold,
nonpositive_pressure, wire, budget, step_min, alpha1_zero, other, interrupted: a signal stopped it, the curve is
partial); ``end_description``
says the same for people, with where. ``parameter`` is q's short name (M, alpha1, Jm, mu[0]), ``parameter_key`` its
scene key (field.M, material.parameters.Jm, material.mu[0]; alpha1: itself), ``parameter_derivative`` how ∂R/∂q was
computed (exact: a generated kernel; central: central differences): ``analysis.critical.second_parameter``. Files written
before these two existed have ``parameter`` M or alpha1 and are read all the same.
"""
from dataclasses import replace

import h5py
import numpy as np

from ..analysis.results import Kind
from .hdf5 import atomic_file, checksummed, plain
from .layout import (FileError, carries_checksums, check_columns, check_sizes, opened, require_attrs,
                     require_group)
from .run_file import check_coordinates, check_special, legendre_poles, read_run, read_special, root_attrs, write_special
from .schema import attach_dimensions, describe_parameter, scale


def write_curve(path, scene, curve, name: str = "pear", force: bool = False, extra_attrs: dict | None = None):
    """Write a two-parameter curve (analysis.critical.pitchfork_curve.TwoParameterCurve) to ``path`` atomically."""
    attrs = root_attrs(scene) | {"title": f"balloon-cg two-parameter curve of scene {scene.name}"} | dict(
        extra_attrs or {})
    critical = curve.critical
    with atomic_file(path, force) as f:
        f.attrs.update(attrs)
        f.create_group("branches").attrs["snap_throughs"] = False  # a run file with no branches
        group = f.create_group("two_parameter").create_group(name)
        group.attrs.update({
            "parameter": curve.parameter,
            "of": curve.of.value,
            "parameter_key": curve.second.key,
            "parameter_derivative": curve.second.derivative.value,
            "stop_reason": curve.stop_reason,
            "stop_code": curve.stop.code.value if curve.stop else "",
            "end": curve.end.value if curve.end else "",
            "end_description": curve.describe() if curve.end else "",
            "q0": curve.q0,
            "wall_time": curve.wall_time,
            "degree": curve.disc.degree,
            "kernel_class": curve.system().eq.kernels.name,
            "M": curve.params.M,
            "chi": curve.params.chi,
            "critical_q": np.nan if critical is None else critical[0],
        })
        columns = {"pressure": curve.pressure, **curve.pole_values(),
                   "newton_iterations": curve.iterations, "residual": curve.residual,
                   "unknowns": curve.branch_X(), "mode": curve.mode}
        for key, data in columns.items():
            checksummed(group, key, data)
        point, unknown = scale(group, "point", len(curve.q)), scale(group, "unknown", columns["unknowns"].shape[1])
        attach_dimensions(group, {1: (point,), "unknowns": (point, unknown),
                                  "mode": (point, scale(group, "mode_unknown", columns["mode"].shape[1]))})
        parameter_coordinate(group, curve.parameter, curve.second.key, curve.q, point)
        points = sorted(curve.merges + curve.meetings, key=lambda s: (s.index, s.X[-1]))
        special = group.create_group("special_points")
        write_special(special, [replace(s, X=curve.branch_X(s.X)[0], parameter="P") for s in points], curve.n + 1,
                      lambda X: legendre_poles(curve.disc, X))
        parameter_coordinate(special, curve.parameter, curve.second.key, [s.X[-1] for s in points],
                             special["special"])
    return path


def parameter_coordinate(group, name: str, key: str, values, dimension) -> None:
    """q's values as the dataset ``name`` (its short name) along ``dimension``, described, and named a coordinate
    (CF ``coordinates``) of the group's other one-dimensional quantities along it (xarray: a coordinate)."""
    q = checksummed(group, name, np.asarray(values, dtype=float))
    q.dims[0].attach_scale(dimension)
    describe_parameter(q, key)
    for item in group.values():
        if isinstance(item, h5py.Dataset) and item.ndim == 1 and not item.is_scale and item.name != q.name \
                and item.dtype.kind == "f":
            item.attrs["coordinates"] = name


CURVE_COLUMNS = {**{name: ("float", 1) for name in ("q", "pressure", "lam2_top", "lam2_bottom", "residual")},
                 "newton_iterations": ("int", 1), "unknowns": ("float", 2), "mode": ("float", 2)}
CURVE_REQUIRED = {"parameter": "str", "stop_reason": "str", "end": "str", "q0": "float", "critical_q": "float",
                  "end_description": "str", "degree": "int", "wall_time": "float"}
CURVE_KINDS = CURVE_REQUIRED | {"parameter_key": "str", "parameter_derivative": "str", "of": "str"}


def read_curve(path, name: str = "pear") -> dict:
    """The datasets and attributes of a stored curve: {'attrs', datasets…, 'special_points': [dicts], 'q'}.
    Raises CurveFileError naming the file and what is missing (the file must also be a readable run file)."""
    read_run(path)  # the root attributes and /branches, checked
    with opened(path, CurveFileError) as f:
        curves = require_group(f, "two_parameter", path, CurveFileError)
        group = require_group(curves, name, f"{path}: two_parameter", CurveFileError)
        where = f"{path}: two_parameter/{name}"
        written = carries_checksums(f)  # a file of this version: every attribute it writes
        require_attrs(group.attrs, where, CURVE_KINDS if written else CURVE_REQUIRED, CURVE_KINDS, CurveFileError)
        coordinate = parameter_column(group)
        columns = {coordinate if k == "q" else k: kind for k, kind in CURVE_COLUMNS.items()}
        check_columns(group, where, columns, CurveFileError)
        check_sizes(group, where, CurveFileError)
        special = require_group(group, "special_points", where, CurveFileError)
        check_special(special, f"{where}: special_points", group["unknowns"].shape[1], CurveFileError,
                      {coordinate: ("float", 1)}, written=written)
        check_coordinates(group, where, CurveFileError)
        data = {key: item[()] for key, item in group.items() if isinstance(item, h5py.Dataset) and key != coordinate}
        data["q"] = group[coordinate][()]
        data["attrs"] = {k: plain(v) for k, v in group.attrs.items()}
        data["special_points"] = read_special(special)
        data["special_q"] = special[coordinate][()]
    for key, values in ((coordinate, data["q"]), ("pressure", data["pressure"]),
                        (f"special_points/{coordinate}", data["special_q"]),
                        ("special_points/pressure", [s["pressure"] for s in data["special_points"]])):
        if not np.isfinite(np.asarray(values, dtype=float)).all():
            raise CurveFileError(where, f"dataset {key} holds NaN or inf (a stored curve point is always finite)")
    return data


def parameter_column(group) -> str:
    """The dataset of a curve group holding q: named after the parameter (``parameter`` attribute), or ``q`` in
    files written before the coordinate had its parameter's name."""
    name = str(plain(group.attrs["parameter"]))
    return name if name in group and name not in CURVE_COLUMNS and name != "special_points" else "q"


MEETING_KINDS = (Kind.LP_BP, Kind.LV_BP, Kind.LN_BP)  # the meetings of a fold and a pitchfork or branch point


def curve_meetings(curve: dict) -> list[dict]:
    """The meetings of a fold and a pitchfork or branch point on a stored curve (``read_curve``): kind, q,
    pressure, north pole stretch, status and uncertainty each."""
    return [{"kind": s["kind"], "q": float(q), "pressure": s["pressure"], "lam2_top": s["lam2_top"],
             "status": s["status"], "uncertainty": s["uncertainty"]}
            for s, q in zip(curve["special_points"], curve["special_q"]) if s["kind"] in MEETING_KINDS]


class CurveFileError(FileError):
    """A file that is not a readable two-parameter curve file (names the file and what is missing)."""
