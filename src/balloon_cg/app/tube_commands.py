"""The commands on a tube scene (docs/tubes.md): ``run`` (tube/picture.tube_picture) and ``critical``
(tube/picture.onset_picture) write a tube run file (io/tube_file.py) and summarise it. A signal (SIGINT or SIGTERM,
numerics.interrupt) stops the work at its next point or before its next stage: what is finished is written, the
file's ``interrupted`` attribute names the stage, and the command exits 130 with one line read from the file."""
import math
import sys

from .cli import INTERRUPTED, PROG, Failure, UsageError, _say, field_needed
from ..scene.tables import ContinuationParameter, Ends


def run_tube(scene, output, args) -> int:
    """A tube scene's run (tube/picture.py: the primary branch, its folds and branch points, the bulge branch)
    written to the tube run file ``output`` and summarised; 130 when a signal stopped it (module docstring); 1 (0 with
    --allow-partial) when a switched branch could not start (its first step did not converge: the file's
    ``not_started``) or the bulge branch stopped unresolved at its cap (solver.tube_resolution "elements", the
    default: the element layout's, tube/front.element_cap; "refine": solver.max_degree, tube/resolution.py), saying so in one line."""
    from ..dynamics.tube import with_frequencies
    from ..tube.picture import tube_picture
    from .tube_summary import format_tube, summarise_tube

    def picture():
        return with_frequencies(scene, tube_picture(scene, args.primary_only))

    summarise = None if args.quiet else (lambda run: format_tube(summarise_tube(run)))
    run, summary, signalled = _written(output, args, picture, scene, summarise)
    code = interrupted_status(run, output, signalled)
    if code is not None:
        return code
    if summary is not None:
        print(summary)
    return stored_verdict_status(run, output, args)


def stored_verdict_status(run: dict, output, args) -> int:
    """0 for a tube run file whose stored verdict (tube/picture.gaps; a signal's answered before, by
    ``interrupted_status``) is complete; else one line on stderr naming what is missing and 1 (0 with
    --allow-partial, where the command has it)."""
    from ..analysis.verdict import Gap

    a = run["attrs"]
    if a["complete"]:  # (a stated limitation alone leaves it complete)
        return 0
    missing = [f"not started: {branch}: {why}" if gap == Gap.NOT_STARTED else f"{branch}: {why}"
               for gap, branch, why in zip(a["incomplete_gaps"], a["incomplete_branches"], a["incomplete_messages"])]
    if not missing:
        return 0
    print(f"{PROG}: incomplete ({'; '.join(missing)}); the rest is written to {output}", file=sys.stderr)
    return 0 if getattr(args, "allow_partial", False) else 1


ONSET_PARAMETERS = {"M": "M", "field.M": "M", "voltage": "voltage", "electric.voltage": "voltage",
                    "axial_stretch": "axial_stretch", "geometry.axial_stretch": "axial_stretch"}  # critical's


