"""Which single coil gives the paper's critical M (≈ 0.004 SPOM1, ≈ 0.0078 TPOM1)? (issue 15, item 3)

For each coil radius a (height 0, current 1, chi and the rest as in scenes/spom1_single_coil.toml, except
continuation.wire_gap = 0.05 instead of 0.1: with 0.1 the curves of coils near the balloon stop at the wire on
their way back to the partner pitchfork; docs/numerics.md: gaps down to ~0.04 fit in max_degree 320) runs
`balloon-cg critical SCENE --parameter M` for SPOM1 and TPOM1 and reads the curve file back: how the curve ended
(`end`, balloon_cg.analysis.critical.pitchfork_curve.CurveEnd), the critical M (`critical_q`, a value only for a verified
isola_merge) and the first fold of the curve in M (`special_q[0]`, a candidate merge, unverified unless the end is
isola_merge). Then, if two radii with a verified SPOM1 merge bracket M = 0.004, bisects a there to
|Δa| < 5e-4 (three significant digits; otherwise it says so and stops), runs SPOM1 and TPOM1 (the test of the
inference: the paper's 0.0078) at that a, and repeats both with solver.max_error 1e-11 (convergence).
Run: python benchmarks/paper_coil.py  (output kept in benchmarks/results/paper_coil.txt)
"""
import re
import subprocess
import tempfile
import time
from itertools import pairwise
from pathlib import Path

import numpy as np

from balloon_cg.io.curve_file import read_curve

ROOT = Path(__file__).resolve().parent.parent
SCENE = (ROOT / "scenes" / "spom1_single_coil.toml").read_text()
RADII = (1.9, 1.95, 2.0, 2.25, 2.5, 3.0, 3.5, 4.0, 5.0)
TARGET_M = 0.004  # the paper's critical M for SPOM with one coil (0.0078 for TPOM)
A_TOL = 5e-4
WIRE_GAP = 0.05
FINE_ERROR = 1e-11  # solver.max_error of the convergence check (default 1e-9)


def scene_text(radius: float, preset: str, solver: str = "") -> str:
    """The shipped single-coil scene with the coil radius, the material preset and the wire gap replaced."""
    text, n_radius = re.subn(r"(?m)^radius = .*$", f"radius = {radius!r}", SCENE)
    text, n_preset = re.subn(r'(?m)^preset = .*$', f'preset = "{preset}"', text)
    text, n_gap = re.subn(r"(?m)^wire_gap = .*$", f"wire_gap = {WIRE_GAP!r}", text)
    assert (n_radius, n_preset, n_gap) == (1, 1, 1), "scenes/spom1_single_coil.toml: expected one coil radius, " \
        "one preset, one wire_gap"
    return text + (f"\n[solver]\n{solver}\n" if solver else "")


