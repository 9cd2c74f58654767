"""Benchmark: which basis map ``Tracer._refine`` keeps when a leg's degree grows, under three OpenBLAS kernel sets.

At a resolution stop with a wire map the tracer recomputes the leg's last point at the next degree on the current
map and on the re-centred one. It used to keep the smaller tail estimate T; where both sit at T's rounding floor the
kernels' rounding chose (spom1_single_coil's primary at P 0.876362, tpom1_two_coils_M0.002's pear_free_1 at P
2.245873: tests/test_stability_reference.py). Now the current map is kept unless the re-centred one's T is lower by
the factor map_gain = 2 (``Resolution.clearly_lower``). For both scenes (the whole picture, surface branches off),
analysed in one subprocess per OPENBLAS_CORETYPE (the machine's default, Haswell here; Sandybridge; Nehalem), every
such decision: P, the degrees, each map's widths and T, their ratio, the map the old rule (smaller T) would keep and
the one kept now. The legs follow the new choice, so the old rule's column is what the old code did up to its first
differing decision.

    python benchmarks/refine_choice.py > benchmarks/results/refine_choice.txt
"""
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENES = ("spom1_single_coil", "tpom1_two_coils_M0.002")
CORES = ("default", "Sandybridge", "Nehalem")
PARALLEL = 3  # subprocesses at a time


def worker(name: str) -> None:
    """Analyse scene ``name`` and print one JSON line per growth decision between two maps."""
    from threadpoolctl import threadpool_info

    from balloon_cg.analysis.branches import tracer
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.scene import load_scene

    readings = []

    def solve(residual, *args):  # _refine's Newton solve: the candidate's T recorded (residual: its system's)
        result = tracer_newton(residual, *args)
        disc = residual.__self__.eq.disc
        readings.append((disc.mapping, disc.tail(result.x[:-1]) if result.converged else float("inf")))
        return result

    refine, tracer_newton = tracer.Tracer._refine, tracer.newton

    def recorded(self, disc, last, degree, mappings, params, accept):
        readings.clear()
        out = refine(self, disc, last, degree, mappings, params, accept)
        if len(mappings) > 1:
            smaller = min(readings, key=lambda r: r[1])[0]
            kept = "failed" if isinstance(out, str) else label(out[0].eq.disc.mapping, mappings)
            print(json.dumps({"P": float(last.X[-1]), "from": disc.degree, "to": degree,
                              "maps": [[widths(m), t] for m, t in readings],
                              "old": label(smaller, mappings), "new": kept}), flush=True)
        return out

    tracer.newton, tracer.Tracer._refine = solve, recorded
    print(json.dumps({"blas": [i.get("architecture") for i in threadpool_info()]}), flush=True)
    scene = load_scene(ROOT / "scenes" / f"{name}.toml").with_overrides({"surface.branches": "none"}, name=name)
    analyse(scene)


def widths(mapping) -> str:
    return "x" if mapping is None else ",".join(f"{w:.5f}" for w in mapping.widths)


def label(mapping, mappings) -> str:
    return ("current", "re-centred")[mappings.index(mapping)]


def main() -> None:
    print(f"# load average {os.getloadavg()[0]:.1f} at the start")
    jobs = [(scene, core) for scene in SCENES for core in CORES]
    lines = {}
    for start in range(0, len(jobs), PARALLEL):
        running = {}
        for scene, core in jobs[start:start + PARALLEL]:
            env = dict(os.environ) | ({} if core == "default" else {"OPENBLAS_CORETYPE": core})
            running[scene, core] = subprocess.Popen([sys.executable, __file__, "--worker", scene], env=env,
                                                    stdout=subprocess.PIPE, text=True)
        for job, process in running.items():
            out, _ = process.communicate()
            if process.returncode:
                raise SystemExit(f"{job}: worker exited with {process.returncode}")
            lines[job] = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
    print(f"{'scene':<24}{'kernels':<25}{'P':>10}{'degree':>11}  {'current map: widths, T':<30}"
          f"    {'re-centred map: widths, T':<30}{'ratio':>9}{'old rule':>12}{'kept now':>12}")
    for scene in SCENES:
        for core in CORES:
            blas, *decisions = lines[scene, core]
            for d in decisions:
                (w0, t0), (w1, t1) = d["maps"]
                print(f"{scene:<24}{core + '/' + blas['blas'][0]:<25}{d['P']:>10.6f}{d['from']:>5} -> {d['to']:<3}  "
                      f"{w0:<18}{t0:>12.4g}    {w1:<18}{t1:>12.4g}{t0 / t1:>9.3f}{d['old']:>12}{d['new']:>12}")
        kept = {core: [(round(d["P"], 6), d["to"], d["new"]) for d in lines[scene, core][1:]] for core in CORES}
        old = {core: [(round(d["P"], 6), d["to"], d["old"]) for d in lines[scene, core][1:]] for core in CORES}
        print(f"# {scene}: decisions kept now identical under {', '.join(CORES)}: "
              f"{all(k == kept[CORES[0]] for k in kept.values())}; old rule's identical: "
              f"{all(o == old[CORES[0]] for o in old.values())}")
    print(f"# load average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--worker"]:
        worker(sys.argv[2])
    else:
        main()
