"""What ``inspect`` shows of a tube's run file (io/tube_file.py): the shape and its parameters, the field, the
voltage ([electric]; None without), the parameter continued in (``parameter``: "voltage" at ``fixed_pressure`` on a
voltage continuation, tube/voltage.py, its branch's Φ̄ range and its located points' Φ̄; "axial_stretch" at
``fixed_pressure`` on a continuation in the held distance of the ends, tube/stretch.py, its λ range and its located
points' λ), the loading control (its
stability reading: how many of a branch's points are stable under it; under gas control the amount n = P V of every
located point), Maxwell's pressure, per branch its points, P and V/V0 ranges, its stop, how many of its points are
compressed (tube/stability.py), a switched branch's parent label and where it rejoined (``parent``, ``rejoins``),
how many are not resolved (their Legendre tail above the scene's solver.max_error:
tube/accuracy.py; None in files before the tail is stored), the largest tail, the height of its last point's crest
and its located points (with their crest's height; those in a compressed state marked: docs/tubes.md; a UZ point with
its event), with [dynamics] frequencies each block's lowest Ω² at every located point (``frequencies``: per block
over the points, as a sphere run's), the m ≥ 1 blocks (``azimuthal``: per m the most unstable directions, the
smallest eigenvalue, the points after which the unstable count changes and the located zeros with where their mode is
largest; {} where not assessed), the onset curve of
``critical`` (its range, folds and stop), the verdict (``complete``, ``result``: io/tube_file.py's; None and "not
assessed" in files before it), the stage a signal stopped (``interrupted``), the switched branches that
did not start (``not_started``: "name: why") and the non-axisymmetric branches ([surface] branches:
``surface_branches``, their parent branch and zero, ranges, stop, stable points and largest error estimate)."""
import math
import tomllib

import numpy as np

from .summaries import surface_branch_lines, surface_branch_summaries, verdict_text
from ..io.tube_file import CREST, HELD_M1, HOOP, STRETCH, VOLTAGE, discretisation
from ..scene.tables import parse_stored
from ..tube.azimuthal import mode_profile
from ..tube.stability import COMPRESSED

PEAK_SAMPLES = 401  # points of [0, L] on which a critical mode's largest displacement is found

def summarise_tube(run: dict) -> dict:
    """JSON-ready summary of ``io.tube_file.read_tube_run`` output."""
    a = run["attrs"]
    geometry = {"shape": a["shape"], "length": a["length"], "ends": a["ends"],
                "axial_stretch": None if math.isnan(a["axial_stretch"]) else a["axial_stretch"]}
    control, v0 = a["control"], np.pi * a["length"]
    max_error = parse_stored(a["scene_toml"]).solver.max_error
    branches = {}
    for name, b in sorted(run["branches"].items(), key=lambda item: item[0] != "primary"):
        unstable = b.get(f"unstable_{control}")
        special = [s | ({"amount": float(s["pressure"] * s["volume"] * v0)} if control == "gas" else {})
                   for s in b["special_points"]]
        lineage = b["attrs"]
        branches[name] = {"points": len(b["pressure"]), "stop_code": b["attrs"]["stop_code"],
                          "parent": None if "parent_label" not in lineage else
                          {"branch": lineage["parent_branch"], "label": int(lineage["parent_label"])},
                          "rejoins": None if lineage.get("rejoins_label", -1) < 0 else int(lineage["rejoins_label"]),
                          "stop_message": b["attrs"]["stop_message"],
                          "pressure": [float(b["pressure"].min()), float(b["pressure"].max())],
                          "volume": [float(b["volume"].min()), float(b["volume"].max())],
                          "voltage": None if VOLTAGE not in b else [float(b[VOLTAGE].min()), float(b[VOLTAGE].max())],
                          "axial_stretch": None if STRETCH not in b else [float(b[STRETCH].min()),
                                                                          float(b[STRETCH].max())],
                          "compressed_points": int((b["smallest_stress"] < COMPRESSED).sum()),
                          "unresolved_points": int((b["tail"] > max_error).sum()) if "tail" in b else None,
                          "largest_tail": float(b["tail"].max(initial=0.0)) if "tail" in b else None,
                          "last_crest_height": float(b[CREST][-1]) if CREST in b else None,
                          "stable_points": None if unstable is None else int((unstable == 0).sum()),
                          "special_points": _with_omega2(special, b.get("frequencies")),
                          "azimuthal": _azimuthal(b, discretisation(a, b["attrs"])),
                          **_frequencies(b.get("frequencies"))}
    maxwell = None if math.isnan(a["maxwell_pressure"]) else a["maxwell_pressure"]
    field = scene_field(a["scene_toml"])
    electric = tomllib.loads(a["scene_toml"]).get("electric")
    primary = run["branches"]["primary"]
    parameter = "voltage" if VOLTAGE in primary else STRETCH if STRETCH in primary else "pressure"  # P fixed but
    #                                     in P: tube/voltage.py (run, or continue from a label), tube/stretch.py
    return {"file": run["path"], "kind": "tube", "scene_name": a["scene_name"], "geometry": geometry,
            "field": field, "voltage": None if electric is None else float(electric.get("voltage", 0.0)),
            "parameter": parameter,
            "fixed_pressure": float(primary["pressure"][0]) if parameter != "pressure" else None,
            "control": control, "degree": a["degree"], "maxwell_pressure": maxwell,
            "provenance": {k: a[k] for k in ("format", "created", "command", "package_version")},
            "branches": branches, "surface_branches": surface_branch_summaries(run.get("surface_branches", {}), control),
            "onset": _onset(run.get("onset"), max_error), "interrupted": a["interrupted"] or None,
            "complete": None if "complete" not in a else bool(a["complete"]), "result": verdict_text(a),
            "not_started": [line for line in a["not_started"].split("\n") if line]}


