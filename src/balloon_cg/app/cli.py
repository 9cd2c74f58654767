"""Command line: ``balloon-cg run | solve | inspect | plot | sweep | critical`` (``balloon-cg SUBCOMMAND -h``).

Exit codes: 0 success: the result is complete (analysis.verdict: every branch reached its requested end, every
special point is located, stability settled); 1 the computation did not give what was asked (a branch could
not start, or the result is incomplete: the file is still written, flagged, and the incomplete parts are named
on stderr; ``--allow-partial`` makes an incomplete result exit 0; ``critical``: the two-parameter curve did not
end in a verified merge of the pitchforks); 2 bad input (invalid scene, missing or unreadable file, existing
output without --force, a scene ``critical`` cannot handle). Errors are one line on stderr, ``balloon-cg: error: ...``.
"""
import argparse
import json
import shlex
import sys
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..analysis.picture import analyse
from ..analysis.primary import trace_primary
from ..analysis.results import StopCode
from ..analysis.tracer import ContinuationError
from ..analysis.verdict import failing, incomplete, summary_line
from ..model.field import FieldError
from ..post.plotting import KINDS, PlotError, plot as draw_plot
from ..galerkin.profiles import equator_values
from ..scene import SceneError, load_scene
from ..io.hdf5 import check_output
from ..io.run_file import RunFileError, read_run, write_run
from .kernels_cmd import add_kernels

PROG = "balloon-cg"


class UsageError(ValueError):
    """A bad command-line value (exit code 2)."""


class Failure(Exception):
    """A computation that ran but did not give what was asked (exit code 1)."""


