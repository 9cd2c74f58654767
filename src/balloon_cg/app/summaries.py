"""Summaries of stored files for people and for JSON: run files, sweep files and two-parameter curve files."""
from pathlib import Path

import numpy as np

from ..io.legacy import stale_readings
from ..io.parents import parent_label, rejoin_label
from ..io.run_file import stored_scene
from ..scene.tables import Shape


def summarise_file(path) -> tuple[dict, str]:
    """(JSON-ready summary, readable text) of a run, sweep, curve or tube file, told apart by their format and
    content (raises the readers' errors for anything else)."""
    from ..io.layout import file_kind
    from ..io.run_file import RunFileError, read_run

    path = Path(path)
    kind = file_kind(path, RunFileError) if path.is_file() else None
    if kind == "sweep":
        summary = summarise_sweep(path)
        return summary, format_sweep(summary)
    if kind == "curve":
        summary = summarise_curves(path)
        return summary, format_curves(summary)
    if kind == "tube":
        from ..io.tube_file import read_tube_run
        from .tube_summary import format_tube, summarise_tube

        summary = summarise_tube(read_tube_run(path))
        return summary, format_tube(summary)
    run = read_run(path)
    return summarise_run(run), format_run(run)


def summarise_sweep(path) -> dict:
    """Provenance and, per member, its overrides, verdict and the primary branch's summary."""
    from ..io.sweep_file import read_sweep

    sweep = read_sweep(path)
    members = {}
    for index, member in sweep["members"].items():
        primary = member["branches"].get("primary")
        members[index] = {"overrides": member["overrides"],
                          "complete": bool(member["attrs"].get("complete", False)),
                          "stale_readings": _stale(member["attrs"]),
                          "branches": {name: len(b["pressure"]) for name, b in member["branches"].items()},
                          "primary": None if primary is None else _member_primary(path, index, member)}
    return {"file": str(path), "kind": "sweep", "provenance": sweep["attrs"], "members": members}


def _member_primary(path, index: int, member: dict) -> dict:
    """The summary of a sweep member's primary branch: a sphere's (``summarise_branch``) or, for a tube's member
    (its ``shape`` attribute "tube", io.sweep_file.is_tube: its branches are a tube run's), the tube summary's
    (app/tube_summary.py)."""
    if member["attrs"].get("shape") != Shape.TUBE.value:
        return summarise_branch(member["branches"]["primary"])
    from .tube_summary import summarise_tube

    tube = summarise_tube({"attrs": member["attrs"], "branches": {"primary": member["branches"]["primary"]},
                           "path": f"{path}: /members/{index}"})
    return tube["branches"]["primary"]


def format_sweep(summary: dict) -> str:
    p = summary["provenance"]
    lines = [f"file           {summary['file']}", f"sweep of       {p.get('scene_name', '?')}",
             f"created        {p.get('created', '?')}  (balloon-cg {p.get('package_version', '?')}, "
             f"format {p.get('format')})", f"command        {p.get('command', '?')}",
             f"members        {len(summary['members'])}", ""]
    for index, m in summary["members"].items():
        settings = ", ".join(f"{k} = {v}" for k, v in m["overrides"].items())
        branches = ", ".join(f"{name} ({n} points)" for name, n in m["branches"].items())
        specials = len(m["primary"]["special_points"]) if m["primary"] else 0
        lines.append(f"  member {index:<4} {settings}: {'complete' if m['complete'] else 'INCOMPLETE'}; "
                     f"{branches}; {specials} special points on the primary branch")
        lines += ["  " + line for line in _outdated(m["stale_readings"])]
    return "\n".join(lines)


def _stale(attrs) -> list[str]:
    """``stale_readings`` of a file or sweep member whose attributes ``attrs`` hold its scene (``scene_toml``) and
    provenance (a resumed sweep's members may come from two versions)."""
    from ..scene.tables import parse_stored

    return stale_readings(attrs, parse_stored(attrs["scene_toml"], "member").geometry.shape.value)


def _outdated(stale: list[str]) -> list[str]:
    """One OUTDATED line per change of ``stale_readings`` a file or member predates."""
    return [f"OUTDATED       written before this version changed its readings: {what}; run the scene again for "
            "this version's" for what in stale]


