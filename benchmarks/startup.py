"""Benchmark: what the command line costs beyond its computation (warm numba cache).

For each command, the wall time of the whole process (best of REPEATS, in alternating rounds) against the time of
its computation alone, measured inside a warm process on the same input (the part a faster start-up cannot
remove). Prints the table and the ratios. Run: python benchmarks/startup.py
"""
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPEATS = 3
ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "scenes" / "spom1.toml"


def wall(args) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "balloon_cg", *map(str, args)], check=True, capture_output=True)
    return time.perf_counter() - start


COMPUTE = """
import sys, time
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.primary import trace_primary
from balloon_cg.app.summaries import summarise_file
from balloon_cg.scene import load_scene
scene = load_scene(sys.argv[1])
analyse(scene); trace_primary(scene, stop_stretch=3.0, down=False); summarise_file(sys.argv[2])  # warm
def best(f):
    times = []
    for _ in range(3):
        t = time.perf_counter(); f(); times.append(time.perf_counter() - t)
    return min(times)
print(best(lambda: analyse(scene)), best(lambda: trace_primary(scene, stop_stretch=3.0, down=False)),
      best(lambda: summarise_file(sys.argv[2])))
"""


def main():
    with tempfile.TemporaryDirectory() as tmp:
        run_file = Path(tmp) / "run.h5"
        wall(["run", SCENE, "-o", run_file, "--quiet"])  # warms the numba cache
        out = subprocess.run([sys.executable, "-c", COMPUTE, str(SCENE), str(run_file)], check=True,
                             capture_output=True, text=True).stdout.split()
        compute = dict(zip(("run", "solve", "inspect"), map(float, out)))
        compute["--help"] = compute["--version"] = 0.0
        commands = {"--help": ["--help"], "--version": ["--version"], "inspect": ["inspect", run_file],
                    "solve": ["solve", SCENE, "--pole-stretch", "3.0"],
                    "run": ["run", SCENE, "-o", run_file, "--quiet", "--force"]}
        walls = {name: [] for name in commands}
        for _ in range(REPEATS):  # alternating rounds: a noisy moment hits every command alike
            for name, args in commands.items():
                walls[name].append(wall(args))
    print(f"{'command':<28} {'wall (s)':>9} {'compute (s)':>12} {'wall/compute':>13}")
    for name, args in commands.items():
        w, c = min(walls[name]), compute[name]
        label = " ".join(str(a) if not isinstance(a, Path) else a.name for a in args)[:28]
        print(f"{label:<28} {w:9.3f} {c:12.3f} {w / c if c else float('nan'):13.2f}")
    print("\ncompute: the same work in a warm process (run: analyse; solve: the trace to λ2(0) = 3; inspect: the "
          "summary of the run file). Targets (issue 12): --help, --version <= 0.3 s, inspect <= 0.8 s, "
          "run <= 2x compute.")


if __name__ == "__main__":
    main()