def main(argv=None) -> int:
    """Run one subcommand; returns the exit code."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser().parse_args(argv)
    args.command_line = shlex.join([PROG, *argv])
    try:
        return args.handler(args)
    except (SceneError, RunFileError, UsageError, PlotError, FieldError) as e:
        return _error(str(e), 2)
    except OSError as e:
        return _error(_os_message(e), 2)
    except (ContinuationError, Failure) as e:
        return _error(str(e), 1)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=PROG, description="Inflated magnetoelastic membranes.")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in (_add_run, _add_solve, _add_inspect, _add_plot, _add_sweep, _add_critical, add_kernels):
        add(commands)
    return parser


def _error(message: str, code: int) -> int:
    print(f"{PROG}: error: {message}", file=sys.stderr)
    return code


def _os_message(e: OSError) -> str:
    if e.filename is None:
        return str(e)
    return f"{e.filename}: {e.strerror or e}"


# --- run ---------------------------------------------------------------------------------------------------

def _add_run(commands):
    p = commands.add_parser("run", help="trace the primary branch of a scene and write a run file")
    p.add_argument("scene", help="scene TOML file")
    p.add_argument("-o", "--output", required=True, help="run file to write (HDF5)")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.add_argument("--quiet", action="store_true", help="no progress bar and no summary")
    p.add_argument("--primary-only", action="store_true",
                   help="trace the primary branch only (no stability, branch points or pear branches)")
    p.add_argument("--allow-partial", action="store_true",
                   help="exit 0 also when the result is incomplete (it is still flagged in the file and on stderr)")
    p.set_defaults(handler=run)


def run(args) -> int:
    """Trace, write, read back and summarise."""
    scene = load_scene(args.scene)
    _, found = run_scene(scene, args.output, args.force, progress=not args.quiet, command=args.command_line,
                         primary_only=args.primary_only)
    if not args.quiet:
        print(format_run(read_run(args.output)))
    return verdict_status(found, args.allow_partial)


def verdict_status(found: list, allow_partial: bool) -> int:
    """Exit status of a written result: 0 when complete (or ``allow_partial``), else 1 with the incomplete
    parts on stderr (one line)."""
    if not failing(found):
        return 0
    print(f"{PROG}: {summary_line(found)}", file=sys.stderr)
    return 0 if allow_partial else 1


def run_scene(scene, out_path, force: bool = False, progress: bool = False, command: str | None = None,
              primary_only: bool = False) -> tuple[Path, list]:
    """Analyse ``scene`` (primary branch, stability, branch points, pear branches, snap-throughs; or only the
    primary branch) and write the run file ``out_path``; returns the path and what is incomplete
    (analysis.verdict.Incomplete entries, empty when the result is complete).

    The output is checked before the trace (which may take long); ``progress`` shows a bar on stderr;
    ``command`` overrides the provenance attribute (default: sys.argv).
    """
    check_output(out_path, force)
    with tqdm(desc=scene.name, unit=" points", disable=not progress, file=sys.stderr) as bar:
        tick = lambda point: bar.update()  # noqa: E731
        if primary_only:
            branches, snaps = [trace_primary(scene, progress=tick)], None
            found = incomplete(branches)
        else:
            picture = analyse(scene, progress=tick)
            branches, snaps, found = picture.branches, picture.snaps, picture.incomplete
    extra = {} if command is None else {"command": command}
    return write_run(out_path, scene, branches, force=force, extra_attrs=extra, snaps=snaps, found=found), found


# --- solve -------------------------------------------------------------------------------------------------

def _add_solve(commands):
    p = commands.add_parser("solve", help="one equilibrium on the primary branch at a given north pole stretch")
    p.add_argument("scene", help="scene TOML file")
    p.add_argument("--pole-stretch", type=float, required=True, metavar="X", help="north pole stretch λ2(0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(handler=solve)


def solve(args) -> int:
    """Trace the primary branch up to the requested north pole stretch and report its end point."""
    scene = load_scene(args.scene)
    x, start = args.pole_stretch, scene.continuation.start_stretch
    if not np.isfinite(x) or x <= start:
        raise UsageError(f"--pole-stretch = {x:g}: must be > continuation.start_stretch = {start:g}")
    branch = trace_primary(scene, stop_stretch=x, down=False)
    if branch.legs[0].stop.code != StopCode.STOP_STRETCH:
        reached = branch.pole_values()["lam2_north"].max()
        raise Failure(
            f"the primary branch did not reach north pole stretch {x:g} ({branch.stop_reason}); "
            f"largest stretch reached: {reached:.10g}"
        )
    result = solution(branch, -1)
    print(json.dumps(result) if args.json else format_table(result | {"wall_time": f"{result['wall_time']:.3f} s"}))
    return 0


def solution(branch, i: int) -> dict:
    """The reported quantities of point i of a branch."""
    X = branch.X[i]
    values = {"pressure": X[-1], **branch.pole_values(X), **equator_values(branch.disc, X)}
    return {
        **{k: float(np.squeeze(v)) for k, v in values.items()},
        "residual": float(branch.residual[i]),
        "error_estimate": float(branch.error_estimate[i]),
        "wall_time": branch.wall_time,
    }


# --- inspect -----------------------------------------------------------------------------------------------

def _add_inspect(commands):
    p = commands.add_parser("inspect", help="summary of the branches in a run file")
    p.add_argument("file", help="run file (HDF5)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(handler=inspect)


def inspect(args) -> int:
    """Print the summary of a run file."""
    run = read_run(args.file)
    if args.json:
        print(json.dumps(summarise_run(run)))
    else:
        print(format_run(run))
    return 0


# --- plot --------------------------------------------------------------------------------------------------

IMAGE_FORMATS = (".png", ".pdf", ".svg")


def _add_plot(commands):
    p = commands.add_parser("plot", help="draw a figure from one or more run files (docs/plots.md)")
    p.add_argument("files", nargs="+", metavar="FILE", help="run files (HDF5); several: one curve set per file")
    p.add_argument("--what", required=True, choices=list(KINDS), metavar="KIND",
                   help=f"what to draw: {', '.join(KINDS)}")
    p.add_argument("-o", "--output", help="image file, .png, .pdf or .svg (default: FIRST_FILE_STEM_KIND.png "
                                          "next to the first file; an existing image is overwritten)")
    p.add_argument("--points", type=_indices, metavar="I,J,K",
                   help="point indices for shapes, stresses, field, curvature (negative: from the end)")
    p.add_argument("--branch", metavar="NAME",
                   help="branch to draw (default: every branch for pressure-* and energy, primary for the others)")
    p.set_defaults(handler=plot)


def _indices(text: str) -> list[int]:
    try:
        return [int(item) for item in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected comma-separated integers, e.g. 0,10,-1") from None


def plot(args) -> int:
    """Draw one figure and save it; prints the image path."""
    first = Path(args.files[0])
    output = Path(args.output) if args.output else first.with_name(f"{first.stem}_{args.what}.png")
    if output.suffix.lower() not in IMAGE_FORMATS:
        raise UsageError(f"--output {output}: the suffix must be one of {', '.join(IMAGE_FORMATS)}")
    check_output(output, force=True)
    draw_plot(args.files, args.what, args.points, args.branch).savefig(output, dpi=150)
    print(output)
    return 0


# --- critical ----------------------------------------------------------------------------------------------

def _add_critical(commands):
    p = commands.add_parser(
        "critical", help="continue the first pear pitchfork in M or alpha1 (two-parameter continuation) and report "
                         "the critical value where the isola's two pitchforks merge",
        description="Trace the primary branch, locate its first pear-shaped pitchfork and follow it in M or alpha1. "
                    "Exit 0: the two pitchforks merge at P > 0 and the curve returns to the partner pitchfork "
                    "(critical value printed). Exit 1: the computation gave no critical value (no pear pitchfork, "
                    "or the curve ended otherwise: one line says how and where; the curve file is still written). "
                    "Exit 2: a scene this command cannot handle (not equator-symmetric; --parameter M without "
                    "coils) or bad input.")
    p.add_argument("scene", help="scene TOML file (equator-symmetric: coils mirror-symmetric about z = 0)")
    p.add_argument("--parameter", required=True, choices=("M", "alpha1"), help="the second parameter")
    p.add_argument("-o", "--output", required=True, help="curve file to write (HDF5; plot it with --what phase)")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(handler=critical)


def critical(args) -> int:
    """Primary branch, its first pear pitchfork, the curve of pitchforks in the parameter, the merge point.

    Exit codes: 0 a verified merge (``CurveEnd.ISOLA_MERGE``: a fold in q at P > 0 after which the curve returns
    to q0 at the partner pitchfork) located, ``critical q = ...`` on stdout. 1 (``Failure``) the computation ran
    but gave no verified critical value: no pear pitchfork on the primary branch, the extended system did not
    start, the merge is only approximately located, or the curve
    ended otherwise (P reached 0, a fold not verified as a merge, a coil wire, the point budget, the minimum
    step): one line on stderr says how and where, and the curve file is still written. 2 (``UsageError``) a
    scene the command cannot handle, checked before any computation: not equator-symmetric (the pear block needs
    the equator-symmetric layout), or ``--parameter M`` without coils. Progress goes to stderr (``--quiet``: none).
    """
    from ..analysis.bifurcation import detect, locate
    from ..analysis.stability import assess_branch
    from ..analysis.codim2 import CurveEnd, TwoParameterError, continue_branch_point
    from ..analysis.results import Block, Status
    from ..io.curve_file import write_curve

    scene = load_scene(args.scene)
    asymmetry = _asymmetry(scene)
    if asymmetry:
        raise UsageError(f"critical needs an equator-symmetric scene: {args.scene}: {asymmetry}")
    if args.parameter == "M" and not scene.field.coils:
        raise UsageError(f"critical --parameter M needs coils: {args.scene} has no [[field.coils]], so the "
                         "equilibrium does not depend on M")
    check_output(args.output, args.force)

    def say(text):
        if not args.quiet:
            print(f"{PROG} critical: {text}", file=sys.stderr)

    with tqdm(desc="primary branch", unit=" points", disable=args.quiet, file=sys.stderr) as bar:
        branch = trace_primary(scene, progress=lambda point: bar.update())
    say(f"primary branch: {len(branch.X)} points ({branch.stop_reason}); assessing the pear block")
    assessments, _ = assess_branch(branch, scene.stability.degree)
    pear = [event for event in detect(branch, assessments) if event[1] == Block.ODD_HELD]
    if not pear:
        raise Failure(f"no pear-shaped pitchfork on the primary branch of {args.scene} ({branch.stop_reason}): "
                      f"nothing to continue in {args.parameter}")
    say(f"locating the first pear pitchfork (of {len(pear)})")
    bp = locate(branch, *pear[0])
    if bp.status != Status.LOCATED:
        say(f"the pear pitchfork is only approximately located (±{bp.uncertainty:.1g}: {bp.reason})")
    say(f"pear pitchfork at P = {bp.X[-1]:.10g}; continuing it in {args.parameter}")
    try:
        with tqdm(desc=f"curve in {args.parameter}", unit=" points", disable=args.quiet, file=sys.stderr) as bar:
            curve = continue_branch_point(branch, bp, args.parameter, progress=lambda point: bar.update())
    except TwoParameterError as e:
        raise Failure(f"the curve of pitchforks in {args.parameter} could not start: {e}") from None
    write_curve(args.output, scene, curve, force=args.force, extra_attrs={"command": args.command_line})
    say(f"curve: {len(curve.q)} points, ended: {curve.end.value}")
    if curve.end != CurveEnd.ISOLA_MERGE:
        raise Failure(f"no critical {args.parameter}: {curve.describe()}; curve (end: {curve.end.value}) still "
                      f"written to {args.output}")
    q, P, stretch = curve.critical
    merge = curve.merge
    if merge.status != Status.LOCATED:
        raise Failure(f"the merge of the pitchforks near {args.parameter} = {q:.8g} is only approximately located "
                      f"(±{merge.uncertainty:.1g}: {merge.reason}); curve written to {args.output}")
    print(f"critical {args.parameter} = {q:.12g} (P = {P:.10g}, pole stretch {stretch:.10g}); "
          f"curve written to {args.output}")
    return 0


def _asymmetry(scene) -> str:
    """Why the primary branch of ``scene`` is not traced in the equator-symmetric layout ('' if it is)."""
    if scene.continuation.symmetry == "none":
        return 'continuation.symmetry = "none"'
    if scene.field.is_equator_symmetric:
        return ""
    coils = scene.field.coils
    for i, c in enumerate(coils):
        if not any(d.radius == c.radius and d.height == -c.height and abs(d.current) == abs(c.current) for d in coils):
            return (f"coil {i} (radius {c.radius:g}, height {c.height:g}) has no mirror image about z = 0 "
                    "(radius, height −h, current ±)")
    return "the coil pairs mix equal and opposite currents (all pairs must be one or the other)"


# --- sweep -------------------------------------------------------------------------------------------------

def _add_sweep(commands):
    p = commands.add_parser("sweep", help="run a scene over a grid of parameter values into one sweep file")
    p.add_argument("scene", help="scene TOML file (the base scene)")
    p.add_argument("--vary", action="append", required=True, metavar="KEY=SPEC",
                   help="KEY=START:STOP:COUNT or KEY=v1,v2,...; KEY a dotted scene key (field.M, "
                        "field.coils[0].radius, material.alpha[0]) or a bare name of one table (M = field.M); "
                        "repeat for a cartesian product")
    p.add_argument("-o", "--output", required=True, help="sweep file (HDF5) to write or resume")
    p.add_argument("--scheduler", metavar="ADDRESS", help="send the members to this dask.distributed scheduler")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="local worker processes (default: all cores; 1: compute in this process)")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--primary-only", action="store_true", help="trace the primary branch only")
    mode.add_argument("--no-pear", action="store_true",
                      help="primary branch, stability and branch points, but no pear branches")
    p.add_argument("--force", action="store_true", help="replace an existing file holding a different sweep")
    p.add_argument("--quiet", action="store_true", help="no progress bar and no summary")
    p.add_argument("--allow-partial", action="store_true",
                   help="exit 0 also when some members are incomplete (they are flagged in the file)")
    p.set_defaults(handler=sweep)


def sweep(args) -> int:
    """Expand, compute the members not yet in the file, append them, summarise."""
    from ..io.sweep_file import incomplete_members
    from .sweep import SweepError, format_summary, run_sweep

    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers {args.workers}: must be >= 1")
    mode = "primary-only" if args.primary_only else "no-pear" if args.no_pear else "analysis"
    scene = load_scene(args.scene)
    try:
        result = run_sweep(scene, args.vary, args.output, mode=mode, workers=args.workers, scheduler=args.scheduler,
                           force=args.force, progress=not args.quiet, command=args.command_line)
    except SweepError as e:
        raise UsageError(str(e)) from None
    if not args.quiet:
        print(format_summary(result))
    if result.failed:
        raise Failure(f"{len(result.failed)} of {len(result.members)} sweep members failed (members "
                      f"{', '.join(map(str, sorted(result.failed)))}); re-run the same command to retry them")
    partial = incomplete_members(result.path)  # the verdicts stored with the members (attributes only)
    if partial:
        print(f"{PROG}: incomplete: sweep members {', '.join(map(str, partial))} (their results are flagged in the "
              "file: members/<index> attributes complete, incomplete_*)", file=sys.stderr)
        return 0 if args.allow_partial else 1
    return 0



# --- summaries ---------------------------------------------------------------------------------------------

def summarise_run(run: dict) -> dict:
    """JSON-ready summary of read_run() output: provenance and one summary per branch."""
    return {
        "file": run["path"],
        "scene_name": run["scene_name"],
        "provenance": run["attrs"],
        "branches": {name: summarise_branch(b) for name, b in run["branches"].items()},
        "snap_throughs": run.get("snap_throughs", []),
    }


def summarise_branch(b: dict) -> dict:
    """Points, ranges, special points, accuracy and run time of one stored branch."""
    n, attrs = len(b["pressure"]), b["attrs"]
    wall = float(attrs["wall_time"])
    return {
        "points": n,
        "pressure": _range(b["pressure"]),
        "lam2_north": _range(b["lam2_north"]),
        "lam2_south": _range(b["lam2_south"]),
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
        "parent": [attrs["parent_branch"], int(attrs["parent_branch_point"])] if "parent_branch" in attrs else None,
        "stable_points": {k: int(np.sum(v)) for k, v in b.get("stability", {}).items() if k.startswith("stable")},
    }


def _range(values) -> list:
    return [float(np.min(values)), float(np.max(values))]


def format_run(run: dict) -> str:
    """Readable summary of read_run() output."""
    summary = summarise_run(run)
    p = summary["provenance"]
    lines = [
        f"file           {summary['file']}",
        f"scene          {summary['scene_name']}",
        f"created        {p['created']}  (balloon-cg {p['package_version']}, format {p['format']})",
        f"command        {p['command']}",
        f"tolerance      {p['tolerance']:g}",
        f"kernels        digest {p['generated_digest'][:16]}…",
        f"result         {_verdict(p)}",
    ]
    for name, b in summary["branches"].items():
        lines += ["", *_format_branch(name, b)]
    for s in summary["snap_throughs"]:
        target = f"{s['to_branch']} point {s['to_index']}" if s["to_branch"] else "no stable state on the traced branches"
        lines.append(f"snap-through at P = {s['pressure']:.10g}: {s['from_branch']} point {s['from_index']} -> {target}")
    return "\n".join(lines)


def _verdict(attrs: dict) -> str:
    """'complete', or the incomplete parts stored in a run file's root attributes."""
    if "complete" not in attrs:
        return "not assessed"
    if attrs["complete"]:
        return "complete"
    parts = [f"{gap} ({branch}: {message})" for gap, branch, message in
             zip(attrs["incomplete_gaps"], attrs["incomplete_branches"], attrs["incomplete_messages"])]
    return "incomplete: " + "; ".join(parts)