def _azimuthal(branch: dict, disc) -> dict:
    """{m: {'unstable_max', 'lowest_min', 'changes': [{'after_point', 'unstable', 'pressure', 'volume'}], 'points'}}
    of the branch's m ≥ 1 blocks ('1 held': the held tube's m = 1 block in a field, io/tube_file.HELD_M1): a change
    between points i and i + 1 listed after point i (at point i + 1's P and V/V0), and the located zeros of the
    eigenvalues ('points': io/tube_file's dicts, the critical mode replaced by ``mode_peak``, the reference
    arclength S where its displacement |(R, T, Z)| is largest: None in files before the mode is stored)."""
    out = {}
    for m, block in branch.get("azimuthal", {}).items():
        counts = block["unstable"]
        changes = [{"after_point": int(i), "unstable": int(counts[i + 1]), "pressure": float(branch["pressure"][i + 1]),
                    "volume": float(branch["volume"][i + 1])} for i in np.flatnonzero(np.diff(counts))]
        points = [{k: v for k, v in p.items() if k != "mode"} | {"mode_peak": _peak(disc, p["mode"])}
                  for p in block["points"]]
        out[str(m)] = {"unstable_max": int(counts.max()), "lowest_min": float(block["lowest"][:, 0].min()),
                       "changes": changes, "points": points}
    return out


def _peak(disc, mode) -> float | None:
    """The reference arclength S (on PEAK_SAMPLES points of [0, L]) where the critical mode's |(R, T, Z)| is largest."""
    if mode is None:
        return None
    S = np.linspace(0.0, disc.length, PEAK_SAMPLES)
    return float(S[np.argmax(np.linalg.norm(mode_profile(disc, mode, S), axis=0))])


def _frequencies(frequencies: dict | None) -> dict:
    """{'frequencies': {block: the lowest Ω² at every point}} of a branch with frequencies, else {}."""
    if frequencies is None:
        return {}
    return {"frequencies": {block: [float(v) for v in values[:, 0]] for block, values in frequencies["omega2"].items()}}


def _with_omega2(special: list, frequencies: dict | None) -> list:
    """The located points, each with 'omega2' (block: its lowest Ω² there) where the branch has frequencies."""
    if frequencies is None:
        return special
    return [{**s, "omega2": {block: float(values[k, 0]) for block, values in frequencies["special"].items()}}
            for k, s in enumerate(special)]


def scene_field(toml: str) -> dict:
    """{'M', 'coils'} of the scene's [field] (the file's scene text)."""
    field = tomllib.loads(toml).get("field", {})
    return {"M": float(field.get("M", 0.0)), "coils": len(field.get("coils", []))}


