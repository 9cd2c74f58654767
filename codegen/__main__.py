"""``python -m codegen [OUTDIR]``: regenerate every kernel module (default OUTDIR: generated/)."""
import sys
import time
from pathlib import Path

from . import build


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    outdir = Path(argv[0]) if argv else Path(__file__).resolve().parent.parent / "generated"
    start = time.perf_counter()
    written = build.write_all(outdir, log=print)
    print(f"codegen: {len(written)} modules in {outdir} ({time.perf_counter() - start:.1f} s)")


if __name__ == "__main__":
    main()
