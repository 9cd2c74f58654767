"""The default run (``make run``): ``python -m balloon_cg.app.default_run OUTDIR [--quick]``.

For each default scene (SPOM1 at M = 0, and SPOM1 between the paper's two opposed coils at M = 0.002: the
files scenes/spom1.toml and scenes/spom1_two_coils_M0.002.toml, read as the package data balloon_cg.scenes,
which pyproject.toml maps to the top-level scenes/, so that an installed package runs them too) the primary
branch is traced and written to OUTDIR/<scene>.h5 (the scenes at once: each but the last, the longest, in a child
process beside this one, whose workers get the cores a finished child frees; a child, its scene written, compiles
the last scene's whole-sphere kernels into numba's cache before drawing, so that on a first run this process
finds them there when its surface branches start: model/compile_lock.py makes either wait for a kernel the other
is compiling), and every plot kind that applies is drawn as
OUTDIR/<scene>_<kind>.png (a child's by the child; the last scene's, once the children are done, with the
pressure curves of all scenes together (several M in one figure), OUTDIR/all_<kind>.png, on every core, each
run file read once for them and the summary). Existing files of these names are overwritten. A summary table
closes the run; the exit code is 1 if a scene failed or its result is incomplete (analysis.verdict), else 0.
``--quick`` limits every leg of the continuation to QUICK_POINTS points (for tests: the results are then partial
by design and do not change the exit code).
"""
import argparse
import json
import subprocess
import sys
import time
from contextlib import nullcontext
from importlib import resources
from pathlib import Path

from ..analysis.branches.tracer import ContinuationError
from ..analysis.surface.branches import compile_kernels
from ..analysis.verdict import failing, summary_line
from ..io.output import replacing
from ..numerics.workers import MIN_COST, serial, spread
from .cli import run_scene
from .progress import shown
from .summaries import run_time, summarise_branch
from ..post.plotting import applicable_kinds, load_branches, plot, special_label
from ..scene import parse_scene
from ..io.run_file import read_run

SCENES = ("spom1", "spom1_two_coils_M0.002")
COMBINED = ("pressure-pole", "pressure-equator")
QUICK_POINTS = 8


def default_scenes(max_points: int | None = None) -> list:
    """The default scenes from the package data (``continuation.max_points`` overridden if given)."""
    folder = resources.files("balloon_cg.scenes")
    scenes = [parse_scene((folder / f"{name}.toml").read_text(encoding="utf-8"), name) for name in SCENES]
    if max_points is not None:
        scenes = [s.with_overrides({"continuation.max_points": max_points}) for s in scenes]
    return scenes


def draw_figures(paths, outdir: Path, stem: str, kinds=None) -> list[Path]:
    """Save every applicable plot kind (or those of ``kinds``) for the run files ``paths`` as <stem>_<kind>.png (each
    file read once for all of them; ``drawn``)."""
    return drawn(figures([read_run(p) for p in paths], outdir, stem, kinds))


def figures(runs: list, outdir: Path, stem: str, kinds=None) -> list[tuple]:
    """(runs, kind, image) of every plot kind that applies to the read ``runs`` (or of those of ``kinds``), the image
    outdir/<stem>_<kind>.png."""
    applicable = applicable_kinds([b for run in runs for b in load_branches(run)])
    return [(runs, kind, outdir / f"{stem}_{kind}.png")
            for kind in (applicable if kinds is None else [k for k in kinds if k in applicable])]


# a figure's drawing (~0.4 s) in numerics.workers' cost units (degree³ of a block): each is worth a worker's start
FIGURE_COST = MIN_COST


def drawn(jobs: list[tuple]) -> list[Path]:
    """Draw and save the figures ``jobs`` ((runs, kind, image) each: ``figures``) on the cores this process may use
    (numerics.workers.spread: a forked worker draws the same figure it would here); their images in order."""
    def draw(job: tuple) -> str:
        runs, kind, image = job
        figure = plot(runs, kind)
        with replacing(image, force=True) as tmp:  # the default run owns out/ (its runs are replaced too)
            figure.savefig(tmp, dpi=150, format="png")
        return str(image)

    return [Path(image) for image in spread(draw, jobs, [FIGURE_COST] * len(jobs), interruptible=False)]


def summary_row(run: dict) -> dict:
    """Scene, points, P range, special points, max error estimate, the primary trace's time and the whole run's
    (every phase, writing included: ``summaries.run_time``) of a read run file."""
    b = summarise_branch(run["branches"]["primary"])
    timing = run_time(run["attrs"])
    return {
        "scene": run["scene_name"],
        "points": str(b["points"]),
        "P range": "{:.4f} .. {:.4f}".format(*b["pressure"]),
        "special points": " ".join(special_label(s) for s in b["special_points"]),
        "max error est.": f"{b['max_error_estimate']:.1e}",
        "trace time": f"{b['wall_time']:.1f} s",
        "run time": f"{timing['total']:.1f} s" if timing else "-",
        "result": "complete" if run["attrs"].get("complete") else "incomplete",
    }


