"""``python -m balloon_cg`` and the ``balloon-cg`` script (``run``): the command line (app.cli).

A signal at any moment of balloon-cg's own code ends it in one line, never by the signal (exit −2, −15) nor with a
traceback. Both raise KeyboardInterrupt from this module's first lines, before anything heavy is imported, so a signal during the imports exits 130 as later ones do (app.cli.main). Once the command has its
exit code (``_exit_code``), a signal prints that the work had finished and leaves the code as it is, and from
the first atexit handler on (Python resets a handler of its own to the default before it exits) it is ignored. One
that comes before ``run`` has entered its ``try`` (the rest of this module's import, the script's own lines) is held
(``_held``) and raised there.
What comes before this module (the interpreter's start, the import of the package ``balloon_cg``: a few tens of
ms) is Python's: SIGTERM kills, SIGINT raises there.
"""
import atexit
import os
import signal
import sys

SIGNALS = (signal.SIGINT, signal.SIGTERM)
_exit_code = None  # the command's exit code, once it is over
_running = False  # run has entered its try: a signal raises there
_held = False  # a signal came before that


def _signalled(signum, frame):
    """Before ``run``'s try: held for it. While the command runs: KeyboardInterrupt. After: one line, the exit code
    unchanged, later ones ignored."""
    global _held
    if not _running:
        _held = True
        return
    if _exit_code is None:
        raise KeyboardInterrupt
    _ignore_signals()
    _say(f"{signal.Signals(signum).name} after the work had finished: exit {_exit_code}")


for _s in SIGNALS:  # at import: `balloon-cg` imports this module, then calls run
    signal.signal(_s, _signalled)


def run() -> int:
    global _exit_code, _running
    try:
        _running = True
        if _held:
            raise KeyboardInterrupt
        from .app.cli import main
        _exit_code = main()
    except KeyboardInterrupt:
        if _exit_code is None:
            _exit_code = 130
            _say("error: interrupted")
        else:  # between the command's end and _over
            _say(f"interrupted after the work had finished: exit {_exit_code}")
    _over()
    return _exit_code


def _over() -> None:
    """The command is over: both signals go to ``_signalled``, and are ignored from the first atexit handler on
    (the last registered)."""
    for s in SIGNALS:
        signal.signal(s, _signalled)
    atexit.register(_ignore_signals)


def _ignore_signals() -> None:
    for s in SIGNALS:
        signal.signal(s, signal.SIG_IGN)


def _say(text: str) -> None:
    """One line on stderr, written at once (not print: a signal may land inside a write to sys.stderr)."""
    os.write(2, f"balloon-cg: {text}\n".encode())


if __name__ == "__main__":
    sys.exit(run())
