"""Benchmark: the stability assessment of the two-coil scene's m = 1 branch (``analysis.surface.assessment``), the
phase that reads every point of a surface branch under every reading, on every core (``numerics.workers``).

For each install (``--python``, default this interpreter), in alternation, ``--repeat`` fresh processes each trace
the branch born at the first m = 1 point of ``spom1_two_coils_M0.002`` (its assessment captured, not run), then
assess it twice and report the second (the first loads the kernels): wall seconds, CPU seconds with its workers,
and a digest of every stored eigenvalue (equal digests: the same numbers). Then the ratios to the first install,
of one run. ``PYTHON::NAME=VALUE`` runs an install with environment variables set (``::BALLOON_CG_WORKERS=1``:
the serial reading, whose digest the parallel one must equal).

    python benchmarks/surface_assessment.py --python /path/to/old/venv/bin/python --python python \
        --python python::BALLOON_CG_WORKERS=1
"""
import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

MEASURE = """
import hashlib, json, resource, time
import numpy as np
from balloon_cg.analysis import picture
try:
    from balloon_cg.analysis.surface import assessment as surface_assessment, branches as surface_branches
except ImportError:  # an install from before analysis/ was regrouped (session 21)
    from balloon_cg.analysis import surface_assessment, surface_branches
from balloon_cg.numerics.threads import limited_blas
from balloon_cg.scene import load_scene

captured = []
assess = surface_branches.assess
surface_branches.assess = lambda sb, traced, readings: captured.append((sb, traced, readings))
picture.analyse(load_scene("spom1_two_coils_M0.002"))
surface_branches.assess = assess
sb, traced, readings = captured[0]

def cpu():
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime

special = list(sb.special)
for _ in range(2):
    sb.special = list(special)
    start, used = time.perf_counter(), cpu()
    limited_blas(surface_assessment.assessed)(sb, traced, readings)  # one BLAS thread, as analyse runs it
    wall, total = time.perf_counter() - start, cpu() - used
digest = hashlib.sha256(b"".join(np.ascontiguousarray(sb.stability[k]).tobytes() for k in sorted(sb.stability)))
print(json.dumps({"wall": wall, "cpu": total, "points": len(traced), "size": int(traced[-1][1].size),
                  "digest": digest.hexdigest()[:12]}))
"""


def measure(python: str) -> dict:
    """One fresh process of ``python`` (``PYTHON::NAME=VALUE,...``: with those environment variables, e.g.
    BALLOON_CG_WORKERS=1 for the serial reading)."""
    python, _, settings = python.partition("::")
    env = {**os.environ, **dict(item.split("=", 1) for item in settings.split(",") if item)}
    out = subprocess.run([python, "-c", MEASURE], capture_output=True, text=True, check=True, cwd=ROOT.parent, env=env)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--python", action="append", help="an interpreter with balloon-cg installed (repeatable)")
    parser.add_argument("--repeat", type=int, default=2, help="fresh processes per install (default 2)")
    args = parser.parse_args(argv)
    pythons = args.python or [sys.executable]
    results = {python: [] for python in pythons}
    for _ in range(args.repeat):
        for python in pythons:
            results[python].append(measure(python))
    print(f"{'install':<40}{'wall s':>9}{'CPU s':>9}{'points':>8}{'size':>7}  digest")
    for python, runs in results.items():
        for r in runs:
            print(f"{python:<40}{r['wall']:9.2f}{r['cpu']:9.2f}{r['points']:8d}{r['size']:7d}  {r['digest']}")
    first = results[pythons[0]]
    for python in pythons[1:]:
        wall = min(r["wall"] for r in results[python]) / min(r["wall"] for r in first)
        cpu = min(r["cpu"] for r in results[python]) / min(r["cpu"] for r in first)
        print(f"{python} / {pythons[0]} (best of {args.repeat}): wall {wall:.2f}x, CPU {cpu:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
