"""Command line: ``balloon-cg run | solve | inspect | plot | sweep | critical | continue`` (``SUBCOMMAND -h``;
also ``python -m balloon_cg``). The computing layers are imported by the subcommand that needs them, so
``--help``, ``--version`` and ``inspect`` start fast.

Exit codes: 0 success: the result is complete (analysis.verdict: every branch reached its requested end, every
special point is located, stability settled); 1 the computation did not give what was asked (a branch could
not start, or the result is incomplete: the file is still written, flagged, and the incomplete parts are named
on stderr; ``--allow-partial`` makes an incomplete result exit 0; ``critical``: the two-parameter curve did not
end in a verified merge of the pitchforks or cusp); 2 bad input (invalid scene, missing or unreadable file, existing
output without --force or in use by another process, a damaged file, a scene ``critical`` cannot handle); 3 an
internal error (a bug: one line asking to report it; ``--debug`` shows the traceback); 130 interrupted (SIGINT or
SIGTERM: ``run``, ``continue`` and ``critical`` stop at the next point and write what is finished, flagged
incomplete; their exit follows the file: 0 when the work had finished before the signal, and they say so). Errors
are one line on stderr, ``balloon-cg: error: ...``.
"""
import argparse
import json
import math
import os
import re
import shlex
import signal
import sys
import threading
from importlib import resources
from pathlib import Path

from .. import __version__
from ..io.output import IMAGE_FORMATS
from ..scene.validation import did_you_mean
from .kernels_cmd import add_kernels

PROG = "balloon-cg"
CURVE_KINDS = ("BP", "LP", "LV", "LN")  # critical --of: the pear pitchfork, the folds in P, V, n
INTERRUPTED = 130  # 128 + SIGINT, the shell's convention
BROKEN_PIPE = 141  # 128 + SIGPIPE: what a tool killed by SIGPIPE reports
PLOT_KINDS = ("pressure-pole", "pressure-equator", "voltage-pole", "voltage-equator", "shapes", "stresses", "field",
              "curvature", "energy", "frequencies", "modes", "phase", "surface", "stretch-map")
# the exceptions that mean bad input (exit 2) or a computation that did not give what was asked (exit 1), by
# module: a module that is not loaded cannot have raised its exception, so none is imported to catch it
BAD_INPUT = {"balloon_cg.scene.validation": "SceneError", "balloon_cg.io.layout": "FileError",
             "balloon_cg.post.plotting": "PlotError", "balloon_cg.model.field": "FieldError",
             "balloon_cg.post.tube_plots": "TubePlotError"}
FAILED = {"balloon_cg.analysis.branches.tracer": "ContinuationError"}


class UsageError(ValueError):
    """A bad command-line value (exit code 2)."""


HDF5_SUFFIXES = (".h5", ".hdf5")


def hdf5_output(path: str, kind: str) -> str:
    """``path`` if its suffix names an HDF5 file (HDF5_SUFFIXES), else UsageError: ``-o results.txt`` would
    write HDF5 under a text file's name (or, with --force, over a text file)."""
    if not path.strip():
        raise UsageError(f"--output {path!r}: an empty path (give a file name ending in .h5)")
    if Path(path).suffix.lower() not in HDF5_SUFFIXES:
        raise UsageError(f"--output {path}: a {kind} file is HDF5: its suffix must be one of "
                         f"{', '.join(HDF5_SUFFIXES)}")
    return path


class Failure(Exception):
    """A computation that ran but did not give what was asked (exit code 1)."""


def main(argv=None) -> int:
    """Run one subcommand; returns the exit code. SIGTERM raises KeyboardInterrupt from the start (exit 130, as
    Ctrl-C; before, a SIGTERM during the imports ended the process with −15); the previous handler is restored
    on return (main called in a process that has its own)."""
    previous = _terminate_raises()
    try:
        return _main(argv)
    except KeyboardInterrupt:  # during argument parsing
        return _error("interrupted", INTERRUPTED)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _terminate_raises():
    """SIGTERM raises KeyboardInterrupt (main thread only); returns the previous handler (None: unchanged)."""
    if threading.current_thread() is not threading.main_thread():
        return None

    def terminate(signum, frame):
        raise KeyboardInterrupt

    return signal.signal(signal.SIGTERM, terminate)


def _main(argv) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser()
    command = next((word for word in argv if not word.startswith("-")), None)
    if command is not None and command not in parser.commands:  # argparse names no near miss before Python 3.14
        return _error(f"{command!r}: not a command{did_you_mean(command, parser.commands)} (choose from "
                      f"{', '.join(parser.commands)}; {PROG} COMMAND -h)", 2)
    args, extra = parser.parse_known_args(argv)
    if extra:  # argparse would print the top-level usage, naming no near miss
        return _error(unrecognized(parser.subcommands[args.command], extra), 2)
    args.command_line = shlex.join([PROG, *argv])
    try:
        return args.handler(args)
    except KeyboardInterrupt:  # before the computation installed its own handler (imports), or a second Ctrl-C
        return _error("interrupted", INTERRUPTED)
    except BrokenPipeError:  # the reader of stdout went away (`| head`): stop quietly, as other Unix tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # the exit's flush must not fail again
        return BROKEN_PIPE
    except (UsageError, *_loaded(BAD_INPUT)) as e:
        return _debug(args) or _error(str(e), 2)
    except OSError as e:
        return _debug(args) or _error(_os_message(e), 2)
    except (Failure, *_loaded(FAILED)) as e:
        return _debug(args) or _error(str(e), 1)
    except Exception as e:  # noqa: BLE001 - a bug: one line and exit 3 (the traceback with --debug)
        return _debug(args) or _error(f"internal error ({type(e).__name__}: {e}); please report it with the "
                                      f"command and the output of `{PROG} --debug ...`", 3)


def unrecognized(command: argparse.ArgumentParser, extra: list[str]) -> str:
    """One line for arguments a command does not take, naming the option nearest the first unknown one."""
    options = [o for action in command._actions for o in action.option_strings]
    unknown = next((word.partition("=")[0] for word in extra if word.startswith("-")), "")
    near = did_you_mean(unknown, options).strip(" ()") if unknown else ""
    return (f"{command.prog.removeprefix(PROG).strip()}: unrecognized arguments: {' '.join(extra)} "
            f"({near + '; ' if near else ''}{command.prog} -h lists its options)")


def _debug(args) -> None:
    """With --debug, re-raise the exception being handled (the traceback instead of one line)."""
    if args.debug:
        raise


def _loaded(classes: dict) -> tuple:
    """The exception classes of ``classes`` ({module: name}) whose modules are loaded."""
    return tuple(getattr(sys.modules[module], name) for module, name in classes.items() if module in sys.modules)


def docs_path(name: str) -> str:
    """Where the installed documentation page docs/``name`` is."""
    return str(resources.files("balloon_cg.docs") / name)


SCENE_HELP = ("scene TOML file of any shape (sphere, spheroid, capsule, tube), or the name of a scene shipped with the "
              "package (spom1, tpom1_two_coils_M0.002, tube_spom1_L10, …: the files in "
              f"{resources.files('balloon_cg.scenes')})")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG, description="Inflated membranes of an axisymmetric reference shape (a sphere, a spheroid, a capsule "
                               "or a tube: [geometry]), in the field of coils or under a voltage: equilibrium "
                               "branches, their bifurcations (a sphere's pear branches, a tube's bulge) and stability. "
                               f"Documentation: {docs_path('')}")
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in (_add_run, _add_solve, _add_inspect, _add_plot, _add_sweep, _add_critical, _add_continue,
                add_kernels, _add_figure, _add_completion):
        add(commands)
    parser.commands = tuple(commands.choices)
    parser.subcommands = dict(commands.choices)
    for name, subcommand in commands.choices.items():
        subcommand.epilog = EXAMPLES_HEADING + "\n".join(f"  {line}" for line in EXAMPLES[name])
        subcommand.formatter_class = ExamplesFormatter
    return parser


