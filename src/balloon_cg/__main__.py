"""``python -m balloon_cg``: the command line (app.cli). SIGTERM raises KeyboardInterrupt from the first line,
so a signal during the imports exits 130 as later ones do (app.cli.main)."""
import signal
import sys


def _terminate(signum, frame):
    raise KeyboardInterrupt


signal.signal(signal.SIGTERM, _terminate)
try:
    from .app.cli import main
except KeyboardInterrupt:
    print("balloon-cg: error: interrupted", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
