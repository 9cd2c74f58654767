"""Two-parameter curve files: a run file (same root attributes, empty /branches) with /two_parameter.

Layout::

    /                            attrs: as a run file (format, scene, provenance) + extra_attrs
    /branches/                   (empty: the file is also a readable run file)
    /two_parameter/<name>/       attrs: parameter, stop_reason, stop_code, end, end_description, q0, wall_time,
                                        degree, kernel_class, M, chi, critical_q (NaN unless end = isola_merge)
        q, pressure, lam2_north, lam2_south, newton_iterations, residual      (n_points,)
        unknowns (n_points, n + 1): u then P;  mode (n_points, m): φ on the odd perturbation block
        special_points/ the run file's special-point columns (kind LP: the folds in q; status located only for
                        the verified merge of the two pitchforks), unknowns in the branch layout (u, P), and q

``end`` is the curve's ``analysis.codim2.CurveEnd`` (how it ended: isola_merge, fold, nonpositive_pressure, wire,
budget, step_min, alpha1_zero, other); ``end_description`` says the same for people, with where.
"""
from dataclasses import replace

import h5py
import numpy as np

from .hdf5 import atomic_file, plain
from .run_file import read_special, root_attrs, write_special
from .schema import attach_dimensions, describe, scale


def write_curve(path, scene, curve, name: str = "pear", force: bool = False, extra_attrs: dict | None = None):
    """Write a two-parameter curve (analysis.codim2.TwoParameterCurve) to ``path`` atomically."""
    attrs = root_attrs(scene) | dict(extra_attrs or {})
    critical = curve.critical
    with atomic_file(path, force) as f:
        f.attrs.update(attrs)
        f.create_group("branches")
        group = f.create_group("two_parameter").create_group(name)
        group.attrs.update({
            "parameter": curve.parameter,
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
        columns = {"q": curve.q, "pressure": curve.pressure, **curve.pole_values(),
                   "newton_iterations": curve.iterations, "residual": curve.residual,
                   "unknowns": curve.branch_X(), "mode": curve.mode}
        for key, data in columns.items():
            group.create_dataset(key, data=data)
        point, unknown = scale(group, "point", len(curve.q)), scale(group, "unknown", columns["unknowns"].shape[1])
        attach_dimensions(group, {1: (point,), "unknowns": (point, unknown),
                                  "mode": (point, scale(group, "mode_unknown", columns["mode"].shape[1]))})
        merges = [replace(s, X=curve.branch_X(s.X)[0]) for s in curve.merges]
        special = group.create_group("special_points")
        write_special(special, merges, curve.n + 1, curve.disc, unknown)
        q = special.create_dataset("q", data=np.array([s.X[-1] for s in curve.merges], dtype=float))
        q.dims[0].attach_scale(special["special"])
        describe(q)
    return path


def read_curve(path, name: str = "pear") -> dict:
    """The datasets and attributes of a stored curve: {'attrs', datasets…, 'special_points': [dicts], 'q'}."""
    with h5py.File(path, "r") as f:
        group = f["two_parameter"][name]
        data = {key: item[()] for key, item in group.items() if isinstance(item, h5py.Dataset)}
        data["attrs"] = {k: plain(v) for k, v in group.attrs.items()}
        special = group["special_points"]
        data["special_points"] = read_special(special)
        data["special_q"] = special["q"][()]
    return data