EXAMPLES_HEADING = "examples:\n"
EXAMPLES = {  # each subcommand's --help ends with these
    "run": ("balloon-cg run spom1_two_coils_M0.002 -o two_coils.h5",
            "balloon-cg run spom1 --set continuation.stop_stretch=3 --primary-only",
            "balloon-cg run tube_spom1_L10 -o tube.h5"),
    "solve": ("balloon-cg solve spom1 --pole-stretch 2.5 --json", "balloon-cg solve tube_spom1_L10 --hoop-stretch 1.5"),
    "inspect": ("balloon-cg inspect two_coils.h5", "balloon-cg inspect sweep.h5 --json"),
    "plot": ("balloon-cg plot two_coils.h5 --what pressure-pole,shapes -o p.pdf",
             "balloon-cg plot two_coils.h5 --what pressure-pole --stability volume",
             "balloon-cg plot tube.h5 --what pressure-volume,profiles,front --width 3.5 -o tube.pdf"),
    "sweep": ("balloon-cg sweep spom1_two_coils_M0.002 --vary M=0:0.003:num=21 -o sweep.h5",
              "balloon-cg sweep spom1_two_coils_M0.002 --vary 'M=linspace(0, 0.003, 4)' --primary-only --workers 2"),
    "critical": ("balloon-cg critical spom1_single_coil --parameter M -o critical_M.h5",
                 "balloon-cg critical spom1 --parameter alpha1 --set continuation.stop_stretch=3",
                 "balloon-cg critical spom1 --set material.preset=Gent --of LP --parameter material.parameters.Jm "
                 "--direction -1 -o cusp.h5",
                 "balloon-cg critical tube_spom1_L10_coil --parameter M -o onset_M.h5"),
    "continue": ("balloon-cg continue two_coils.h5 3 -o again.h5",
                 "balloon-cg continue gent.h5 2 --parameter material.parameters.Jm --direction -1 -o fold.h5",
                 "balloon-cg continue two_coils.h5 2 --parameter M --set continuation.stop_field=0.004 -o tuning.h5"),
    "kernels": ("balloon-cg kernels spom1 --json",),
    "figure": ("balloon-cg figure fig9 --width 3.5", "balloon-cg figure all -o paper-figures --width 7.2"),
    "completion": ("balloon-cg completion bash > ~/.local/share/bash-completion/completions/balloon-cg",
                   "balloon-cg completion zsh > ~/.zfunc/_balloon-cg"),
}


class ExamplesFormatter(argparse.HelpFormatter):
    """argparse's help, the examples epilog kept one command a line (the other text wrapped as usual)."""

    def _fill_text(self, text, width, indent):
        if text.startswith(EXAMPLES_HEADING):
            return "\n".join(indent + line for line in text.splitlines())
        return super()._fill_text(text, width, indent)


def _error(message: str, code: int) -> int:
    print(f"{PROG}: error: {message}", file=sys.stderr)
    return code


def _os_message(e: OSError) -> str:
    """'FILE: what is wrong', with the nearest name in its folder when the file does not exist."""
    if e.filename is None:
        return str(e)
    near = ""
    if isinstance(e, FileNotFoundError) and Path(e.filename).parent.is_dir():
        folder = Path(e.filename).parent
        near = did_you_mean(e.filename, [str(folder / p.name) for p in folder.iterdir()])
    return f"{e.filename}: {e.strerror or e}{near}"


# --- run ---------------------------------------------------------------------------------------------------

def _add_run(commands):
    p = commands.add_parser("run", help="analyse a scene of any shape (primary branch, stability, branch points and "
                                        "the branches switched there: a sphere's pear branches, a tube's bulges) and "
                                        "write a run file")
    p.add_argument("scene", help=SCENE_HELP)
    p.add_argument("-o", "--output", help="run file to write (HDF5; default: SCENE_NAME.h5 in the current folder, "
                                          "with a token per --set, --unset: SCENE_NAME_stop_stretch3.h5)")
    _add_settings(p)
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.add_argument("--quiet", action="store_true", help="no progress bar and no summary")
    p.add_argument("--primary-only", action="store_true",
                   help="trace the primary branch only (no stability, branch points or switched branches)")
    p.add_argument("--allow-partial", action="store_true",
                   help="exit 0 also when the result is incomplete (it is still flagged in the file and on stderr)")
    p.set_defaults(handler=run)


def _add_settings(p, shorthands: bool = True):
    """--set, --unset and (``shorthands``) the continuation limits AUTO users expect on the command line, all
    validated like the TOML."""
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="settings",
                   help="override a scene key (dotted, e.g. field.M=0.003, field.coils[0].radius=2.5, "
                        "material.preset=TPOM1; a bare name of one table: M=0.003); repeatable")
    p.add_argument("--unset", action="append", default=[], metavar="KEY",
                   help="restore a scene key to its default (e.g. continuation.stop_stretch); repeatable")
    if not shorthands:
        return
    for flag, key, metavar in (("--max-points", "max_points", "N"), ("--stop-stretch", "stop_stretch", "X"),
                               ("--stop-pressure", "stop_pressure", "P")):
        p.add_argument(flag, dest=key, metavar=metavar, help=f"continuation.{key} (as --set continuation.{key}=…)")


def scene_of(args):
    """The scene file with the command line's --set, --unset and continuation limits applied (renamed after them).
    A key given twice (also as a bare name and dotted, or by --set and its shorthand flag) is refused."""
    return configured(args)[0]


def configured(args):
    """(scene, stem): ``scene_of``'s scene and the stem of its default output file, its name with a token for
    each setting the name does not show (scene.tables.output_stem: ``spom1_stop_stretch3``)."""
    from ..scene import load_scene
    from ..scene.tables import output_stem

    scene, overrides = _with_settings(args, load_scene(args.scene))
    return scene, output_stem(scene.name, overrides)


def default_output(given: str | None, stem: str, kind: str) -> str:
    """``-o`` as given (an HDF5 name: ``hdf5_output``), or STEM.h5 in the current folder. Either way an existing
    file is replaced only with --force (io.output, the one rule)."""
    return hdf5_output(given, kind) if given is not None else f"{stem}.h5"


def _with_settings(args, scene):
    """(scene with the settings applied, {canonical key: value (None: --unset)})."""
    from ..scene import SceneError

    shorthands = [f"continuation.{key}={getattr(args, key)}" for key in ("max_points", "stop_stretch", "stop_pressure")
                  if getattr(args, key, None) is not None]
    settings = list(args.settings) + shorthands
    if not settings and not args.unset:
        return scene, {}
    from .sweep import SweepError, overridden, parse_vary

    for text in settings:
        key, sep, value = (part.strip() for part in text.partition("="))
        if not sep or not key or not value:
            raise UsageError(f"--set {text}: expected KEY=VALUE, e.g. --set field.M=0.003 (--unset KEY restores "
                             "the default)")
        if "," in value or ":" in value:
            raise UsageError(f"--set {text}: one value per key (sweep --vary takes lists and ranges)")
    try:
        overrides = {}
        for text in settings:
            key, values = parse_vary(text, scene)
            if key in overrides:
                raise UsageError(f"--set {text}: {key} is given twice (by --set or a shorthand flag): give it once")
            overrides[key] = values[0]
        for text in args.unset:
            key = scene.canonical_key(text.strip())
            if key in overrides:
                raise UsageError(f"--unset {text}: {key} is also given a value: give one of the two")
            overrides[key] = None
    except SweepError as e:
        raise UsageError(str(e).replace("--vary", "--set")) from None
    except SceneError as e:
        raise UsageError(f"--unset {e}") from None
    return overridden(scene, overrides), overrides