def _onset(onset: dict | None, max_error: float) -> dict | None:
    """The onset curve's ranges, last point, folds (each with its state's Legendre ``tail`` and ``unresolved``:
    above ``max_error``, solver.max_error) and stop; ``unresolved_points`` and ``largest_tail`` (None in files
    before the tail is stored)."""
    if onset is None:
        return None
    a = onset["attrs"]
    tail = onset.get("tail")
    return {"unresolved_points": None if tail is None else int((tail > max_error).sum()),
            "largest_tail": None if tail is None else float(tail.max(initial=0.0)),
            "parameter": a["parameter"], "q0": a["q0"], "points": len(onset["q"]),
            "q": [float(onset["q"].min()), float(onset["q"].max())],
            "pressure": [float(onset["pressure"].min()), float(onset["pressure"].max())],
            "hoop_stretch": [float(onset[HOOP].min()), float(onset[HOOP].max())],
            "last": {"q": float(onset["q"][-1]), "pressure": float(onset["pressure"][-1]),
                     "hoop_stretch": float(onset[HOOP][-1]), "crest_height": float(onset[CREST][-1])},
            "folds": [f | {"unresolved": bool(f["tail"] > max_error)} for f in onset["folds"]],
            "stop_code": a["stop_code"], "stop_message": a["stop_message"]}


def _no_maxwell(summary: dict) -> str:
    """Why a tube run has no Maxwell pressure (tube/picture.maxwell)."""
    if summary["parameter"] == "voltage":
        return "none (a voltage continuation: no bulge branch is traced)"
    if summary["geometry"]["axial_stretch"] is not None:
        return "none (the ends are held apart)"
    if summary["field"]["coils"] and summary["field"]["M"] > 0:
        return "none (in a coil field there is no uniform state to draw an equal-area line on)"
    return "none (the uniform closed path has no pressure maximum and minimum)"


def _assessed(summary: dict) -> str:
    """Which m ≥ 1 blocks the branches were assessed for."""
    largest = [len([m for m in b["azimuthal"] if m != HELD_M1]) for b in summary["branches"].values()]
    if not largest or min(largest) == 0:
        return "m ≥ 1 not assessed"
    shown = "m = 1" if min(largest) == 1 else f"m = 1..{min(largest)}"
    return f"{shown} (the same under all three: δV = 0 for m ≥ 1)"