def critical_tube(scene, output, args) -> int:
    """``critical`` on a tube (tube/onset.py): the primary branch, its first odd branch point (the onset of bulging)
    followed in M, the voltage Φ̄ or the held ends' distance λ (axial_stretch), written with the primary branch to the
    tube run file ``output`` (its /onset group) and summarised. Exit 0 with ``critical M = ...`` where the curve turns
    back in the parameter (its first fold, the first turning point in the --direction, with its status; printed,
    but exit 1 with a line on stderr where its state is not resolved, its Legendre tail above solver.max_error), 1 (the file
    still written) where it does not (the line
    says the curve was traced one way from the scene's value, as every critical curve, and --direction the other); 1
    without a file where the primary branch has no odd branch point; 2 for anything but the onset (--of BP) in M,
    the voltage or axial_stretch, M without coils, the voltage without [electric], axial_stretch on closed ends (no
    held distance), a scene continued in the voltage; 130 when a signal stopped it (module docstring)."""
    from ..tube.picture import onset_picture

    name = ONSET_PARAMETERS.get(args.parameter)
    if scene.continuation.parameter == ContinuationParameter.VOLTAGE:
        raise UsageError(f"critical on a tube follows the onset of bulging on a pressure continuation: {args.scene} "
                         'continues in the voltage (continuation.parameter = "voltage")')
    if args.of != "BP" or name is None:
        raise UsageError(f"critical on a tube follows the onset of bulging (--of BP) in M, the voltage or "
                         f"axial_stretch: {args.scene}: --of {args.of} --parameter {args.parameter}")
    if name == "axial_stretch" and scene.geometry.axial_stretch is None:
        raise UsageError(f"critical --parameter axial_stretch follows the onset in the held distance of the ends: "
                         f"{args.scene} has closed ends (geometry.axial = \"closed\", the default: the distance free, "
                         "none held); hold them apart with geometry.axial_stretch = λ (in [1, 5]) in its [geometry]")
    field_needed(scene, args.parameter, "critical --parameter M", args.scene)
    if name == "voltage" and scene.electric is None:
        raise UsageError(f"critical --parameter voltage needs an [electric] table: {args.scene} has none, so the "
                         "equilibrium does not depend on the voltage")

    def picture():
        found = onset_picture(scene, name, args.direction)
        if found.onset is None and found.interrupted is None:
            primary = found.branches["primary"]
            raise Failure(f"no odd branch point (the onset of bulging) on the primary branch of {args.scene} "
                          f"({primary.stop.message}): nothing to follow in {name}")
        return found

    run, _, signalled = _written(output, args, picture, scene)
    code = interrupted_status(run, output, signalled)
    if code is not None:
        return code
    onset = run["onset"]
    _say(args, f"onset curve: {len(onset['q'])} points, stop {onset['attrs']['stop_code']} "
               f"({onset['attrs']['stop_message']})")
    if not onset["folds"]:
        side = "up" if args.direction > 0 else "down"
        raise Failure(f"no critical {name}: the onset curve does not turn back in {name} "
                      f"({onset['attrs']['stop_message']}; last point {name} = {onset['q'][-1]:.10g}, P = "
                      f"{onset['pressure'][-1]:.10g}); traced {side} from {name} = {onset['attrs']['q0']:g} only, as "
                      f"every critical curve: --direction {-args.direction:g} traces the other side; curve written to "
                      f"{output}")
    fold = onset["folds"][0]  # the first turning point: the curve starts with q moving in --direction
    print(f"critical {name} = {fold['q']:.12g} (P = {fold['pressure']:.10g}; the onset curve turns back in {name}: "
          f"{fold['status']}); curve written to {output}")
    if fold["tail"] > scene.solver.max_error:
        raise Failure(f"the fold's state is not resolved at solver.degree = {scene.solver.degree}: its Legendre tail "
                      f"{fold['tail']:.2g} is above solver.max_error = {scene.solver.max_error:g} (the critical value "
                      "may be off, or the fold an artefact: raise solver.degree, or solver.max_error to accept it; "
                      "docs/tubes.md)")
    return 0


def _written(output, args, compute, scene, summarise=None) -> tuple:
    """``compute()`` (a TubePicture) under ``stop_on_signals``, written to ``output`` (owned, checked first), read
    back and, unless a signal came, ``summarise``d (the text to print): (the file's contents, the summary or None,
    whether a signal came). All of it under the flag, so that a signal before the command's end never raises in
    the middle of reading (the run's exit 0 or 130 says what the file holds: app/cli.run's rule)."""
    from ..io.lock import claim
    from ..io.output import check_output
    from ..io.tube_file import read_tube_run, write_tube_run
    from ..numerics.interrupt import requested, stop_on_signals

    with claim(output, args.command):
        check_output(output, args.force)
        with stop_on_signals():
            write_tube_run(output, scene, compute(), args.force, args.command_line)
            run = read_tube_run(output)
            summary = None if summarise is None or requested() else summarise(run)
            signalled = requested()
    return run, summary, signalled


def interrupted_status(run: dict, output, signalled: bool) -> int | None:
    """130 when the tube run file ``run`` says a signal stopped its work (its ``interrupted`` stage; the line is
    the file's: the stage, its points or that it had not started); else None, having said so when a signal came
    once the work had finished (``signalled``: the file is whole)."""
    from ..analysis.results import StopCode  # here, as cli's: the command line's start-up does not load analysis

    stage = run["attrs"]["interrupted"]
    if stage:
        traced = [*run["branches"].values(), *run.get("surface_branches", {}).values()]
        stopped = (b for b in traced if b["attrs"]["stop_code"] == StopCode.INTERRUPTED.value)
        stored = run["onset"] if stage == "onset" else next(stopped, None)  # the branch the signal stopped
        if stage == "frequencies":
            done = [name for name, b in run["branches"].items() if b["frequencies"] is not None]
            what = f"the branches whole, the frequencies of {', '.join(done) or 'none'} written"
        elif stage == "modes":
            what = "the branches whole, their m ≥ 1 blocks not read"
        elif stored is None:
            what = "not started"
        else:
            what = f"{stored['attrs']['stop_message']}, after {len(stored['pressure'])} points"
        print(f"{PROG}: interrupted ({stage}: {what}); what was finished is written to {output} (flagged "
              "interrupted)", file=sys.stderr)
        return INTERRUPTED
    if signalled:
        print(f"{PROG}: a signal arrived once the work had finished: {output} is written whole", file=sys.stderr)
    return None


