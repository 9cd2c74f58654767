"""``python -m balloon_cg`` and the ``balloon-cg`` script (``run``): the command line (app.cli). SIGTERM raises
KeyboardInterrupt before anything heavy is imported, so a signal during the imports exits 130 as later ones do
(app.cli.main)."""
import signal
import sys


def _terminate(signum, frame):
    raise KeyboardInterrupt


def run() -> int:
    signal.signal(signal.SIGTERM, _terminate)
    try:
        from .app.cli import main
    except KeyboardInterrupt:
        print("balloon-cg: error: interrupted", file=sys.stderr)
        return 130
    return main()


if __name__ == "__main__":
    sys.exit(run())