def summarise_curves(path) -> dict:
    """Provenance and, per two-parameter curve, its parameter, end, critical value and ranges."""
    import h5py

    from ..io.curve_file import CurveFileError, curve_meetings, read_curve
    from ..io.hdf5 import plain
    from ..io.layout import reading

    with h5py.File(path, "r") as f, reading(path, CurveFileError):
        attrs = {k: plain(v) for k, v in f.attrs.items()}
        names = list(f["two_parameter"])
    curves = {}
    for name in names:
        c = read_curve(path, name)
        curves[name] = {**{k: c["attrs"][k] for k in ("parameter", "end", "end_description", "q0", "critical_q",
                                                      "degree", "wall_time")},
                        "of": c["attrs"].get("of", "BP"),
                        "points": len(c["q"]), "q": _range(c["q"]), "pressure": _range(c["pressure"]),
                        "special_points": c["special_points"], "meetings": curve_meetings(c)}
    return {"file": str(path), "kind": "curve", "provenance": attrs, "stale_readings": _stale(attrs),
            "curves": curves}


def format_curves(summary: dict) -> str:
    p = summary["provenance"]
    lines = [f"file           {summary['file']}", f"scene          {p.get('scene_name')}",
             f"created        {p.get('created')}  (balloon-cg {p.get('package_version')}, format {p.get('format')})",
             f"command        {p.get('command')}", *_outdated(summary["stale_readings"])]
    for name, c in summary["curves"].items():
        critical = c["critical_q"]
        lines += ["", f"two-parameter curve {name}   (of {c['of']} points, in {c['parameter']}, degree {c['degree']})",
                  f"  points               {c['points']}",
                  "  {:<20} {:.10g} .. {:.10g}".format(c["parameter"], *c["q"]),
                  "  pressure             {:.10g} .. {:.10g}".format(*c["pressure"]),
                  f"  ended                {c['end']}: {c['end_description']}",
                  f"  critical value       {critical:.12g}" if np.isfinite(critical) else
                  "  critical value       none (the curve did not end in a verified merge or cusp)",
                  *(f"  {m['kind']} meeting        {c['parameter']} = {m['q']:.12g}, P = {m['pressure']:.10g} "
                    f"(pole stretch {m['lam2_top']:.10g}), {m['status']}" +
                    (f" ±{m['uncertainty']:.1g}" if m["status"] != "located" else "") for m in c["meetings"]),
                  f"  wall time            {c['wall_time']:.3f} s"]
    return "\n".join(lines)


def summarise_run(run: dict) -> dict:
    """JSON-ready summary of read_run() output: the reference shape and its parameters (``geometry``: the stored
    scene's [geometry] table), provenance, what changed since in the meaning of its stored readings
    (``stale_readings``: io.legacy), the run time per phase (``run_time``) and one summary per branch."""
    geometry = stored_scene(run).geometry
    return {
        "file": run["path"],
        "scene_name": run["scene_name"],
        "geometry": geometry.to_table(),
        "stale_readings": stale_readings(run["attrs"], geometry.shape.value),
        "provenance": run["attrs"],
        "run_time": run_time(run["attrs"]),
        "branches": {name: summarise_branch(b) | {"parent_label": parent_label(run, name),
                                                  "rejoin_label": rejoin_label(run, name)}
                     for name, b in run["branches"].items()},
        "snap_throughs": run.get("snap_throughs", []),
    } | _capsule_surface(run)


def _capsule_surface(run: dict) -> dict:
    """{'surface_branches': a capsule's non-axisymmetric branches (``surface_branch_summaries``)} where the run file
    has them, else {}."""
    found = run.get("meridian_surface")
    return {"surface_branches": surface_branch_summaries(found, run["attrs"].get("control", "pressure"))} if found else {}