def format_tube(summary: dict) -> str:
    """Readable summary of ``summarise_tube``."""
    g, p = summary["geometry"], summary["provenance"]
    held = "free (closed)" if g["axial_stretch"] is None else f"held at {g['axial_stretch']:g} L" + (
        f" (continued in λ at P = {summary['fixed_pressure']:g})" if summary["parameter"] == STRETCH else "")
    maxwell = _no_maxwell(summary) if summary["maxwell_pressure"] is None else f"{summary['maxwell_pressure']:.10g}"
    lines = [f"file           {summary['file']}",
             f"scene          {summary['scene_name']}",
             f"created        {p['created']}  (balloon-cg {p['package_version']}, format {p['format']})",
             f"command        {p['command']}",
             f"shape          tube of length {g['length']:g}, {g['ends']} ends, end distance {held}",
             "field          " + (f"{summary['field']['coils']} coil(s), M = {summary['field']['M']:g}"
                                   if summary["field"]["coils"] else "none"),
             "voltage        " + ("none" if summary["voltage"] is None else f"Φ̄ = {summary['voltage']:g}"
                                     if summary["parameter"] != "voltage" else
                                     f"continued in Φ̄ at P = {summary['fixed_pressure']:g}"),
             f"control        {summary['control']}",
             f"degree         {summary['degree']}",
             "stability      m = 0 (pressure, volume and gas control); " + _assessed(summary),
             f"Maxwell        P_M = {maxwell}",
             f"result         {summary['result']}"]
    lines += [f"not started    {line}" for line in summary["not_started"]]
    if summary["interrupted"]:
        lines.append(f"interrupted    a signal stopped the {summary['interrupted']} stage: what follows it is missing")
    label = 0  # the labels of ``continue``, numbered through the branches (io/tube_file.tube_labels)
    for name, b in summary["branches"].items():
        origin = "" if b["parent"] is None else f" (from label {b['parent']['label']} of {b['parent']['branch']}" + (
            "" if b["rejoins"] is None else f", rejoins it at label {b['rejoins']}") + ")"
        lines += ["", f"branch {name}{origin}: {b['points']} points, P {b['pressure'][0]:.6g}..{b['pressure'][1]:.6g}, "
                      f"V/V0 {b['volume'][0]:.6g}..{b['volume'][1]:.6g}"
                      + ("" if b["voltage"] is None else f", Φ̄ {b['voltage'][0]:.6g}..{b['voltage'][1]:.6g}")
                      + ("" if b["axial_stretch"] is None else
                         f", λ {b['axial_stretch'][0]:.6g}..{b['axial_stretch'][1]:.6g}")
                      + f", stop {b['stop_code']} ({b['stop_message']})"
                      + ("" if b["stable_points"] is None else
                         f"; {b['stable_points']} stable under {summary['control']} control")
                      + (f"; {b['compressed_points']} points compressed" if b["compressed_points"] else "")
                      + (f"; {b['unresolved_points']} points unresolved (Legendre tail above solver.max_error, "
                         f"largest {b['largest_tail']:.2g})" if b["unresolved_points"] else "")
                      + ("" if b["last_crest_height"] is None else
                         f"; last crest at height {b['last_crest_height']:.6g}")]
        for m, block in b["azimuthal"].items():
            changes = ", ".join(f"{c['unstable']} after point {c['after_point']} (P = {c['pressure']:.6g}, "
                                f"V/V0 = {c['volume']:.6g})" for c in block["changes"])
            name = f"m = {m}" + (" free" if m == "1" and HELD_M1 in b["azimuthal"] else "")
            lines.append(f"  {name}: lowest eigenvalue ≥ {block['lowest_min']:.4g}, at most {block['unstable_max']} "
                         f"unstable" + (f"; unstable count {changes}" if changes else ""))
            lines += [f"        BP m = {m} (eigenvalue {p['order']}) after point {p['index']:<4} P = {p['pressure']:.10g}  "
                      f"V/V0 = {p['volume']:.8g}  {p['status']}"
                      + ("" if p["mode_peak"] is None else f"  mode largest at S = {p['mode_peak']:.4g}")
                      for p in block["points"]]
        for s in b["special_points"]:
            k, label = label, label + 1
            block = f" {s['block']}" if s["block"] else ""
            compressed = "  compressed" if s["smallest_stress"] < COMPRESSED else ""
            crest = f"  crest at {s[CREST]:.6g}" if CREST in s else ""
            amount = f"  n = {s['amount']:.10g}" if "amount" in s else ""
            note = f"  {s['note']}" if s["note"] else ""
            charge = f"  Φ̄ = {s[VOLTAGE]:.10g}" if VOLTAGE in s else f"  λ = {s[STRETCH]:.10g}" if STRETCH in s else ""
            lines.append(f"  {k:>3} {s['kind']}{block:<5} after point {s['index']:<4} P = {s['pressure']:.10g}  "
                         f"V/V0 = {s['volume']:.8g}{charge}{amount}  {s['status']}{note}{crest}{compressed}")
            if "omega2" in s:
                lines.append("        lowest Ω²  " + "  ".join(f"{name} {value:.4g}"
                                                         for name, value in s["omega2"].items()))
    for name, b in summary.get("surface_branches", {}).items():
        lines += ["", *surface_branch_lines(name, b, summary["control"], f"zero {b['parent']['zero']} of block "
                                                                        f"m = {b['m']}")]
    onset = summary["onset"]
    if onset is not None:
        name, last = onset["parameter"], onset["last"]
        lines += ["", f"onset in {name} (from {name} = {onset['q0']:g}): {onset['points']} points, {name} "
                      f"{onset['q'][0]:.6g}..{onset['q'][1]:.6g}, P {onset['pressure'][0]:.8g}..{onset['pressure'][1]:.8g}"
                      f", largest hoop stretch {onset['hoop_stretch'][0]:.6g}..{onset['hoop_stretch'][1]:.6g}, stop "
                      f"{onset['stop_code']} ({onset['stop_message']}); last: {name} = {last['q']:.8g}, "
                      f"P = {last['pressure']:.10g}, hoop stretch {last['hoop_stretch']:.8g}, crest at "
                      f"{last['crest_height']:.6g}"
                      + (f"; {onset['unresolved_points']} points unresolved (Legendre tail above solver.max_error, "
                         f"largest {onset['largest_tail']:.2g})" if onset["unresolved_points"] else "")]
        lines += [f"  fold in {name} at {name} = {f['q']:.10g}, P = {f['pressure']:.10g}  {f['status']}"
                  + (f"  unresolved (tail {f['tail']:.2g})" if f["unresolved"] else "") for f in onset["folds"]]
    return "\n".join(lines)