def _has_field(run: dict) -> bool:
    """Whether coils act in the tube run file's scene (its primary branch is then not uniform)."""
    from .tube_summary import scene_field

    field = scene_field(run["attrs"]["scene_toml"])
    return field["coils"] > 0 and field["M"] > 0


def continue_tube(args) -> int:
    """``continue`` from a label of a tube run file (``inspect`` numbers the located points of its branches in
    order, from 0): at an odd branch point of the primary branch (the onset of bulging), or at an even one of a
    uniform primary branch (sliding ends, no field), the branch switched there (tube/bulge.py; named as ``run`` names it:
tube/picture.branch_name), with the file's scene and the command line's continuation settings (``--set continuation.stop_stretch=6``:
    traced further than the file's), or with ``--parameter M`` the onset followed in M (as ``critical``); written with
    the stored primary branch to a tube run file (130 on a signal; 1 where its verdict is incomplete, a branch not
    started or stopped unresolved: as ``run``); with ``--parameter voltage`` from a
    user point (UZ) of the primary branch, the tube continued in Φ̄ at its P (``_continue_in_voltage``). Exit 2,
    before any work, for another label, a setting outside [continuation], another parameter, or no coils for M."""
    from ..dynamics.tube import with_frequencies
    from ..io.tube_file import read_tube_run, stored_branch, tube_labels
    from ..tube.bulge import PLUGGED_WHY
    from ..tube.picture import branch_name, bulge_picture, maxwell, onset_from
    from ..tube.primary import scene_parameters

    run = read_tube_run(args.run)
    labels = tube_labels(run)
    if args.parameter in VOLTAGE_NAMES:
        return _continue_in_voltage(args, run, labels)
    if args.parameter in STRETCH_NAMES:
        return _continue_in_stretch(args, run, labels)
    if args.parameter not in (None, "P", "M", "field.M"):
        raise UsageError(f"continue {args.run}: --parameter {args.parameter}: a tube's onset is followed in M, a "
                         "user point's state in the voltage, a held tube's located point in axial_stretch (allowed: "
                         "M, voltage, axial_stretch, or none for the bulge branch)")
    in_field = args.parameter in ("M", "field.M")
    uniform = run["attrs"]["ends"] == Ends.SLIDING.value and not _has_field(run)  # even BPs switched there
    blocks = ("odd",) if in_field or not uniform else ("odd", "even")
    onsets = [i for i, (name, _, s) in enumerate(labels) if name == "primary" and s["kind"] == "BP"
              and s["block"] in blocks]
    if not 0 <= args.label < len(labels) or args.label not in onsets:
        name, _, s = labels[args.label] if 0 <= args.label < len(labels) else (None, None, None)
        what = "no such label" if s is None else " ".join(filter(None, (s["kind"], s["block"]))) + f" on branch {name}"
        which = "an odd branch point of its primary branch (the onset of bulging)" if blocks == ("odd",) else \
            "a branch point of its primary branch (odd: the onset of bulging; even: on its uniform branch)"
        from ..analysis.results import Kind  # here, as cli's: the command line's start-up does not load analysis
        primary_event = s is not None and name == "primary" and s["kind"] == Kind.UZ.value
        event = " (from a UZ: --parameter voltage, in Φ̄ at its P)" if primary_event else ""
        raise UsageError(f"continue {args.run}: label {args.label}: {what}; a tube continues from {which}: labels "
                         f"{', '.join(map(str, onsets)) or 'none'}{event}")
    scene = with_continuation_settings(args, stored_scene(args, run))
    at_fixed_scene(args, run, labels, scene)
    if in_field:
        field_needed(scene, "M", "continue --parameter M", args.run)
    elif scene.geometry.ends != Ends.SLIDING:
        raise UsageError(f"continue {args.run}: the bulge branch is switched on sliding ends, not "
                         f"{scene.geometry.ends.value}: {PLUGGED_WHY}")
    name, k, _ = labels[args.label]
    primary = stored_branch(run, "primary", scene_parameters(scene))
    point = primary.special[k]

    def picture():
        pm = maxwell(scene)
        if in_field:
            return onset_from(scene, primary, point, "M", args.direction, pm)
        return with_frequencies(scene, bulge_picture(scene, primary, [k], pm))

    written, _, signalled = _written(args.output, args, picture, scene)
    code = interrupted_status(written, args.output, signalled)
    if code is not None:
        return code
    grown = written["onset"] if in_field else written["branches"].get(branch_name(primary, k))
    if grown is not None:  # (a branch that did not start is none: the verdict names it)
        size = len(grown["q"] if in_field else grown["pressure"])
        print(f"{'onset curve in M' if in_field else 'branch ' + branch_name(primary, k)} from label {args.label}: "
              f"{size} points, stop "
              f"{grown['attrs']['stop_code']} ({grown['attrs']['stop_message']}); written to {args.output}")
    return stored_verdict_status(written, args.output, args)