def surface_branch_summaries(found: dict, control: str) -> dict:
    """{name: {'m', 'parent' {'branch', 'zero'}, 'points', 'pressure', 'volume', 'amplitude' ranges, 'stable_points'
    (under the file's control), 'largest_error_estimate', 'limited' (the basis at its cap: estimates above
    solver.max_error; False in files before it), 'image_of' (the branch it is the image of under the rotation by
    π/m about the axis; "" where traced), 'folds' [{'after_point', 'pressure'}], 'events' (its UZ points:
    [{'after_point', 'pressure', 'volume', 'note', 'located'}]), 'stop_code', 'stop_message'}}
    of a tube's or a capsule's non-axisymmetric branches (io/tube_surface_file.py)."""
    def span(values):
        return [float(values.min()), float(values.max())]

    return {name: {"m": int(b["attrs"]["m"]),
                   "parent": {"branch": b["attrs"]["parent_branch"], "zero": int(b["attrs"]["parent_zero"])},
                   "points": len(b["pressure"]), "pressure": span(b["pressure"]), "volume": span(b["volume"]),
                   "amplitude": span(b["amplitude"]), "stable_points": int((b[f"unstable_{control}"] == 0).sum()),
                   "largest_error_estimate": float(b["error_estimate"].max()),
                   "limited": bool(b["attrs"].get("limited", False)), "image_of": b["attrs"].get("image_of", ""),
                   "folds": [{"after_point": i, "pressure": p} for i, p in b["folds"]],
                   "events": [{k: v for k, v in e.items() if k != "coefficients"} for e in b.get("events", [])],
                   "stop_code": b["attrs"]["stop_code"], "stop_message": b["attrs"]["stop_message"]}
            for name, b in found.items()}


def surface_branch_lines(name: str, b: dict, control: str, origin: str) -> list[str]:
    """The lines of a tube's or a capsule's non-axisymmetric branch (``surface_branch_summaries``), born at
    ``origin`` (its zero or branch point) of its parent branch."""
    return [f"surface branch {name} (m = {b['m']}, from {origin} of {b['parent']['branch']}): {b['points']} points, "
            f"P {b['pressure'][0]:.8g}..{b['pressure'][1]:.8g}, "
            f"V/V0 {b['volume'][0]:.6g}..{b['volume'][1]:.6g}, amplitude {b['amplitude'][0]:.4g}.."
            f"{b['amplitude'][1]:.4g}, stop {b['stop_code']} ({b['stop_message']}); {b['stable_points']} "
            f"stable under {control} control; largest error estimate "
            f"{b['largest_error_estimate']:.2g}{' (limited: the basis at its cap)' if b['limited'] else ''}"
            + (f"; the image of {b['image_of']} under the rotation by π/{b['m']} about the axis" if b["image_of"]
               else ""),
            *(f"  LP after point {f['after_point']:<4} P = {f['pressure']:.10g}" for f in b["folds"]),
            *(f"  UZ after point {e['after_point']:<4} P = {e['pressure']:.10g}  V/V0 = {e['volume']:.8g}  "
              f"{e['note']}{'' if e['located'] else '  approximate'}" for e in b["events"])]


def run_time(attrs: dict) -> dict | None:
    """{'total': seconds of the whole run, 'phases': {phase: seconds}} (io.run_file.timing_attrs); None for a file
    written without them (before issue 28, or by a writer given no clock)."""
    if "total_seconds" not in attrs:
        return None
    return {"total": float(attrs["total_seconds"]),
            "phases": {str(name): float(t) for name, t in zip(attrs["phase_names"], attrs["phase_seconds"])}}


def summarise_branch(b: dict) -> dict:
    """Points, ranges, special points, accuracy and run time of one stored branch (``m`` = 0: axisymmetric;
    a surface branch, m ≥ 1: ``summarise_surface_branch``)."""
    if "surface_degree" in b["attrs"]:
        return summarise_surface_branch(b)
    n, attrs = len(b["pressure"]), b["attrs"]
    wall = float(attrs["wall_time"])
    return {
        "m": 0,
        "points": n,
        "pressure": _range(b["pressure"]),
        "lam2_top": _range(b["lam2_top"]),
        "lam2_bottom": _range(b["lam2_bottom"]),
        "special_points": b["special_points"],
        "stop_reason": attrs["stop_reason"],
        "stop_codes": dict(zip(attrs.get("leg_labels", []), attrs.get("leg_stop_codes", []))),
        "max_residual": float(b["residual"].max()),
        "max_error_estimate": float(b["error_estimate"].max()),
        "wall_time": wall,
        "wall_time_per_point": wall / n,
        "degree": int(attrs["degree"]),
        "symmetric": bool(attrs["symmetric"]),
        "basis_map": {"centres": [float(c) for c in attrs.get("map_centres", [])],
                      "widths": [float(w) for w in attrs.get("map_widths", [])]},
        "kernel_class": attrs["kernel_class"],
        "M": float(attrs["M"]),
        "chi": float(attrs["chi"]),
        **({"voltage": _range(b["voltage"]), "parameter": attrs["parameter"]} if "voltage" in b else {}),
        **({"field_M": _range(b["M"]), "parameter": "M"} if "M" in b else {}),  # continue --parameter M
        "parent": [attrs["parent_branch"], int(attrs["parent_branch_point"])] if "parent_branch" in attrs else None,
        "origin": attrs.get("origin", "traced"),  # files written before reflected mirrors: every branch traced
        "gauge": attrs["gauge"],  # io.run_file reads it from the layout in files written before it
        "reflection_of": attrs.get("reflection_of", ""),
        "stable_points": {k: int(np.sum(v)) for k, v in b.get("stability", {}).items() if k.startswith("stable")},
        **_lowest_frequencies(b),
    }


