"""Benchmark: stability per branch point (N = 20, m = 0 and 1) and the whole SPOM1 M = 0 picture.

The picture is the primary branch 1 -> 6, stability of every point, the two pear branch points located and
classified, and the isola (the pear branch traced, its mirror image the reflection: analysis.switching.mirror) with
stability on every point (the mirror's copied).
Times: best of 3, process CPU time (BLAS single-threaded, so on a shared machine the CPU time is the reliable one)
and wall time in parentheses. Run: python benchmarks/stability.py
"""
import time

from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.scene import parse_scene
from balloon_cg.analysis.stability.axisymmetric import SecondVariation
from balloon_cg.numerics.threads import blas_threads

SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 6.0\n'


def best(f, repeat=3):
    """(best CPU seconds, best wall seconds, last value)."""
    cpu, wall = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        value = f()
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - t0)
    return min(cpu), min(wall), value


def main():
    scene = parse_scene(SCENE, name="spom1")
    analyse(scene)  # compile / load kernels
    branch = trace_primary(scene)
    variation = SecondVariation(equilibrium_of(branch), 20)
    params = branch.params

    def assess_all(m_max):  # BLAS limited as in assess_branch (analysis.stability.axisymmetric), the library's entry point
        with blas_threads():
            return [variation.assess(X[:-1], params.with_value("P", X[-1]), True, m_max) for X in branch.X]

    t_m0, w_m0, _ = best(lambda: assess_all(0))
    t_m1, w_m1, _ = best(lambda: assess_all(1))
    t_picture, w_picture, picture = best(lambda: analyse(scene))
    points = sum(len(b.X) for b in picture.branches)
    n = len(branch.X)
    print(f"SPOM1, M = 0, N = 20, {n} primary points (CPU time, wall in parentheses)")
    print(f"  stability per point, m = 0 blocks          {t_m0 / n * 1e3:7.3f} ms ({w_m0 / n * 1e3:.3f} ms)")
    per_point = t_m1 / n
    print(f"  stability per point, m = 0 and m = 1       {per_point * 1e3:7.3f} ms ({w_m1 / n * 1e3:.3f} ms)   "
          f"floor <= 0.3 ms: {'met' if per_point <= 3e-4 else 'NOT met'}")
    print(f"  whole picture (primary + isola, stability on {points} points, 2N checks, classification) "
          f"{t_picture:.3f} s ({w_picture:.3f} s)   floor <= 0.5 s: {'met' if t_picture <= 0.5 else 'NOT met'}")


if __name__ == "__main__":
    main()