VOLTAGE_NAMES = ("voltage", "electric.voltage")  # continue --parameter
STRETCH_NAMES = ("axial_stretch", "geometry.axial_stretch")  # continue --parameter


def _continue_in_voltage(args, run: dict, labels: list) -> int:
    """``continue --parameter voltage`` from a UZ point of a tube file's primary branch (a state where an event's
    quantity reached its value, at the scene's voltage Φ̄0): the tube continued in Φ̄ at that point's P
    (tube/picture.charged_picture from the stored state, ``--direction`` −1: Φ̄ falling first), with the file's
    scene and the command line's [continuation] settings (stop_stretch, max_points, steps), written as a tube run
    file's primary branch (130 on a signal, as ``run``). Exit 2, before any work, for another label (the bulge
    branch's states are not mirror-symmetric: the voltage continuation is on the even block), a scene without
    [electric], with coils, or a setting outside [continuation]."""
    from ..io.tube_file import stored_branch
    from ..tube.picture import charged_picture
    from ..tube.primary import scene_parameters

    points = [i for i, (name, _, s) in enumerate(labels) if name == "primary" and s["kind"] == "UZ"]
    if args.label not in points:
        name, _, s = labels[args.label] if 0 <= args.label < len(labels) else (None, None, None)
        what = "no such label" if s is None else f"{s['kind']} on branch {name}"
        raise UsageError(f"continue {args.run}: label {args.label}: {what}; a tube continues in the voltage from a "
                         f"user point (UZ) of its primary branch: labels {', '.join(map(str, points)) or 'none'}")
    stored = stored_scene(args, run)
    at_fixed_scene(args, run, labels, stored)
    if stored.electric is None:
        raise UsageError(f"continue {args.run}: --parameter voltage needs an [electric] table: the file's scene has "
                         "none, so the equilibrium does not depend on the voltage")
    if _has_field(run):
        raise UsageError(f"continue {args.run}: --parameter voltage: a tube's voltage continuation reads no coil "
                         "field yet; allowed: a scene without coils")
    scene = with_continuation_settings(args, stored)
    _, k, _ = labels[args.label]
    point = stored_branch(run, "primary", scene_parameters(scene)).special[k]
    start = (point.u, point.pressure, scene.voltage)
    return _at_fixed_pressure(args, scene, lambda: charged_picture(scene, start, args.direction), point.pressure,
                              "voltage", "Φ̄")


def _continue_in_stretch(args, run: dict, labels: list) -> int:
    """``continue --parameter axial_stretch`` from a located point of a held tube's primary branch (a fold in P, the
    onset of bulging, an event's point: mirror-symmetric states): the tube continued in the held distance λ at that
    point's P (tube/picture.stretched_picture from the stored state on the file's discretisation, ``--direction``
    −1: λ falling first), with the file's scene and the command line's [continuation] settings, written as a tube run
    file's primary branch (130 on a signal, as ``run``). Exit 2, before any work, for closed ends (nothing held),
    another branch's label (a bulge branch's states are not mirror-symmetric: the continuation is on the even
    block), an even branch point (the path in λ is itself at a branch point there: its tangent is not unique; start
    from a neighbouring label), or a setting outside [continuation]."""
    from ..io.tube_file import discretisation, stored_branch
    from ..tube.picture import stretched_picture
    from ..tube.primary import scene_parameters

    if math.isnan(run["attrs"]["axial_stretch"]):
        raise UsageError(f"continue {args.run}: --parameter axial_stretch continues a tube whose ends are held apart: "
                         "the file's has closed ends (the distance free, nothing held); hold them with "
                         "geometry.axial_stretch = λ (in [1, 5]) and run it again")
    points = [i for i, (name, _, s) in enumerate(labels) if name == "primary" and s["block"] != "even"]
    if args.label not in points:
        name, _, s = labels[args.label] if 0 <= args.label < len(labels) else (None, None, None)
        what = "no such label" if s is None else " ".join(filter(None, (s["kind"], s["block"]))) + f" on branch {name}"
        why = " (the path in λ is at a branch point there too: start from a neighbouring label)" if (
            s is not None and name == "primary") else ""
        raise UsageError(f"continue {args.run}: label {args.label}: {what}{why}; a held tube continues in "
                         "axial_stretch from a located point of its primary branch other than an even branch point: "
                         f"labels {', '.join(map(str, points)) or 'none'}")
    scene = with_continuation_settings(args, stored_scene(args, run))
    at_fixed_scene(args, run, labels, scene)
    _, k, _ = labels[args.label]
    point = stored_branch(run, "primary", scene_parameters(scene)).special[k]
    disc = discretisation(run["attrs"], run["branches"]["primary"]["attrs"])
    return _at_fixed_pressure(args, scene, lambda: stretched_picture(scene, point, disc, args.direction),
                              point.pressure, "axial_stretch", "λ")