def _lowest_frequencies(b: dict) -> dict:
    """A branch's stored frequencies (per block the lowest Ω² at every point and special point; an axisymmetric
    branch's rigid translations), or nothing when it stores none."""
    if "frequencies" not in b:
        return {}
    return {"frequencies": {block: values[:, 0] for block, values in b["frequencies"].items()},
            "special_frequencies": {block: values[:, 0] for block, values in b["special_frequencies"].items()},
            **({"translation_omega2": b["translation_omega2"]} if b["translation_omega2"] else {})}


def summarise_surface_branch(b: dict) -> dict:
    """The summary of a surface branch (docs/hdf5.md): m, its parent (branch, branch point number), every
    point's P, the ranges of the pole stretches, volume and tilt, its basis, stop, accuracy, stability."""
    n, attrs = len(b["pressure"]), b["attrs"]
    wall = float(attrs["wall_time"])
    return {
        "m": int(attrs["m"]),
        "parent": [attrs["parent_branch"], int(attrs["parent_branch_point"])] if attrs["parent_branch"] else None,
        "origin": attrs.get("origin", "traced"),
        "reflection_of": attrs.get("reflection_of", ""),
        "reflection": [int(k) for k in attrs.get("reflection", (-1, -1, 1))],  # files before it: the half turn
        "gauge": attrs["gauge"],  # io.run_file reads it from M in files written before it
        "points": n,
        "pressure": _range(b["pressure"]),
        "pressures": [float(p) for p in b["pressure"]],
        "lam2_top": _range(b["lam2_top"]),
        "lam2_bottom": _range(b["lam2_bottom"]),
        "volume": _range(b["volume"]),
        "tilt": _range(b["tilt"]),
        **{name: {"max": float(np.abs(b[name]).max()), "last": [float(v) for v in b[name][-1]]}
           for name in ("force", "torque") if name in b},
        "special_points": b["special_points"],
        "stop_reason": attrs["stop_reason"],
        "stop_codes": dict(zip(attrs.get("leg_labels", []), attrs.get("leg_stop_codes", []))),
        "max_residual": float(b["residual"].max()),
        "max_error_estimate": float(b["error_estimate"].max()),
        "wall_time": wall,
        "wall_time_per_point": wall / n,
        "surface_degree": int(attrs["surface_degree"]),
        "symmetry": np.asarray(attrs["symmetry"]).reshape(-1, 3).tolist(),
        "characters": [int(c) for c in attrs["characters"]],
        "nodes": [int(attrs["n_theta"]), int(attrs["n_phi"])],
        "kernel_class": attrs["kernel_class"],
        "M": float(attrs["M"]),
        "chi": float(attrs["chi"]),
        "stable_points": {k: int(np.sum(v)) for k, v in b.get("stability", {}).items() if k.startswith("stable")},
        **_lowest_frequencies(b),
    }


def _vector(values) -> str:
    return "(" + ", ".join(f"{v:.6g}" for v in values) + ")"


def _range(values) -> list:
    return [float(np.min(values)), float(np.max(values))]


