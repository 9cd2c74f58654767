"""The commands on a tube scene (docs/shapes.md): ``run`` (tube/picture.tube_picture) and ``critical``
(tube/picture.onset_picture) write a tube run file (io/tube_file.py) and summarise it. A signal (SIGINT or SIGTERM,
numerics.interrupt) stops the work at its next point or before its next stage: what is finished is written, the
file's ``interrupted`` attribute names the stage, and the command exits 130 with one line read from the file."""
import sys

from .cli import INTERRUPTED, PROG, Failure, UsageError, _say, field_needed


def run_tube(scene, output, args) -> int:
    """A tube scene's run (tube/picture.py: the primary branch, its folds and branch points, the bulge branch)
    written to the tube run file ``output`` and summarised; 130 when a signal stopped it (module docstring)."""
    from ..io.tube_file import read_tube_run
    from ..tube.picture import tube_picture
    from .tube_summary import format_tube, summarise_tube

    run, signalled = _written(output, args, lambda: tube_picture(scene, args.primary_only), scene)
    code = interrupted_status(run, output, signalled)
    if code is not None:
        return code
    if not args.quiet:
        print(format_tube(summarise_tube(read_tube_run(output))))
    return 0


def critical_tube(scene, output, args) -> int:
    """``critical`` on a tube (tube/onset.py): the primary branch, its first odd branch point (the onset of bulging)
    followed in M, written with the primary branch to the tube run file ``output`` (its /onset group) and summarised.
    Exit 0 with ``critical M = ...`` where the curve turns back in M (a located fold: the onset's largest or smallest
    M), 1 (the file still written) where it does not; 1 without a file where the primary branch has no odd branch
    point; 2 for anything but the onset (--of BP) in M, or no coils; 130 when a signal stopped it (module
    docstring)."""
    from ..tube.picture import onset_picture

    if args.of != "BP" or args.parameter not in ("M", "field.M"):
        raise UsageError(f"critical on a tube follows the onset of bulging (--of BP) in M: {args.scene}: --of "
                         f"{args.of} --parameter {args.parameter}")
    field_needed(scene, args.parameter, "critical --parameter M", args.scene)

    def picture():
        found = onset_picture(scene, "M", args.direction)
        if found.onset is None and found.interrupted is None:
            primary = found.branches["primary"]
            raise Failure(f"no odd branch point (the onset of bulging) on the primary branch of {args.scene} "
                          f"({primary.stop.message}): nothing to follow in M")
        return found

    run, signalled = _written(output, args, picture, scene)
    code = interrupted_status(run, output, signalled)
    if code is not None:
        return code
    onset = run["onset"]
    _say(args, f"onset curve: {len(onset['q'])} points, stop {onset['attrs']['stop_code']} "
               f"({onset['attrs']['stop_message']})")
    if not onset["folds"]:
        raise Failure(f"no critical M: the onset curve does not turn back in M ({onset['attrs']['stop_message']}; "
                      f"last point M = {onset['q'][-1]:.10g}, P = {onset['pressure'][-1]:.10g}); curve written to "
                      f"{output}")
    fold = max(onset["folds"], key=lambda f: args.direction * f["q"])
    print(f"critical M = {fold['q']:.12g} (P = {fold['pressure']:.10g}; the onset curve turns back in M: "
          f"{fold['status']}); curve written to {output}")
    return 0


def _written(output, args, compute, scene) -> tuple:
    """``compute()`` (a TubePicture) under ``stop_on_signals``, written to ``output`` (owned, checked first) and read
    back: (the file's contents, whether a signal came)."""
    from ..io.lock import claim
    from ..io.output import check_output
    from ..io.tube_file import read_tube_run, write_tube_run
    from ..numerics.interrupt import requested, stop_on_signals

    with claim(output, args.command):
        check_output(output, args.force)
        with stop_on_signals():
            write_tube_run(output, scene, compute(), args.force, args.command_line)
            signalled = requested()
    return read_tube_run(output), signalled


def interrupted_status(run: dict, output, signalled: bool) -> int | None:
    """130 when the tube run file ``run`` says a signal stopped its work (its ``interrupted`` stage; the line is
    the file's: the stage, its points or that it had not started); else None, having said so when a signal came
    once the work had finished (``signalled``: the file is whole)."""
    stage = run["attrs"]["interrupted"]
    if stage:
        stored = run["onset"] if stage == "onset" else run["branches"].get(stage)
        if stored is None:
            what = "not started"
        else:
            what = f"{stored['attrs']['stop_message']}, after {len(stored['pressure'])} points"
        print(f"{PROG}: interrupted ({stage}: {what}); what was finished is written to {output} (flagged "
              "interrupted)", file=sys.stderr)
        return INTERRUPTED
    if signalled:
        print(f"{PROG}: a signal arrived once the work had finished: {output} is written whole", file=sys.stderr)
    return None
