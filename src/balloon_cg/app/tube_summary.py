"""What ``inspect`` shows of a tube's run file (io/tube_file.py): the shape and its parameters, Maxwell's pressure,
per branch its points, P and V/V0 ranges, its stop, how many of its points are compressed (tube/stability.py) and
its located points (those in a compressed state marked: docs/shapes.md)."""
import math

from ..tube.stability import COMPRESSED


def summarise_tube(run: dict) -> dict:
    """JSON-ready summary of ``io.tube_file.read_tube_run`` output."""
    a = run["attrs"]
    geometry = {"shape": a["shape"], "length": a["length"], "ends": a["ends"],
                "axial_stretch": None if math.isnan(a["axial_stretch"]) else a["axial_stretch"]}
    branches = {}
    for name, b in sorted(run["branches"].items(), key=lambda item: item[0] != "primary"):
        branches[name] = {"points": len(b["pressure"]), "stop_code": b["attrs"]["stop_code"],
                          "stop_message": b["attrs"]["stop_message"],
                          "pressure": [float(b["pressure"].min()), float(b["pressure"].max())],
                          "volume": [float(b["volume"].min()), float(b["volume"].max())],
                          "compressed_points": int((b["smallest_stress"] < COMPRESSED).sum()),
                          "special_points": b["special_points"]}
    maxwell = None if math.isnan(a["maxwell_pressure"]) else a["maxwell_pressure"]
    return {"file": run["path"], "kind": "tube", "scene_name": a["scene_name"], "geometry": geometry,
            "degree": a["degree"], "maxwell_pressure": maxwell,
            "provenance": {k: a[k] for k in ("format", "created", "command", "package_version")},
            "branches": branches}


def format_tube(summary: dict) -> str:
    """Readable summary of ``summarise_tube``."""
    g, p = summary["geometry"], summary["provenance"]
    held = "free (closed)" if g["axial_stretch"] is None else f"held at {g['axial_stretch']:g} L"
    maxwell = "none" if summary["maxwell_pressure"] is None else f"{summary['maxwell_pressure']:.10g}"
    lines = [f"file           {summary['file']}",
             f"scene          {summary['scene_name']}",
             f"created        {p['created']}  (balloon-cg {p['package_version']}, format {p['format']})",
             f"command        {p['command']}",
             f"shape          tube of length {g['length']:g}, {g['ends']} ends, end distance {held}",
             f"degree         {summary['degree']}",
             f"Maxwell        P_M = {maxwell}"]
    for name, b in summary["branches"].items():
        lines += ["", f"branch {name}: {b['points']} points, P {b['pressure'][0]:.6g}..{b['pressure'][1]:.6g}, "
                      f"V/V0 {b['volume'][0]:.6g}..{b['volume'][1]:.6g}, stop {b['stop_code']} ({b['stop_message']})"
                      + (f"; {b['compressed_points']} points compressed" if b["compressed_points"] else "")]
        for k, s in enumerate(b["special_points"]):
            block = f" {s['block']}" if s["block"] else ""
            compressed = "  compressed" if s["smallest_stress"] < COMPRESSED else ""
            lines.append(f"  {k:>3} {s['kind']}{block:<5} after point {s['index']:<4} P = {s['pressure']:.10g}  "
                         f"V/V0 = {s['volume']:.8g}  {s['status']}{compressed}")
    return "\n".join(lines)