def format_run(run: dict) -> str:
    """Readable summary of read_run() output."""
    summary = summarise_run(run)
    p = summary["provenance"]
    lines = [
        f"file           {summary['file']}",
        f"scene          {summary['scene_name']}",
        f"shape          {stored_scene(run).geometry.describe()}",
        f"created        {p['created']}  (balloon-cg {p['package_version']}, format {p['format']})",
        f"command        {p['command']}",
        f"tolerance      {p['tolerance']:g}",
        f"control        {p.get('control', 'pressure')} (loading.control)",
        f"kernels        digest {p['generated_digest'][:16]}…",
        f"result         {verdict_text(p)}",
        *_outdated(summary["stale_readings"]),
        *_run_time_lines(summary),
    ]
    for name, b in summary["branches"].items():
        lines += ["", *_format_branch(name, b)]
    for name, b in summary.get("surface_branches", {}).items():
        lines += ["", *surface_branch_lines(name, b, p.get("control", "pressure"),
                                            f"branch point {b['parent']['zero']}")]
    for s in summary["snap_throughs"]:
        target = f"{s['to_branch']} point {s['to_index']}" if s["to_branch"] else "no stable state on the traced branches"
        value = f"{_snap_symbol(run, s['from_branch'])} = {s['pressure']:.10g}"
        lines.append(f"snap-through at {value}: {s['from_branch']} point {s['from_index']} -> {target}")
    return "\n".join(lines)


def _run_time_lines(summary: dict) -> list[str]:
    """'run time  15.3 s (190 ms per primary point): trace 0.14 s, …' when the file stores its phases."""
    timing, primary = summary["run_time"], summary["branches"].get("primary")
    if timing is None:
        return []
    per_point = f" ({1e3 * timing['total'] / primary['points']:.1f} ms per primary point)" if primary else ""
    phases = ", ".join(f"{name} {seconds:.3f} s" for name, seconds in timing["phases"].items())
    return [f"run time       {timing['total']:.3f} s{per_point}: {phases}"]


def _snap_symbol(run: dict, branch: str) -> str:
    """What a snap-through's stored value is: Φ̄ on a voltage branch, M on a branch in M, else the control value P,
    V or n."""
    from ..scene import Control

    parameter = run["branches"][branch]["attrs"].get("parameter")
    if parameter in ("voltage", "M"):
        return parameter
    control = Control(run["attrs"].get("control", Control.PRESSURE))
    return {Control.PRESSURE: "P", Control.VOLUME: "V", Control.GAS: "n"}[control]


def verdict_text(attrs: dict) -> str:
    """'complete', or the incomplete parts stored in a run file's root attributes; a complete result with stated
    limitations (a part not searched, a surface branch at its basis' cap: ``analysis.verdict.Gap.fails`` false)
    names them."""
    if "complete" not in attrs:
        return "not assessed"
    parts = [f"{gap} ({branch}: {message})" for gap, branch, message in
             zip(attrs["incomplete_gaps"], attrs["incomplete_branches"], attrs["incomplete_messages"])]
    if attrs["complete"]:
        return "complete" + (", except: " + "; ".join(parts) if parts else "")
    return "incomplete: " + "; ".join(parts)


def _image(reflection) -> str:
    """What a reflected surface branch is the image under: 'the rotation by π about the axis' (diag(−1, −1, 1)),
    else 'the reflection (x → −x, …)'."""
    if list(reflection) == [-1, -1, 1]:
        return "the rotation by π about the axis"
    return "the reflection " + _reflections([reflection], [1])


def _reflections(symmetry, characters) -> str:
    """'y → −y, z → −z' for the reflections a surface basis keeps (a character −1 as 'odd under …')."""
    axes = "xyz"
    parts = []
    for row, chi in zip(symmetry, characters):
        flipped = ", ".join(f"{axes[k]} → −{axes[k]}" for k in range(3) if row[k] < 0)
        parts.append(f"({flipped})" + (" odd" if chi < 0 else ""))
    return "; ".join(parts) or "none"