def _format_branch(name: str, b: dict) -> list[str]:
    lines = [
        f"branch {name}   ({b['kernel_class']}, degree {b['degree']}, "
        f"{'equator-symmetric' if b['symmetric'] else 'no symmetry'}, M = {b['M']:g}, chi = {b['chi']:g})",
        *([f"  basis map            centres cos θ = {', '.join(f'{c:.4g}' for c in b['basis_map']['centres'])}, widths "
           f"{', '.join(f'{w:.3g}' for w in b['basis_map']['widths'])} (near the wires)"]
          if b["basis_map"]["centres"] else []),
        f"  points               {b['points']}",
        "  pressure             {:.10g} .. {:.10g}".format(*b["pressure"]),
        "  lam2 north pole      {:.10g} .. {:.10g}".format(*b["lam2_north"]),
        "  lam2 south pole      {:.10g} .. {:.10g}".format(*b["lam2_south"]),
        f"  stop reason          {b['stop_reason']}",
        f"  max residual         {b['max_residual']:.3e}",
        f"  max error estimate   {b['max_error_estimate']:.3e}",
        f"  wall time            {b['wall_time']:.3f} s",
        f"  error estimate vs run time: {b['max_error_estimate']:.3e} max, "
        f"{1e3 * b['wall_time_per_point']:.2f} ms per point",
        f"  stable points        {b['stable_points'] or 'not assessed'}",
        f"  special points       {len(b['special_points']) or 'none'}",
    ]
    for s in b["special_points"]:
        note = f"  {s['note']}" if s["note"] else ""
        status = "" if s["status"] == "located" else f" ({s['status']}, ±{s['uncertainty']:.1g})"
        label = f"{s['kind']} {s['classification']}".strip() + (f" m={s['m']}" if s["m"] else "") + status
        lines.append(
            f"    {label:<3} at point {s['index']:<5} P = {s['pressure']:.10g}  "
            f"lam2 north = {s['lam2_north']:.10g}  lam2 south = {s['lam2_south']:.10g}{note}"
        )
    return lines


def format_table(values: dict) -> str:
    """Two aligned columns: name, value."""
    width = max(map(len, values))
    return "\n".join(f"{k:<{width}}  {_show(v)}" for k, v in values.items())


def _show(v) -> str:
    if isinstance(v, bool):
        return str(v).lower()
    return f"{v:.12g}" if isinstance(v, float) else str(v)
