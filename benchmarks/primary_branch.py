"""Benchmark: SPOM1, M = 0, primary branch from pole stretch 1 to 5 with at least 200 points.

Prints a table: cold run (fresh numba cache, includes JIT compilation, in a subprocess), warm runs (best of 5),
time per converged point, and the ratio warm/cold. Run: python benchmarks/primary_branch.py
"""
import os
import subprocess
import sys
import tempfile
import time

SCENE = """
[material]
preset = "SPOM1"
[continuation]
start_stretch = 1.01
min_stretch = 1.001
stop_stretch = 5.0
step = 0.02
step_max = 0.028
"""

CHILD = """
import time
t0 = time.perf_counter()
from balloon_cg.scene import parse_scene
from balloon_cg.analysis.branches.primary import trace_primary
t1 = time.perf_counter()
branch = trace_primary(parse_scene({scene!r}, name="bench"))
t2 = time.perf_counter()
print(t1 - t0, t2 - t1, len(branch.X))
"""


def cold_run() -> tuple[float, float, int]:
    """Import and first trace in a fresh interpreter with an empty numba cache (includes compilation)."""
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        out = subprocess.run([sys.executable, "-c", CHILD.format(scene=SCENE)], env=env, check=True,
                             capture_output=True, text=True).stdout.split()
    return float(out[0]), float(out[1]), int(out[2])


def warm_runs(repeat: int = 5):
    from balloon_cg.analysis.branches.primary import trace_primary
    from balloon_cg.scene import parse_scene

    scene = parse_scene(SCENE, name="bench")
    trace_primary(scene)  # compile or load from cache
    times, branch = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        branch = trace_primary(scene)
        times.append(time.perf_counter() - t0)
    return min(times), branch


def main():
    import_time, cold, n_cold = cold_run()
    warm, branch = warm_runs()
    n = len(branch.X)
    rows = [
        ("cold: import", f"{import_time:.2f} s", ""),
        ("cold: first branch (JIT compile + trace)", f"{cold:.2f} s", f"{n_cold} points"),
        ("warm: whole branch (best of 5)", f"{warm * 1e3:.1f} ms", f"{n} points"),
        ("warm: per converged point", f"{warm / n * 1e6:.0f} us", f"{branch.iterations.mean():.2f} Newton its/point"),
        ("ratio cold / warm", f"{cold / warm:.0f}x", ""),
        ("max residual / error estimate", f"{branch.residual.max():.1e}", f"{branch.error_estimate.max():.1e}"),
    ]
    width = max(len(r[0]) for r in rows)
    print(f"SPOM1 M = 0 primary branch, pole stretch 1.001 -> 5, degree {branch.disc.degree}, "
          f"{'symmetric' if branch.disc.symmetric else 'general'} subspace, {branch.disc.size} unknowns")
    for label, value, note in rows:
        print(f"  {label:<{width}}  {value:>10}  {note}")
    floor_ok = warm < 1.0 and cold < 60.0 and n >= 200
    print(f"floors (warm < 1 s, cold < 60 s, >= 200 points): {'met' if floor_ok else 'NOT met'}")


if __name__ == "__main__":
    main()