def _format_surface_branch(name: str, b: dict) -> list[str]:
    born = "traced on the whole sphere from the start" if b["parent"] is None else \
        f"m = {b['m']}, from {_parent_point(b)}"
    return [
        f"surface branch {name}   ({born}; {b['kernel_class']}, degree "
        f"{b['surface_degree']}, reflections {_reflections(b['symmetry'], b['characters'])}, nodes "
        f"{b['nodes'][0]} × {b['nodes'][1]}, {READINGS.get(b['gauge'], b['gauge'])}, M = {b['M']:g}, "
        f"chi = {b['chi']:g})",
        f"  points               {b['points']}"
        + (f"  ({_image(b['reflection'])} of {b['reflection_of']})" if b["reflection_of"] else ""),
        "  pressure             {:.10g} .. {:.10g}".format(*b["pressure"]),
        "  lam2 top pole        {:.10g} .. {:.10g}  (√(λ1 λ2) at the material pole)".format(*b["lam2_top"]),
        "  lam2 bottom pole     {:.10g} .. {:.10g}".format(*b["lam2_bottom"]),
        "  volume               {:.10g} .. {:.10g}".format(*b["volume"]),
        "  tilt                 {:.4g} .. {:.4g} degrees".format(*b["tilt"]),
        *([f"  field force          {_vector(b['force']['last'])} at the last point (|F| ≤ {b['force']['max']:.3g}; "
           "the hold's reaction is −F)", f"  field torque         |T| ≤ {b['torque']['max']:.3g} (zero at equilibrium)"]
          if "force" in b else []),
        f"  stop reason          {b['stop_reason']}",
        f"  max residual         {b['max_residual']:.3e}",
        f"  max error estimate   {b['max_error_estimate']:.3e}",
        f"  trace time           {b['wall_time']:.3f} s",
        f"  stable points        {_stable_counts(b['stable_points'], b['points'])}",
        f"  special points       {len(b['special_points']) or 'none'}",
        *_special_lines(b["special_points"], b["gauge"], b["symmetry"]),
        *_frequency_lines(b),
    ]


def _parent_point(b: dict) -> str:
    """Where a branch leaves its parent: 'label 3 on primary' (the label inspect lists and continue takes), or
    'primary branch point 0' when that point is not in the file."""
    if b["parent_label"] is None:
        return f"{b['parent'][0]} branch point {b['parent'][1]}"
    return f"label {b['parent_label']} on {b['parent'][0]}"


def _format_branch(name: str, b: dict) -> list[str]:
    if "surface_degree" in b:
        return _format_surface_branch(name, b)
    born = "" if b["parent"] is None else f"from {_parent_point(b)}; "
    lines = [
        f"branch {name}   ({born}{b['kernel_class']}, degree {b['degree']}, "
        f"{'equator-symmetric' if b['symmetric'] else 'no symmetry'}, {READINGS.get(b['gauge'], b['gauge'])}, M = {b['M']:g}, "
        f"chi = {b['chi']:g})",
        *([f"  basis map            centres cos θ = {', '.join(f'{c:.4g}' for c in b['basis_map']['centres'])}, widths "
           f"{', '.join(f'{w:.3g}' for w in b['basis_map']['widths'])} (near the wires)"]
          if b["basis_map"]["centres"] else []),
        f"  points               {b['points']}"
        + (f"  (the reflection z → −z of {b['reflection_of']}, residuals checked)" if b["reflection_of"] else ""),
        "  pressure             {:.10g} .. {:.10g}".format(*b["pressure"]),
        *(["  voltage              {:.10g} .. {:.10g}".format(*b["voltage"]) + f"  (continued in {b['parameter']})"]
          if "voltage" in b else []),
        *(["  field M              {:.10g} .. {:.10g}  (continued in M at fixed P)".format(*b["field_M"])]
          if "field_M" in b else []),
        "  lam2 top pole        {:.10g} .. {:.10g}".format(*b["lam2_top"]),
        "  lam2 bottom pole     {:.10g} .. {:.10g}".format(*b["lam2_bottom"]),
        f"  stop reason          {b['stop_reason']}"
        + ("" if b.get("rejoin_label") is None else f" (at label {b['rejoin_label']})"),
        f"  max residual         {b['max_residual']:.3e}",
        f"  max error estimate   {b['max_error_estimate']:.3e}",
        f"  trace time           {b['wall_time']:.3f} s",
        f"  error estimate vs trace time: {b['max_error_estimate']:.3e} max, "
        f"{1e3 * b['wall_time_per_point']:.2f} ms of tracing per point",
        f"  stable points        {_stable_counts(b['stable_points'], b['points'])}",
        f"  special points       {len(b['special_points']) or 'none'}",
    ]
    return lines + _special_lines(b["special_points"], b["gauge"]) + _frequency_lines(b)


READINGS = {"both": "held and free", "held": "held at its centre", "free": "free (net axial force zero)"}