def axisymmetric(scene, command: str):
    """``scene``, refused (exit 2) before any work by a ``command`` that works on axisymmetric primary branches
    only when a coil is not coaxial (``run`` traces such a scene on the whole sphere)."""
    if not scene.field.is_axisymmetric:
        k, coil = next((k, c) for k, c in enumerate(scene.field.coils) if not c.is_coaxial)
        raise UsageError(f"coil {k} is not coaxial (centre {list(coil.centre)}, normal {list(coil.normal)}): {command} "
                         "works on axisymmetric fields only; run traces this scene on the whole sphere")
    return scene


def run(args) -> int:
    """Analyse, write, read back and summarise; exit 130 when a signal stopped the work (what is finished is written,
    flagged interrupted: the message is the file's; a signal while the scene loaded: nothing is written), or the
    run's own status when it had finished (and says so). From the scene's load on a signal only sets the flag
    (``stop_on_signals``, as ``continue``): no KeyboardInterrupt is raised that a finalizer could swallow."""
    from ..numerics.interrupt import requested, stop_on_signals

    with stop_on_signals():
        from ..io.run_file import read_run
        from .progress import shown

        scene, stem = configured(args)
        output = default_output(args.output, stem, "run")
        if requested():  # while the scene loaded: nothing computed
            return curve_interrupted_status(None, output, True, "the work had not started")
        if scene.geometry.shape != "tube":
            _, found = run_scene(scene, output, args.force, progress=shown(args.quiet), command=args.command_line,
                                 primary_only=args.primary_only)
            summary = None if args.quiet or requested() else read_run(output)
            signalled = requested()
    if scene.geometry.shape == "tube":
        from .tube_commands import run_tube

        return run_tube(scene, output, args)  # under its own stop_on_signals (app/tube_commands.py)
    code = interrupted_status(found, output, signalled)
    if code is not None:
        return code
    if summary is not None and not signalled:
        from .summaries import format_run

        print(format_run(summary))
    return verdict_status(found, args.allow_partial)


def interrupted_status(found: list, output, signalled: bool) -> int | None:
    """130 when a signal stopped the work of a written run file (``found``, its Incomplete entries: the line names
    the file's interrupted entry, so that the message and the file agree); else None, having said so when a signal
    came once the work had finished (``signalled``: the file is whole)."""
    from ..analysis.verdict import Gap

    stopped = [item for item in found if item.gap == Gap.INTERRUPTED]
    if stopped:
        print(f"{PROG}: interrupted ({stopped[-1].branch}: {stopped[-1].message}); what was finished is written to "
              f"{output} (flagged incomplete)", file=sys.stderr)
        return INTERRUPTED
    if signalled:
        print(f"{PROG}: a signal arrived once the work had finished: {output} is written whole", file=sys.stderr)
    return None


def curve_interrupted_status(curve, output, signalled: bool, before: str = "the curve had not started") -> int | None:
    """``interrupted_status`` of a two-parameter curve: 130 when its file says a signal ended it (end
    ``interrupted``; ``curve`` None: ``before`` it started, nothing is written); else None, having said so when a
    signal came once it had ended."""
    from ..analysis.critical.pitchfork_curve import CurveEnd

    if curve is None or curve.end == CurveEnd.INTERRUPTED:
        written = (f"nothing is written to {output} ({before})" if curve is None else
                   f"the curve is written to {output} (end: {curve.end.value}, {len(curve.q)} points)")
        print(f"{PROG}: interrupted: {written}", file=sys.stderr)
        return INTERRUPTED
    if signalled:
        print(f"{PROG}: a signal arrived once the work had finished: {output} is written whole", file=sys.stderr)
    return None


def verdict_status(found: list, allow_partial: bool) -> int:
    """Exit status of a written result: 0 when complete (or ``allow_partial``), else 1 with the incomplete
    parts on stderr (one line)."""
    from ..analysis.verdict import failing, summary_line

    if not failing(found):
        return 0
    print(f"{PROG}: {summary_line(found)}", file=sys.stderr)
    return 0 if allow_partial else 1


def run_scene(scene, out_path, force: bool = False, progress: bool = False, command: str | None = None,
              primary_only: bool = False) -> tuple[Path, list]:
    """Analyse ``scene`` (primary branch, stability, branch points, pear branches, snap-throughs; or only the
    primary branch) and write the run file ``out_path``; returns the path and what is incomplete
    (analysis.verdict.Incomplete entries, empty when the result is complete).

    The output is checked before the trace (which may take long); ``progress`` shows one bar per phase on
    stderr; ``command`` overrides the provenance attribute (default: sys.argv).
    """
    from ..io.output import check_output
    from ..io.lock import claim
    from ..io.run_file import write_run
    from .api import computed

    with claim(out_path, "run"):
        check_output(out_path, force)
        branches, snaps, found, picture, clock = computed(scene, primary_only, progress=progress)
        extra = {} if command is None else {"command": command}
        return write_run(out_path, scene, branches, force=force, extra_attrs=extra, snaps=snaps, found=found,
                         clock=clock, meridian_surface=picture and picture.meridian_surface), found


# --- solve -------------------------------------------------------------------------------------------------