def format_summary(rows: list[dict]) -> str:
    """Rows of equal keys as an aligned text table."""
    keys = list(rows[0])
    widths = [max(len(k), *(len(r[k]) for r in rows)) for k in keys]

    def line(values):
        return "  ".join(f"{v:<{w}}" for v, w in zip(values, widths)).rstrip()

    return "\n".join([line(keys), line("-" * w for w in widths)] + [line(r[k] for k in keys) for r in rows])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m balloon_cg.app.default_run",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("outdir", help="folder for the run files and figures (created if missing)")
    parser.add_argument("--quick", action="store_true", help=f"at most {QUICK_POINTS} points per leg (for tests)")
    parser.add_argument("--quiet", action="store_true", help="no progress bars")
    parser.add_argument("--only", choices=SCENES, help=argparse.SUPPRESS)  # one scene, nothing combined: a child's
    parser.add_argument("--ahead", choices=SCENES, help=argparse.SUPPRESS)  # a child's: the scene it runs beside
    args = parser.parse_args(argv)
    outdir = Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    scenes = default_scenes(QUICK_POINTS if args.quick else None)
    if args.only:  # a child's: its outcome as one JSON object on stdout
        named = {s.name: s for s in scenes}
        outcome = run_and_draw(named[args.only], outdir, args.quick, args.quiet, named.get(args.ahead))
        print(json.dumps(outcome))
        return 1 if outcome["failure"] else 0
    *beside, last = scenes
    children = [_started(scene.name, outdir, args.quick, last.name) for scene in beside]
    try:
        outcomes = [run_and_draw(last, outdir, args.quick, args.quiet, draw=False)]
        for child in children:
            out, err = child.communicate()
            sys.stderr.write(err)
            outcomes.insert(-1, _outcome(child, out))
    finally:
        for child in children:
            if child.poll() is None:
                child.kill()
                child.wait()
    runs = [read_run(o["path"]) for o in outcomes if o["path"]]  # each file read once: figures and summary
    jobs = figures(runs[-1:], outdir, last.name) if outcomes[-1]["path"] else []
    combined = figures(runs, outdir, "all", COMBINED) if len(runs) > 1 else []
    images = drawn(jobs + combined)  # the last scene's and the combined figures at once, on both cores
    outcomes[-1]["images"] = [str(image) for image in images[:len(jobs)]]
    for outcome in outcomes:  # the children's after the last scene's progress bars, in the scenes' order
        for line in ([outcome["path"]] if outcome["path"] else []) + outcome["images"]:
            print(line)
    failed = [o["failure"] for o in outcomes if o["failure"]]
    for image in images[len(jobs):]:
        print(image)
    rows = [summary_row(run) for run in runs]
    if rows:
        print()
        print(format_summary(rows))
    print(f"\ntotal wall time {time.perf_counter() - start:.1f} s (traces, run files and figures)")
    for message in failed:
        print(f"failed: {message}", file=sys.stderr)
    return 1 if failed else 0


def run_and_draw(scene, outdir: Path, quick: bool, quiet: bool, ahead=None, draw: bool = True) -> dict:
    """Analyse ``scene`` into outdir/<scene>.h5 and draw its figures (not ``draw``: none, 'images' empty): {'path':
    the run file (None when the trace failed), 'images': the figures' paths, 'failure': what failed, or None (a
    quick run's partial result is none)}, plain data (a child's is sent as JSON). ``ahead``: a scene another
    process runs, whose whole-sphere kernels are compiled into numba's cache between the run file and the figures
    (a child's, which draws on its one core: the other is that scene's; module docstring)."""
    try:
        path, found = run_scene(scene, outdir / f"{scene.name}.h5", force=True, progress=shown(quiet))
    except ContinuationError as e:
        return {"path": None, "images": [], "failure": f"{scene.name}: {e}"}
    if ahead is not None:
        compile_kernels(ahead)
    with serial() if ahead is not None else nullcontext():
        images = draw_figures([path], outdir, scene.name) if draw else []
    return {"path": str(path), "images": [str(image) for image in images],
            "failure": f"{scene.name}: {summary_line(found)}" if failing(found) and not quick else None}


def _outcome(child: subprocess.Popen, out: str) -> dict:
    """A finished child's outcome (``run_and_draw``'s, the last line of its stdout), or, where it died before
    saying it, a failure naming its scene and exit status."""
    try:
        return json.loads(out.splitlines()[-1])
    except (IndexError, ValueError):
        return {"path": None, "images": [], "failure": f"{child.args[-1]}: exit {child.returncode}"}


def _started(name: str, outdir: Path, quick: bool, ahead: str) -> subprocess.Popen:
    """The default run of scene ``name`` alone, in a child process beside this one (no progress bars: this
    process draws its own), compiling scene ``ahead``'s whole-sphere kernels before its figures; its stdout (its
    outcome) and stderr captured."""
    command = [sys.executable, "-m", "balloon_cg.app.default_run", str(outdir), "--quiet"] + (
        ["--quick"] if quick else []) + ["--only", name, "--ahead", ahead]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


if __name__ == "__main__":
    sys.exit(main())