def at_fixed_scene(args, run: dict, labels: list, scene) -> None:
    """UsageError (exit 2, one line) for a label of a primary branch continued in the voltage or in λ (``continue
    --parameter voltage|axial_stretch``) whose Φ̄ or λ is not the file's ``scene``'s: every continuation from a label
    starts from the scene's (a branch of another tube, stored as born at that label)."""
    from ..io.tube_file import STRETCH, VOLTAGE

    primary, point = run["branches"]["primary"], labels[args.label][2]
    for column, key, symbol, own in ((VOLTAGE, "electric.voltage", "Φ̄", scene.voltage),
                                     (STRETCH, "geometry.axial_stretch", "λ", scene.geometry.axial_stretch)):
        value = point.get(column) if column in primary else None
        if value is not None and abs(value - (own or 0.0)) > 1e-12 * max(1.0, abs(value)):
            raise UsageError(f"continue {args.run}: label {args.label}: its branch was continued in {column}, this "
                             f"point at {symbol} = {value:.10g}, the file's scene at {symbol} = {own or 0.0:.10g}: a "
                             f"continuation from it would start from the scene's; run the scene with {key} = "
                             f"{value:.10g} and continue from that run's labels")


def _at_fixed_pressure(args, scene, picture, pressure: float, column: str, symbol: str) -> int:
    """``picture()``, the file's primary branch continued from label ``args.label`` in ``column`` (voltage,
    axial_stretch) at the fixed ``pressure``, written to ``args.output`` (130 on a signal, as ``run``) and said in one
    line: its points, the range of ``symbol`` and its stop; 1 where the file's verdict is incomplete, as ``run``."""
    written, _, signalled = _written(args.output, args, picture, scene)
    code = interrupted_status(written, args.output, signalled)
    if code is not None:
        return code
    grown = written["branches"]["primary"]
    print(f"{column} continuation from label {args.label} at P = {pressure:.10g}: {len(grown['pressure'])} points, "
          f"{symbol} {grown[column].min():.6g}..{grown[column].max():.6g}, stop {grown['attrs']['stop_code']} "
          f"({grown['attrs']['stop_message']}); written to {args.output}")
    return stored_verdict_status(written, args.output, args)


def stored_scene(args, run: dict):
    """The scene a tube run file stores, as the new run of ``continue`` starts from it (UsageError, one line, where it
    is not a valid scene or one a new run may not start: ``scene.tables.startable``)."""
    from ..scene import SceneError, parse_scene

    try:
        return parse_scene(run["attrs"]["scene_toml"], run["attrs"]["scene_name"],
                           written=int(run["attrs"].get("readings", 0)))  # its defaults: a tube's resolution
    except SceneError as e:
        raise UsageError(f"continue {args.run}: the stored scene cannot start a new run ({e})") from None


def with_continuation_settings(args, stored):
    """``stored`` with the command line's settings (``--set``, shorthands), which must be [continuation] keys: the
    stored branch belongs to the file's scene (UsageError, one line, naming the first other key)."""
    from .cli import _with_settings

    scene, overrides = _with_settings(args, stored)
    other = [key for key in overrides if not key.startswith("continuation.")]
    if other:
        raise UsageError(f"continue {args.run}: --set {other[0]}={overrides[other[0]]}: the stored branch belongs to "
                         "the file's scene; allowed: continuation.* keys")
    return scene