def _special_lines(special: list, gauge: str = "both", symmetry=()) -> list[str]:
    """One aligned line per stored special point: its label (the number ``continue`` takes), kind (with its reading
    where it is not its branch's ``gauge``, and a surface branch's secondary branch point's sector under the
    reflections ``symmetry`` of its basis), place, P (and M or Φ̄ on a branch continued in it), the pole stretches,
    the note."""
    labels = [f"{s['label']:>3} {s['kind']} {s['classification']}".rstrip() + (f" m={s['m']}" if s["m"] else "")
              + (f" {s['gauge']}" if s.get("gauge", gauge) != gauge else "")
              + (f" sector {_reflections(symmetry, s['sector'])}" if s.get("sector") else "")
              + ("" if s["status"] == "located" else f" ({s['status']}, ±{s['uncertainty']:.1g})")
              for s in special]
    places = [f"point {s['index']}" if s["kind"] == "EP" else f"points {s['index']}-{s['index'] + 1}"
              for s in special]  # EP is a stored point; LP, TP, BP lie between two (docs/hdf5.md)
    width, place_width = max(map(len, labels), default=0), max(map(len, places), default=0)
    lines = []
    for s, label, place in zip(special, labels, places):
        note = f"  {s['note']}" if s["note"] else ""
        lines.append(
            f"    {label:<{width}}  {place:<{place_width}}  P = {s['pressure']:.10g}  "
            + "".join(f"{key} = {s[key]:.10g}  " for key in ("M", "voltage") if key in s) +
            f"lam2 north = {s['lam2_top']:.10g}  lam2 south = {s['lam2_bottom']:.10g}{note}"
        )
    return lines


def _frequency_lines(b: dict) -> list[str]:
    """The lowest Ω² of every block at each special point (its label and kind), one aligned row each, when the branch
    stores frequencies ([dynamics]; a surface branch's blocks are its sectors under each reading,
    dynamics.surface.sector_block)."""
    if "special_frequencies" not in b:
        return []
    rigid = [f"  rigid translation Ω² {direction} {_range_text(values)}" for direction, values in
             b.get("translation_omega2", {}).items()]
    if rigid:
        rigid[-1] += "  (0: no field, the balloon drifts; > 0 the field restores it, < 0 pulls it away)"
    if not b["special_points"]:
        return rigid
    blocks = list(b["special_frequencies"])
    rows = [[f"{s['label']} {s['kind']}"] + [_omega2(b["special_frequencies"][k][n]) for k in blocks]
            for n, s in enumerate(b["special_points"])]
    widths = [max(len(r[j]) for r in rows + [["", *blocks]]) for j in range(len(blocks) + 1)]
    table = [["", *blocks]] + rows
    return rigid + ["  lowest Ω² = ω² R0² ρ/μ per block at the special points (negative: unstable; docs/dynamics.md)",
            *("    " + "  ".join(cell.rjust(w) if j else cell.ljust(w) for j, (cell, w) in enumerate(zip(r, widths)))
              for r in table)]


def _range_text(values) -> str:
    return f"{min(values):.3g} .. {max(values):.3g}"


def _omega2(value) -> str:
    return "-" if not np.isfinite(value) else f"{value:.6g}"


def _stable_counts(counts: dict, points: int) -> str:
    """'pressure control 23, gas control 40, volume control 51 (of 72; the same with the centre free)' from the
    counts of the stored flags stable_READING and stable_READING_free (balloon held at its centre, or free)."""
    if not counts:
        return "not assessed"
    order = {"pressure": 0, "gas": 1, "volume": 2}  # the readings nest in this order (pressure ⊆ gas ⊆ volume)
    held = {k.removeprefix("stable_"): n for k, n in counts.items() if not k.endswith("_free")}
    free = {k.removeprefix("stable_").removesuffix("_free"): n for k, n in counts.items() if k.endswith("_free")}
    held, free = ({k: d[k] for k in sorted(d, key=lambda r: (order.get(r, len(order)), r))} for d in (held, free))
    text = ", ".join(f"{reading} control {n}" for reading, n in held.items()) + f" (of {points}"
    if free == held:
        return text + "; the same with the centre free)"
    if not free:  # a whole-sphere primary of a field without axial symmetry: no free equilibrium to read
        return text + "; centre free: not read)"
    return text + "; centre free: " + ", ".join(f"{reading} control {n}" for reading, n in free.items()) + ")"


def format_table(values: dict) -> str:
    """Two aligned columns: name, value."""
    width = max(map(len, values))
    return "\n".join(f"{k:<{width}}  {_show(v)}" for k, v in values.items())


def _show(v) -> str:
    if isinstance(v, bool):
        return str(v).lower()
    return f"{v:.12g}" if isinstance(v, float) else str(v)