def critical(radius: float, preset: str, work: Path, solver: str = "") -> dict:
    """One `balloon-cg critical` run: end, verified critical M (NaN unless isola_merge), first fold in M, time,
    Legendre degree; `solver` is extra [solver] TOML (the convergence check)."""
    scene = work / f"{preset}_{radius!r}.toml"
    scene.write_text(scene_text(radius, preset, solver))
    out = work / f"{preset}_{radius!r}.h5"
    start = time.perf_counter()
    run = subprocess.run(["balloon-cg", "critical", str(scene), "--parameter", "M", "-o", str(out), "--force",
                          "--quiet"], check=False, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if run.returncode not in (0, 1):
        raise RuntimeError(f"balloon-cg critical {scene}: exit {run.returncode}: {run.stderr.strip()}")
    if not out.exists():  # exit 1 before any curve: no pear pitchfork on the primary branch
        return {"end": "no_pitchfork", "critical": np.nan, "fold": np.nan, "seconds": seconds, "degree": 0,
                "note": run.stderr.strip().splitlines()[-1]}
    curve = read_curve(out)
    folds = curve["special_q"]
    return {"end": curve["attrs"]["end"], "critical": float(curve["attrs"]["critical_q"]),
            "fold": float(folds[0]) if len(folds) else np.nan, "seconds": seconds,
            "degree": curve["attrs"]["degree"],
            "note": curve["attrs"]["end_description"]}


def cell(result: dict) -> str:
    verified = f"{result['critical']:.5g}" if result["end"] == "isola_merge" else "-"
    return f"{result['end']:>13} {verified:>9} {result['fold']:>9.4g}"


def bisect(lo: float, hi: float, m_lo: float, work: Path, runs: list) -> float:
    """a where SPOM1's verified critical M equals TARGET_M, bisecting [lo, hi] (every run must verify)."""
    while hi - lo > A_TOL:
        mid = 0.5 * (lo + hi)
        result = critical(mid, "SPOM1", work)
        runs.append((mid, "SPOM1", result))
        if result["end"] != "isola_merge":
            raise RuntimeError(f"a = {mid}: SPOM1 curve ended {result['end']}, not a verified merge")
        if (result["critical"] - TARGET_M) * (m_lo - TARGET_M) > 0:
            lo, m_lo = mid, result["critical"]
        else:
            hi = mid
    return 0.5 * (lo + hi)


def main():
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        print(f"coil radius a (height 0, current 1, chi 1, wire_gap {WIRE_GAP}); per material: curve end, "
              "verified critical M "
              "(isola_merge only), first fold of the curve in M (unverified unless isola_merge)")
        print(f"{'a':>6} | {'SPOM1 end':>13} {'crit M':>9} {'fold M':>9} | {'TPOM1 end':>13} {'crit M':>9} "
              f"{'fold M':>9}")
        table = {}
        for radius in RADII:
            row = {preset: critical(radius, preset, work) for preset in ("SPOM1", "TPOM1")}
            runs += [(radius, preset, result) for preset, result in row.items()]
            table[radius] = row
            print(f"{radius:>6.3g} | {cell(row['SPOM1'])} | {cell(row['TPOM1'])}", flush=True)
        verified = [(a, row["SPOM1"]["critical"]) for a, row in table.items() if row["SPOM1"]["end"] == "isola_merge"]
        bracket = [(a, ma, b) for (a, ma), (b, mb) in pairwise(verified)
                   if (ma - TARGET_M) * (mb - TARGET_M) <= 0]
        if bracket:
            lo, m_lo, hi = bracket[0]
            radius = bisect(lo, hi, m_lo, work, runs)
            spom, tpom = (critical(radius, preset, work) for preset in ("SPOM1", "TPOM1"))
            runs += [(radius, "SPOM1", spom), (radius, "TPOM1", tpom)]
            print(f"inferred a = {radius:.6g} (bracket [{lo:g}, {hi:g}], bisection to |da| < {A_TOL:g})")
            print(f"{radius:>6.4g} | {cell(spom)} | {cell(tpom)}   (paper: 0.004, 0.0078)")
            for preset, result in (("SPOM1", spom), ("TPOM1", tpom)):
                fine = critical(radius, preset, work, solver=f"max_error = {FINE_ERROR!r}")
                runs.append((radius, preset, fine))
                print(f"  convergence {preset}: max_error 1e-9 (degree {result['degree']}) {result['critical']:.12g}; "
                      f"max_error {FINE_ERROR:g} (degree {fine['degree']}) {fine['critical']:.12g} ({fine['end']})")
        else:
            lowest = min(verified, key=lambda v: v[1]) if verified else None
            print(f"no two radii with a verified SPOM1 merge bracket M = {TARGET_M}: " + (
                f"the smallest verified critical M is {lowest[1]:.5g} at a = {lowest[0]:g}" if lowest
                else "no radius gave a verified merge"))
        print(f"runs: {len(runs)}, total {sum(r['seconds'] for _, _, r in runs):.0f} s")
        for radius, preset, result in runs:
            if result["end"] != "isola_merge":
                print(f"  a = {radius:g} {preset}: {result['note']}")


if __name__ == "__main__":
    main()