def _add_solve(commands):
    p = commands.add_parser("solve", help="one equilibrium on the primary branch at a given north pole stretch (a "
                                          "sphere, spheroid or capsule) or hoop stretch at a tube's middle")
    p.add_argument("scene", help=SCENE_HELP)
    given = p.add_mutually_exclusive_group(required=True)
    given.add_argument("--pole-stretch", type=float, metavar="X",
                       help="north pole stretch λ2(0) (> 1; a sphere, spheroid or capsule)")
    given.add_argument("--hoop-stretch", type=float, metavar="X",
                       help="a tube's hoop stretch at its middle λ2(L/2) (> 1; docs/tubes.md)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    _add_settings(p, shorthands=False)
    p.set_defaults(handler=solve)


def solve(args) -> int:
    """Trace the primary branch up to the requested north pole stretch and report its end point."""
    import numpy as np

    from ..analysis.branches.primary import trace_primary
    from ..analysis.results import StopCode
    from .summaries import format_table

    scene = axisymmetric(scene_of(args), "solve")
    if (scene.geometry.shape == "tube") != (args.hoop_stretch is not None):
        given = "--pole-stretch" if args.hoop_stretch is None else "--hoop-stretch"
        wanted = "a tube has no pole: give --hoop-stretch X (λ2 at its middle)" if args.hoop_stretch is None else \
            "the hoop stretch at a tube's middle: give --pole-stretch X for this shape"
        raise UsageError(f"solve {args.scene}: {given}: {wanted}")
    if args.hoop_stretch is not None:
        return solve_tube(scene, args)
    x = args.pole_stretch
    if not np.isfinite(x) or x <= 1:
        raise UsageError(f"--pole-stretch = {x:g}: must be > 1 (λ2(0) = 1 is the undeformed sphere)")
    if x <= scene.continuation.start_stretch:  # traced upwards from a start below x, halfway from the sphere
        scene = scene.with_overrides({"continuation.start_stretch": (1 + x) / 2, "continuation.min_stretch": None})
    branch = trace_primary(scene, stop_stretch=x, down=False)
    if branch.legs[0].stop.code != StopCode.STOP_STRETCH:
        reached = branch.pole_values()["lam2_top"].max()
        raise Failure(
            f"the primary branch did not reach north pole stretch {x:g} ({branch.stop_reason}); "
            f"largest stretch reached: {reached:.10g}"
        )
    result = solution(branch, -1)
    print(strict_json(result) if args.json else format_table(result | {"wall_time": f"{result['wall_time']:.3f} s"}))
    return 0


def solve_tube(scene, args) -> int:
    """``solve`` on a tube: the primary branch's state with the hoop stretch --hoop-stretch at its middle
    (tube/point.py), reported as ``solve`` reports a sphere's."""
    import time

    import numpy as np

    from ..scene.tables import MAX_STRETCH
    from ..tube.point import NotReached, point_at_middle_hoop, tube_solution
    from .summaries import format_table

    x = args.hoop_stretch
    if scene.continuation.parameter == "voltage":
        raise UsageError('solve on a tube: the state at a hoop stretch is solved on the pressure continuation; the '
                         'scene continues in the voltage (continuation.parameter = "voltage")')
    if not np.isfinite(x) or not 1 < x <= MAX_STRETCH:
        raise UsageError(f"--hoop-stretch = {x:g}: must be in (1, {MAX_STRETCH:g}] (1 is the undeformed tube)")
    clock = time.perf_counter()
    try:
        point = point_at_middle_hoop(scene, x)
    except NotReached as e:
        raise Failure(str(e)) from None
    result = tube_solution(point) | {"wall_time": time.perf_counter() - clock}
    print(strict_json(result) if args.json else format_table(result | {"wall_time": f"{result['wall_time']:.3f} s"}))
    return 0


def solution(branch, i: int) -> dict:
    """The reported quantities of point i of a branch."""
    import numpy as np

    from ..galerkin.profiles import equator_values

    X = branch.X[i]
    values = {"pressure": X[-1], **branch.pole_values(X), **equator_values(branch.disc, X, branch.scene.geometry)}
    return {
        **{k: float(np.squeeze(v)) for k, v in values.items()},
        "residual": float(branch.residual[i]),
        "error_estimate": float(branch.error_estimate[i]),
        "wall_time": branch.wall_time,
    }


# --- inspect -----------------------------------------------------------------------------------------------

def _add_inspect(commands):
    p = commands.add_parser("inspect", help="summary of a run (of any shape), sweep or curve file")
    p.add_argument("file", help="run file (of any shape, a tube's too), sweep or two-parameter curve file (HDF5)")
    p.add_argument("--json", action="store_true", help="print one JSON object (strict: null for NaN)")
    p.set_defaults(handler=inspect)


def inspect(args) -> int:
    """Print the summary of a run, sweep or curve file."""
    from .summaries import summarise_file

    summary, text = summarise_file(args.file)
    print(strict_json(summary) if args.json else text)
    return 0


def strict_json(value) -> str:
    """JSON that strict parsers accept: NaN and ±inf as null, numpy scalars and arrays as numbers and lists."""
    return json.dumps(_finite(value), allow_nan=False)


def _finite(value):
    if isinstance(value, dict):
        return {str(k): _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if hasattr(value, "tolist"):  # numpy scalar or array
        listed = value.tolist()
        return _finite(listed) if type(listed) is not type(value) else str(value)  # a long double lists itself
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


# --- plot --------------------------------------------------------------------------------------------------

def _add_plot(commands):
    p = commands.add_parser("plot", help=f"draw figures from one or more run files ({docs_path('plots.md')})")
    p.add_argument("files", nargs="+", metavar="FILE",
                   help="run files (HDF5); several: one curve set per file (a tube's run file: one, alone)")
    p.add_argument("--what", required=True, type=_kinds, metavar="KIND[,KIND...]",
                   help=f"what to draw, one figure per kind: {', '.join(PLOT_KINDS)}; of a tube's run file: "
                        "pressure-volume, profiles, front, stretches, modes, onset (docs/tubes.md)")
    p.add_argument("-o", "--output", help=f"image file, {', '.join(IMAGE_FORMATS)} (default: "
                                          "FIRST_FILE_STEM_KIND.png next to the first file; with several kinds: "
                                          "OUTPUT_STEM_KIND.SUFFIX; an existing file is replaced only with --force)")
    p.add_argument("--force", action="store_true", help="replace existing image files")
    p.add_argument("--points", type=_indices, metavar="I,J,K",
                   help="point indices for shapes, stresses, field, curvature and a tube's profiles, front, "
                        "stretches (negative: from the end); one index for surface and stretch-map (default: point 1 "
                        "of the surface branch); a tube's modes: indices of the located m >= 1 zeros")
    p.add_argument("--branch", metavar="NAME",
                   help="branch to draw (default: every branch for pressure-*, energy and a tube's "
                        "pressure-volume, the first surface branch for surface and stretch-map, a tube's bulge for "
                        "its other kinds, primary for the others)")
    p.add_argument("--stability", default=None, metavar="READING",
                   help="what solid (stable) and dashed (unstable) mean: pressure (held at the centre, pressure "
                        "control), volume, gas, free, free-volume, free-gas, or axisymmetric (the paper's: m = 0 "
                        "modes only); a tube's: pressure, volume or gas; default: the run's loading.control, held")
    p.add_argument("--width", type=float, metavar="INCHES",
                   help="figure width in inches, its height in proportion (a journal's: 3.5 one column, "
                        "7.2 two; default: each kind's own, 6.4 to 12, a tube's 3.5); titles and legends fitted "
                        "to it")
    p.add_argument("--dpi", type=int, metavar="N", help="resolution of PNG, JPEG and TIFF images (default: the "
                                                        "journal style's 300)")
    p.set_defaults(handler=plot)


def _kinds(text: str) -> list[str]:
    from ..post.tube_plots import TUBE_KINDS

    kinds, known = [k.strip() for k in text.split(",")], PLOT_KINDS + TUBE_KINDS
    unknown = [k for k in kinds if k not in known]
    if unknown:
        raise argparse.ArgumentTypeError(f"{unknown[0]!r}: not a plot kind{did_you_mean(unknown[0], known)} "
                                         f"(choose from {', '.join(known)})")
    return kinds


MAX_DRAWN_POINTS = 100  # --points: shapes drawn in one figure (20,000 took over a minute to draw)


def _indices(text: str) -> list[int]:
    items = text.split(",")
    if len(items) > MAX_DRAWN_POINTS:
        raise argparse.ArgumentTypeError(f"{len(items)} point indices: at most {MAX_DRAWN_POINTS} in one figure")
    try:
        return [int(item) for item in items]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text[:40]!r}: expected comma-separated integers, e.g. 0,10,-1") from None


def plot(args) -> int:
    """Draw one figure per kind and save it; prints the image paths."""
    from ..io.layout import file_kind
    from ..io.output import check_output, replacing
    from ..post.plotting import as_run, plot as draw

    first = Path(args.files[0])
    outputs = {}
    for kind in args.what:
        if args.output is None:
            outputs[kind] = first.with_name(f"{first.stem}_{kind}.png")
        else:
            given = Path(args.output)
            outputs[kind] = given if len(args.what) == 1 else given.with_name(f"{given.stem}_{kind}{given.suffix}")
    for output in outputs.values():
        if output.suffix.lower() not in IMAGE_FORMATS:
            raise UsageError(f"--output {output}: the suffix must be one of {', '.join(IMAGE_FORMATS)}")
        check_output(output, args.force)
    if file_kind(first) == "tube":
        return _plot_tube(args, outputs)
    runs = [as_run(f) for f in args.files] if any(kind != "phase" for kind in args.what) else []
    for kind, output in outputs.items():
        figure = draw(args.files if kind == "phase" else runs, kind, args.points, args.branch,
                      stability=args.stability, width=args.width)
        with replacing(output, args.force) as tmp:
            figure.savefig(tmp, format=output.suffix.lower()[1:], **({} if args.dpi is None else {"dpi": args.dpi}))
        print(output)
    return 0


def _plot_tube(args, outputs: dict) -> int:
    """``plot`` of a tube run file (post/tube_plots.py): one file, post/tube_plots.TUBE_KINDS."""
    from ..io.output import replacing
    from ..io.tube_file import read_tube_run
    from ..post.tube_plots import tube_figure

    if len(args.files) > 1:
        raise UsageError(f"{args.files[1]}: a tube run file is drawn alone; give one file")
    run = read_tube_run(args.files[0])
    for kind, output in outputs.items():
        figure = tube_figure(run, kind, args.stability, args.branch, args.points,
                             args.width or 3.5)
        with replacing(output, args.force) as tmp:
            figure.savefig(tmp, format=output.suffix.lower()[1:], **({} if args.dpi is None else {"dpi": args.dpi}))
        print(output)
    return 0


# --- figure ------------------------------------------------------------------------------------------------

def _add_figure(commands):
    """``figure``: one figure of the paper, or all of them (app.figures, docs/paper.md)."""
    p = commands.add_parser("figure", help=f"draw a figure of the paper, computing its runs ({docs_path('paper.md')})")
    p.add_argument("name", help="fig2 .. fig13, or all (then --output is a folder)")
    p.add_argument("-o", "--output",
                   help=f"image file ({', '.join(IMAGE_FORMATS)}), or the folder for all (default: NAME.pdf in the "
                        "current folder; for all, the folder paper-figures)")
    p.add_argument("--runs", metavar="FOLDER", help="where run files are kept and reused (default: OUTPUT's folder/runs)")
    p.add_argument("--width", type=float, default=7.2, metavar="INCHES", help="figure width (3.5 one column, 7.2 two)")
    p.add_argument("--stability", default="pressure", metavar="READING", help="as for plot")
    p.add_argument("--quick", action="store_true", help="reduced runs (few points, low degree, one M): for tests")
    p.add_argument("--force", action="store_true", help="replace existing image files (the runs folder is a cache: "
                                                        "its runs are reused or recomputed without it)")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.add_argument("--allow-partial", action="store_true", help="exit 0 also when a run drawn is incomplete")

    def figure(args) -> int:
        from .figures import FigureError, command

        try:
            return command(args)
        except FigureError as e:
            raise UsageError(str(e)) from None

    p.set_defaults(handler=figure)


# --- completion --------------------------------------------------------------------------------------------

COMPLETION_SHELLS = ("bash", "zsh", "tcsh")
PATH_ARGUMENTS = ("scene", "file", "files", "output", "runs")  # completed as file names


def _add_completion(commands):
    p = commands.add_parser("completion", help="print the shell completion script of balloon-cg (shtab)",
                            description="Print a completion script for the shell: subcommands, options, choices "
                                        "and file names complete with TAB. bash: save it as "
                                        "~/.local/share/bash-completion/completions/balloon-cg; zsh: as _balloon-cg "
                                        "in a folder of $fpath.")
    p.add_argument("shell", choices=COMPLETION_SHELLS)
    p.set_defaults(handler=completion)


def completion(args) -> int:
    """The completion script of the whole parser (shtab), the arguments that name files completed as files."""
    import shtab

    parser = build_parser()
    for subcommand in parser.subcommands.values():
        for action in subcommand._actions:
            if action.dest in PATH_ARGUMENTS:
                action.complete = shtab.FILE
    print(shtab.complete(parser, args.shell))
    return 0


# --- critical ----------------------------------------------------------------------------------------------

def _add_critical(commands):
    p = commands.add_parser(
        "critical", help="continue the first pear pitchfork in a second parameter (M, alpha1, a material parameter; "
                         "two-parameter continuation) and report the critical value where the isola's two "
                         "pitchforks merge; on a tube, the onset of bulging in M, the voltage or the held axial stretch",
        description="Trace the primary branch, locate its first pear-shaped pitchfork and follow it in the second "
                    "parameter: any runtime parameter of the scene's kernels, named by its scene key (field.M or M, "
                    "field.chi, material.parameters.Jm, material.mu[0], material.alpha[0]) or alpha1 (with mu1 "
                    "keeping sum mu_i alpha_i = 4); an unknown name lists the scene's. With --of LP, LV or LN: its "
                    "first fold in P, V or n instead, to the cusp where the fold curve turns back. "
                    "Exit 0: the two pitchforks merge at P > 0 and the curve returns to the partner pitchfork, or "
                    "the fold curve ends in a cusp (critical value printed). Exit 1: the computation gave no critical "
                    "value (no pear pitchfork or fold, or the curve ended otherwise: one line says how and where; the "
                    "curve file is still written). Exit 2: a scene this command cannot handle (--of BP: not "
                    "equator-symmetric; --parameter M without coils), a parameter the scene does not have, or bad "
                    "input. On a tube: its first odd branch point, the onset of bulging, followed in M, the voltage or "
                    "axial_stretch (the ends held apart at λL; --of BP only), written with the primary branch to a "
                    "tube run file; exit 0 where the onset "
                    "turns back in the parameter (its largest or smallest value printed), 1 where it does not "
                    "(docs/tubes.md).")
    p.add_argument("scene", help=f"{SCENE_HELP}; with --of BP equator-symmetric: coils mirror-symmetric about z = 0")
    p.add_argument("--parameter", required=True, help="the second parameter (a scene key, e.g. M, alpha1, "
                                                       "material.parameters.Jm, voltage; on a tube M, voltage or "
                                                       "axial_stretch: its onset of bulging followed)")
    p.add_argument("--of", default="BP", choices=CURVE_KINDS, metavar="KIND",
                   help="what to follow: BP (the first pear pitchfork, default), LP (the first fold in P: the "
                        "snap-through boundary, ending in its cusp), LV or LN (the first fold in the volume or in the "
                        "gas amount: volume or gas control)")
    p.add_argument("--direction", type=float, choices=(1.0, -1.0), default=1.0,
                   help="start with the parameter increasing (1, default) or decreasing (-1)")
    p.add_argument("-o", "--output", help="curve file to write (HDF5; plot it with --what phase; default: "
                                          "SCENE_NAME_critical_PARAMETER.h5 in the current folder, tokens as run's)")
    _add_settings(p)
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
    scene the command cannot handle, checked before any computation: a voltage continuation (the curve lives in
    (q, P)), not equator-symmetric (the pear block needs the equator-symmetric layout), ``--parameter M`` without
    coils, or a parameter the scene's kernels do not take (one line listing those they do:
    ``analysis.critical.second_parameter``). 130 interrupted (SIGINT or SIGTERM, as ``run``): the work stops at its next
    point (or phase); a curve already started is written (atomically, end ``interrupted``), before it nothing is;
    the exit follows the file (a curve that had ended when the signal came: its own status, and a line saying so).
    Progress goes to stderr (``--quiet``: none).
    """
    from ..io.lock import claim
    from ..numerics.interrupt import requested, stop_on_signals

    with stop_on_signals():  # from the scene's load on, as run
        scene, stem = configured(args)
        axisymmetric(scene, "critical")
        short = re.sub(r"[^A-Za-z0-9.+-]+", "", args.parameter.split(".")[-1])
        if scene.geometry.shape != "tube":
            args.output = default_output(args.output, f"{stem}_critical_{short}", "curve")
            with claim(args.output, "critical"):  # owned from here: no other process writes it meanwhile
                return _critical(args, scene)
        output = default_output(args.output, f"{stem}_critical_{short}", "tube")
        if requested():  # while the scene loaded: nothing computed
            return curve_interrupted_status(None, output, True, "the work had not started")
    from .tube_commands import critical_tube

    return critical_tube(scene, output, args)  # under its own stop_on_signals (app/tube_commands.py)


def _critical(args, scene) -> int:
    """``critical`` on ``scene`` into ``args.output`` (owned, under ``stop_on_signals``)."""
    from ..analysis.critical.pitchfork_curve import CODIM2_ENDS, CurveEnd
    from ..analysis.results import Status
    from ..analysis.critical.second_parameter import UnknownParameter, resolve
    from ..io.curve_file import write_curve
    from ..io.output import check_output
    from ..numerics.interrupt import Interrupted, requested
    from ..scene import ContinuationParameter

    asymmetry = _asymmetry(scene)
    if asymmetry and args.of == "BP":
        raise UsageError(f"critical needs an equator-symmetric scene: {args.scene}: {asymmetry}")
    if scene.continuation.parameter != ContinuationParameter.PRESSURE:
        raise UsageError(f"critical needs a pressure continuation: {args.scene}: continuation.parameter = "
                         f"{scene.continuation.parameter.value!r} (the curve of pitchforks is traced in (q, P); "
                         "continue P at a fixed electric.voltage instead)")
    field_needed(scene, args.parameter, "critical --parameter M", args.scene)
    try:
        resolve(scene, args.parameter)
    except UnknownParameter as e:
        raise UsageError(f"critical --parameter {args.parameter}: {args.scene}: {e}") from None
    check_output(args.output, args.force)
    if requested():  # while the scene and its kernels loaded: nothing computed
        return curve_interrupted_status(None, args.output, True, "the work had not started")
    try:
        curve = (_pitchfork_curve if args.of == "BP" else _fold_curve)(scene, args)
    except Interrupted:  # in a unit that polls inside (a plain degree's search) before the curve started
        curve = None
    if curve is not None:
        write_curve(args.output, scene, curve, name=curve_group(curve), force=args.force,
                    extra_attrs={"command": args.command_line})
    code = curve_interrupted_status(curve, args.output, requested())  # what the file says, not the flag
    if code is not None:
        return code
    _say(args, f"curve: {len(curve.q)} points, ended: {curve.end.value}")
    if curve.end not in CODIM2_ENDS:
        raise Failure(f"no critical {curve.parameter}: {curve.describe()}; curve (end: {curve.end.value}) still "
                      f"written to {args.output}")
    q, P, stretch = curve.critical
    merge, what = curve.merge, "cusp" if curve.end == CurveEnd.CUSP else "merge of the pitchforks"
    if merge.status != Status.LOCATED:
        raise Failure(f"the {what} near {curve.parameter} = {q:.8g} is only approximately located "
                      f"(±{merge.uncertainty:.1g}: {merge.reason}); curve written to {args.output}")
    print(f"critical {curve.parameter} = {q:.12g} (P = {P:.10g}, pole stretch {stretch:.10g}; {what}); "
          f"curve written to {args.output}{curve.describe_meetings()}")
    return 0


def field_needed(scene, parameter: str, what: str, where: str) -> None:
    """UsageError (exit 2, before any work) for a second parameter M on a scene without coils: the equilibrium
    does not depend on M (``critical`` and ``continue`` alike)."""
    if parameter in ("M", "field.M") and not scene.field.coils:
        raise UsageError(f"{what} needs coils: {where} has no [[field.coils]], so the equilibrium does not depend "
                         "on M")


def _say(args, text: str) -> None:
    """A progress line of ``critical`` on stderr (none with --quiet)."""
    if not args.quiet:
        print(f"{PROG} critical: {text}", file=sys.stderr)


def _primary(scene, args):
    """The primary branch ``critical`` starts from (None when a signal stopped it)."""
    from ..analysis.branches.primary import trace_primary
    from ..numerics.interrupt import requested
    from .progress import auto_tqdm, shown, tqdm_disable

    bar = auto_tqdm()(desc="primary branch", unit=" points", disable=tqdm_disable(shown(args.quiet)), file=sys.stderr)
    with bar:
        branch = trace_primary(scene, progress=lambda point: bar.update())
    return None if requested() else branch


def _curve_bar(args):
    """The progress bar of a two-parameter curve."""
    from .progress import auto_tqdm, shown, tqdm_disable

    return auto_tqdm()(desc=f"curve in {args.parameter}", unit=" points", disable=tqdm_disable(shown(args.quiet)),
                       file=sys.stderr)


def _pitchfork_curve(scene, args):
    """``critical``'s computation: the primary branch, its first pear pitchfork located, the curve of pitchforks
    in ``args.parameter`` (analysis.critical.pitchfork_curve). None when a signal (numerics.interrupt) stopped the work before the
    curve started; a signal during the curve ends it at its next point (end ``interrupted``)."""
    from ..analysis.points.branch_points import detect, locate
    from ..analysis.critical.pitchfork_curve import TwoParameterError, continue_branch_point
    from ..analysis.results import Block, Status
    from ..analysis.stability.axisymmetric import assess_branch
    from ..numerics.interrupt import Interrupted, requested

    branch = _primary(scene, args)
    if branch is None:
        return None
    _say(args, f"primary branch: {len(branch.X)} points ({branch.stop_reason}); assessing the pear block")
    try:
        assessments, _ = assess_branch(branch, scene.stability.degree)
    except Interrupted:
        return None
    pear = [event for event in detect(branch, assessments) if event[1] == Block.ODD_HELD]
    if not pear:
        raise Failure(f"no pear-shaped pitchfork on the primary branch of {args.scene} ({branch.stop_reason}): "
                      f"nothing to continue in {args.parameter}")
    _say(args, f"locating the first pear pitchfork (of {len(pear)})")
    bp = locate(branch, *pear[0])
    if requested():
        return None
    if bp.status != Status.LOCATED:
        _say(args, f"the pear pitchfork is only approximately located (±{bp.uncertainty:.1g}: {bp.reason})")
    _say(args, f"pear pitchfork at P = {bp.X[-1]:.10g}; continuing it in {args.parameter}")
    try:
        with _curve_bar(args) as bar:
            return continue_branch_point(branch, bp, args.parameter, args.direction,
                                         progress=lambda point: bar.update())
    except TwoParameterError as e:
        raise Failure(f"the curve of pitchforks in {args.parameter} could not start: {e}") from None


def curve_group(curve) -> str:
    """The group of a two-parameter curve in its file: ``pear`` (pitchforks; ``pear_free``: the free balloon's),
    else its kind (LP, LV, LN)."""
    if curve.of.value != "BP":
        return curve.of.value
    return "pear_free" if curve.block.value == "odd_free" else "pear"


FOLD_CONTROL = {"LP": "pressure", "LV": "volume", "LN": "gas"}  # the loading.control whose folds --of follows


def _fold_curve(scene, args):
    """``critical --of LP|LV|LN``: the primary branch traced under the control of that fold (loading.control
    pressure, volume or gas), its first located fold of that kind, the fold curve in ``args.parameter``
    (analysis.critical.fold_curve). None when a signal stopped the work before the curve started."""
    from ..analysis.critical.pitchfork_curve import TwoParameterError
    from ..analysis.critical.fold_curve import continue_fold
    from ..analysis.results import Kind, Status

    control = FOLD_CONTROL[args.of]
    if scene.loading.control.value != control:
        scene = scene.with_overrides({"loading.control": control, "loading.stop_amount": None}, name=scene.name)
    branch = _primary(scene, args)
    if branch is None:
        return None
    folds = [s for s in branch.special if s.kind == Kind(args.of)]
    if not folds:
        raise Failure(f"no {args.of} fold on the primary branch of {args.scene} ({branch.stop_reason}): nothing to "
                      f"continue in {args.parameter}")
    fold = folds[0]
    if fold.status != Status.LOCATED:
        _say(args, f"the {args.of} fold is only approximately located (±{fold.uncertainty:.1g}: {fold.reason})")
    _say(args, f"primary branch: {len(branch.X)} points; {args.of} fold at P = {fold.X[-1]:.10g}; continuing it in "
               f"{args.parameter}")
    try:
        with _curve_bar(args) as bar:
            return continue_fold(branch, fold, args.parameter, args.direction, progress=lambda point: bar.update())
    except TwoParameterError as e:
        raise Failure(f"the {args.of} curve in {args.parameter} could not start: {e}") from None


# --- continue ----------------------------------------------------------------------------------------------

def _add_continue(commands):
    p = commands.add_parser(
        "continue", help="restart from a labelled special point of a run file (inspect shows the labels)",
        description="Restart from the special point LABEL of a run file: without --parameter (or with the "
                    "branch's own, P) the branch through it is traced again in both directions (a run file with one "
                    "branch, primary; assessed and its branch points located if the stored branch was), "
                    "and at a branch point of an equator-symmetric branch the branches bifurcating there instead "
                    "(a pear point, held or free: the pear branch and its mirror image; a held m >= 1 point: the "
                    "non-axisymmetric branch and its other direction; a run file of those, assessed as run "
                    "assesses them, after the branch of the point as read); with --parameter KEY (a scene "
                    "key, as for critical) from a fold (LP, LV, LN) the fold curve in KEY and its cusp, from a "
                    "pear pitchfork (BP odd_held or odd_free) the curve of pitchforks and the isola's critical "
                    "value (a curve file), from another point (UZ, EP, TP) with --parameter M or voltage the branch "
                    "through it in that parameter at its fixed P (a run file of one branch, assessed as the stored "
                    "one was, with [dynamics] its frequencies: tuning curves, docs/dynamics.md); from a located "
                    "point of a held tube's primary branch (not an even BP) with --parameter axial_stretch the tube "
                    "through it in the held distance of its ends at its fixed P (docs/tubes.md). Exit 0: written (a run file: and complete); 1: the computation did not "
                    "give it (the curve or no switched branch started; a run file written but incomplete, as run: "
                    "--allow-partial exits 0); 2: bad input (no such label, a label or parameter this does not "
                    "continue yet: an even or free m >= 1 BP, an even or m >= 1 BP in a second parameter, a "
                    "surface branch).")
    p.add_argument("run", metavar="RUN", help="run file (HDF5) written by balloon-cg run (a tube's: from the onset "
                                              "of bulging, the bulge branch or with --parameter M its onset curve, "
                                              "docs/tubes.md)")
    p.add_argument("label", type=int, help="the special point's label (balloon-cg inspect RUN lists them)")
    p.add_argument("--parameter", help="continue in this parameter (default: the branch's own, P; from a point "
                                       "that is no fold or BP: M or voltage, at its fixed P; a held tube's "
                                       "located point: axial_stretch, at its fixed P)")
    p.add_argument("--direction", type=float, choices=(1.0, -1.0), default=1.0,
                   help="a fold curve: start with the parameter increasing (1, default) or decreasing (-1)")
    p.add_argument("-o", "--output", help="run or curve file to write (HDF5; default: RUN_label<LABEL>.h5 in the "
                                          "current folder, RUN_label<LABEL>_<KEY>.h5 with --parameter KEY)")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.add_argument("--allow-partial", action="store_true",
                   help="exit 0 also when the run file written is incomplete (it is still flagged in the file and "
                        "on stderr)")
    _add_settings(p)
    p.set_defaults(handler=continue_run)


def continue_run(args) -> int:
    """``continue``: the labelled point found, restarted (``app.restart``), written (the output owned meanwhile)."""
    from ..io.lock import claim

    from ..io.layout import file_kind

    parameter = "" if args.parameter is None else "_" + re.sub(r"[^A-Za-z0-9.+-]+", "", args.parameter.split(".")[-1])
    args.output = default_output(args.output, f"{Path(args.run).stem}_label{args.label}{parameter}", "run")
    if file_kind(args.run) == "tube":
        from .tube_commands import continue_tube

        return continue_tube(args)
    with claim(args.output, "continue"):
        return _continue(args)


def _continue(args) -> int:
    """``continue`` into ``args.output`` (owned)."""
    from ..analysis.critical.pitchfork_curve import TwoParameterError
    from ..analysis.picture import Picture
    from ..analysis.results import Kind
    from ..analysis.critical.second_parameter import UnknownParameter
    from ..io.curve_file import write_curve
    from ..io.legacy import inherited_readings, stale_readings
    from ..io.output import check_output
    from ..io.run_file import read_run, stored_scene
    from ..numerics.interrupt import Interrupted, requested, sigterm_raises, stop_on_signals
    from .restart import RestartError, find_label, restart, with_settings

    if args.direction != 1.0 and args.parameter is None:
        raise UsageError(f"continue: --direction {args.direction:g} starts a curve in a second parameter: give "
                         "--parameter KEY (without it the branch is traced both ways)")
    check_output(hdf5_output(args.output, "run"), args.force)
    try:  # reading has nothing to keep: a signal stops it at once (a file with surface branches takes seconds)
        with sigterm_raises():
            stored = read_run(args.run)
            came = requested()  # one whose KeyboardInterrupt was raised and dropped in a callback (a __del__) set it
    except KeyboardInterrupt:
        came = True
    if came:
        return curve_interrupted_status(None, args.output, True, "the work had not started")
    stale = stale_readings(stored["attrs"], stored_scene(stored).geometry.shape.value)
    if stale:  # its branches' states were solved under another hold: a start from them is no point of this version's
        raise UsageError(f"continue {args.run}: written before this version changed its readings ({stale[0]}); run "
                         "its scene again")
    with stop_on_signals():  # as run: a signal stops the work at its next point, what is finished is written
        try:
            start = find_label(stored, args.label)
            start = with_settings(start, _with_settings(args, start.branch.scene)[1])
            if args.parameter is not None:
                field_needed(start.branch.scene, args.parameter, f"continue --parameter {args.parameter}", args.run)
            if requested():  # while its label was found: nothing computed
                return curve_interrupted_status(None, args.output, True, "the work had not started")
            result = restart(start, args.parameter, args.direction)
        except (RestartError, UnknownParameter) as e:
            raise UsageError(f"continue {args.run}: {e}") from None
        except Interrupted:  # a curve's start (a plain degree's search) abandoned
            return curve_interrupted_status(None, args.output, True)
        except TwoParameterError as e:
            raise Failure(f"the curve from label {args.label} could not start: {e}") from None
        attrs = {"command": args.command_line, "continued_from": f"{args.run} label {args.label}",
                 "readings": inherited_readings(stored["attrs"])}  # its start and copied branches are the file's
        if isinstance(result, Picture):
            return _write_continued(args, result, attrs, start.point.kind == Kind.BP)
        write_curve(args.output, result.scene, result, name=curve_group(result), force=args.force, extra_attrs=attrs)
        signalled = requested()
    code = curve_interrupted_status(result, args.output, signalled)
    if code is not None:
        return code
    ending = f"{result.end.value}: {result.describe()}"
    print(f"{result.of.value} curve from label {args.label} in {result.parameter}: {len(result.q)} points, {ending}; "
          f"written to {args.output}")
    return 0


def _write_continued(args, picture, attrs, switched: bool) -> int:
    """``continue`` in the branch's own parameter: the branch traced again through the point, or at a branch point
    (``switched``) the branch of the point and the branches switched to, written (under ``stop_on_signals``);
    exit 0, 1 when incomplete unless --allow-partial (``verdict_status``), 130 when a signal stopped the work (what
    was finished written, flagged: ``interrupted_status``); at a branch point where no branch started, ``Failure``
    (exit 1, nothing written) unless a signal stopped them."""
    from ..analysis.results import Branch, stop_codes
    from ..io.run_file import write_run
    from ..numerics.interrupt import requested

    branches, over_meridian = picture.branches + picture.surface_branches, picture.meridian_surface
    if switched and len(branches) == 1 and not over_meridian and not picture.interrupted:
        reasons = "; ".join(f"{name}: {reason}" for name, reason in picture.not_started)
        raise Failure(f"no branch started at label {args.label} ({reasons}); nothing written")
    write_run(args.output, branches[0].scene, branches, force=args.force, extra_attrs=attrs, snaps=picture.snaps,
              found=picture.incomplete, meridian_surface=over_meridian)
    code = interrupted_status(picture.incomplete, args.output, requested())
    if code is not None:
        return code
    if switched:
        listed = ", ".join([f"{b.name} ({len(b.X) if isinstance(b, Branch) else len(b.values)} points, "
                            f"{stop_codes(b.legs)})" for b in branches[1:]]
                           + [f"{name} ({len(b.pressure)} points, {b.stop.code.value})"
                              for name, b in over_meridian.items()])
        print(f"branches switched to at label {args.label}: {listed}; written to {args.output}")
    else:  # the branch traced again (after its parent as read, for a pear branch: ``restart.restart_branch``)
        branch = picture.branches[-1]
        print(f"branch {branch.name} continued from label {args.label}: {len(branch.X)} points "
              f"({branch.stop_reason}), {len(branch.special)} special points; written to {args.output}")
    return verdict_status(picture.incomplete, args.allow_partial)


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
    p = commands.add_parser("sweep", help="run a scene of any shape over a grid of parameter values into one sweep "
                                          "file")
    p.add_argument("scene", help=f"{SCENE_HELP}; the base scene")
    p.add_argument("--vary", action="append", required=True, metavar="KEY=SPEC",
                   help="KEY=START:STOP:num=COUNT (or START:STOP:COUNT, or linspace(START, STOP, COUNT): COUNT "
                        "values, ends included) or KEY=v1,v2,...; KEY a dotted scene key (field.M, "
                        "field.coils[0].radius, material.alpha[0]) or a bare name of one table (M = field.M); "
                        "repeat for a cartesian product")
    p.add_argument("-o", "--output", help="sweep file (HDF5) to write or resume (default: SCENE_NAME_sweep_KEY.h5 "
                                          "in the current folder, KEY the last part of each varied key)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="send the members to this dask.distributed scheduler")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="local worker processes (default: all cores; 1: compute in this process; at most the CPU "
                        "count unless --oversubscribe)")
    p.add_argument("--oversubscribe", action="store_true",
                   help=f"allow --workers above the CPU count (up to {MAX_WORKERS}, and as many as the available "
                        "memory holds)")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--primary-only", action="store_true", help="trace the primary branch only")
    mode.add_argument("--no-pear", action="store_true",
                      help="primary branch, stability and branch points, but no pear branches")
    p.add_argument("--force", action="store_true", help="replace an existing file holding a different sweep")
    p.add_argument("--quiet", action="store_true", help="no progress bar and no summary")
    p.add_argument("--allow-partial", action="store_true",
                   help="exit 0 also when some members are incomplete (they are flagged in the file)")
    p.set_defaults(handler=sweep)


MAX_WORKERS = 256  # local worker processes, even with --oversubscribe


def check_workers(workers: int | None, oversubscribe: bool, scheduler: str | None) -> None:
    """UsageError unless ``workers`` is None or in [1, CPU count] (with ``oversubscribe``: [1, MAX_WORKERS], and
    at most the workers the available memory holds, ``sweep.memory_workers``), and
    not given with ``scheduler`` (the cluster's workers compute; local ones would be ignored); ``scheduler`` must
    look like an address ([PROTOCOL://]HOST:PORT)."""
    if scheduler is not None and not re.fullmatch(r"([a-z]+://)?[\w.\-\[\]:]+:\d+", scheduler):
        raise UsageError(f"--scheduler {scheduler!r}: not a scheduler address (e.g. tcp://HOST:8786)")
    if workers is None:
        return
    if scheduler is not None:
        raise UsageError(f"--workers {workers} with --scheduler {scheduler}: the cluster's workers compute the members; "
                         "give one of the two")
    from .sweep import WORKER_MEMORY, available_memory, cpu_count, memory_workers

    if not oversubscribe:
        limit, more = cpu_count(), f" (the CPU count; --oversubscribe allows up to {MAX_WORKERS})"
    elif memory_workers() < MAX_WORKERS:
        limit = memory_workers()
        more = (f" (with --oversubscribe: the workers of ~{WORKER_MEMORY / 2**20:.0f} MiB each that the available "
                f"memory, {available_memory() / 2**30:.3g} GiB, holds)")
    else:
        limit, more = MAX_WORKERS, ""
    if not 1 <= workers <= limit:
        raise UsageError(f"--workers {workers}: must be in [1, {limit}]{more}")


def sweep(args) -> int:
    """Expand, compute the members not yet in the file, append them, summarise."""
    from ..io.sweep_file import incomplete_members
    from ..scene import load_scene
    from .progress import shown
    from .sweep import SweepError, format_summary, run_sweep

    check_workers(args.workers, args.oversubscribe, args.scheduler)
    from ..numerics.interrupt import sigterm_raises

    mode = "primary-only" if args.primary_only else "no-pear" if args.no_pear else "analysis"
    scene = axisymmetric(load_scene(args.scene), "sweep")
    if scene.geometry.shape == "tube" and scene.continuation.parameter == "voltage":
        raise UsageError(f"sweep of a tube: its table reads a pressure continuation's points: {args.scene} continues "
                         'in the voltage (continuation.parameter = "voltage")')
    varied = "_".join(re.sub(r"[^A-Za-z0-9.+-]+", "", text.partition("=")[0].strip().split(".")[-1])
                      for text in args.vary)
    args.output = default_output(args.output, f"{scene.name}_sweep_{varied}", "sweep")
    try:
        with sigterm_raises():
            result = run_sweep(scene, args.vary, args.output, mode=mode, workers=args.workers,
                               scheduler=args.scheduler, force=args.force, progress=shown(args.quiet),
                               command=args.command_line)
    except SweepError as e:
        raise UsageError(str(e)) from None
    except KeyboardInterrupt:  # SIGINT or SIGTERM: the workers are stopped, the finished members are stored
        print(f"{PROG}: interrupted: the finished members are stored; re-run the same command to resume",
              file=sys.stderr)
        return INTERRUPTED
    if not args.quiet:
        print(format_summary(result))
    if result.failed:
        kept = "" if result.replaced else f"; {result.path} is kept until every member of the new sweep is written"
        raise Failure(f"{len(result.failed)} of {len(result.members)} sweep members failed (members "
                      f"{', '.join(map(str, sorted(result.failed)))}); re-run the same command to retry them{kept}")
    partial = incomplete_members(result.path)  # the verdicts stored with the members (attributes only)
    if partial:
        print(f"{PROG}: incomplete: sweep members {', '.join(map(str, partial))} (their results are flagged in the "
              "file: members/<index> attributes complete, incomplete_*)", file=sys.stderr)
        return 0 if args.allow_partial else 1
    return 0
