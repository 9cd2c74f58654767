"""Benchmark: the two loops-anywhere scenes of docs/scenes.md run whole (`balloon-cg run`), each in a fresh
process: the tilted loop (SPOM1 beside one loop of the paper's pair turned by 30°) with ``[surface] branches =
"all"``, and the displaced loop (the same loop moved sideways by 0.5). Prints per scene the wall time, the CPU time
of the run and its children, whether it finished within ``--timeout`` (if not, the run is stopped by SIGTERM and
what it had finished is read back from its file), the verdict line, the run file's phase times and each branch's
points and degree, with the load average before and after (issue 37: measured before
and after; the displaced loop took 90 min and ended ``limited`` at degree 112 in session 14).
Run: python benchmarks/loops_anywhere.py [--scene tilted|displaced] [--timeout S] [--note TEXT]
(appends to benchmarks/results/loops_anywhere.txt)
"""
import argparse
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LOOP = "[material]\npreset = \"SPOM1\"\n[field]\nchi = 1.0\nM = 0.002\n[[field.coils]]\nradius = 1.7321\n"
STOP = "[continuation]\nstop_stretch = 1.6\nwire_gap = 0.1\n"
SCENES = {
    "tilted": LOOP + "centre = [0.5, 0.0, 0.8660254037844386]\nnormal = [0.5, 0.0, 0.8660254037844386]\n"
              "current = 1.0\n" + STOP + "[surface]\nbranches = \"all\"\n",
    "displaced": LOOP + "centre = [0.5, 0.0, 1.0]\nnormal = [0.0, 0.0, 1.0]\ncurrent = 1.0\n" + STOP,
}
SUMMARY_KEYS = ("result", "run time")


def children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_scene(name: str, folder: Path, timeout: float) -> list[str]:
    """One `balloon-cg run` of a scene in a fresh process: the lines of the report."""
    scene = folder / f"{name}_loop.toml"
    scene.write_text(SCENES[name])
    out = folder / f"{name}_loop.h5"
    argv = [sys.executable, "-m", "balloon_cg", "run", str(scene), "-o", str(out), "--allow-partial", "--force"]
    load, cpu, start = os.getloadavg(), children_cpu(), time.perf_counter()
    child = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                             start_new_session=True)  # its own process group: its workers end with it
    try:
        text = child.communicate(timeout=timeout)[0]
        finished = child.returncode == 0
    except subprocess.TimeoutExpired:
        os.killpg(child.pid, signal.SIGTERM)
        text = f"stopped after the timeout of {timeout:.0f} s\n" + child.communicate()[0]
        finished = False
        if out.exists():  # what was finished is written, flagged interrupted
            text += subprocess.run([sys.executable, "-m", "balloon_cg", "inspect", str(out)], capture_output=True,
                                   text=True).stdout
    wall, cpu = time.perf_counter() - start, children_cpu() - cpu
    lines = [f"{name} loop: wall {wall:.1f} s, CPU {cpu:.1f} s (run and children), "
             f"{'finished' if finished else 'NOT finished'}; load average before {load[0]:.2f}, "
             f"after {os.getloadavg()[0]:.2f}"]
    kept = [line for line in text.splitlines() if line.startswith(SUMMARY_KEYS) or line.startswith("branch ")
            or line.lstrip().startswith(("points ", "stop reason", "special points", "max error estimate"))
            or " LP " in line or " BP " in line or "except" in line or "stopped" in line or "interrupted" in line]
    return lines + ["  " + line for line in kept]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", choices=sorted(SCENES), action="append")
    parser.add_argument("--timeout", type=float, default=2700.0, help="seconds per scene (default 45 min)")
    parser.add_argument("--note", default="", help="a line naming the install (commit) and the machine's state")
    args = parser.parse_args()
    lines = [f"# benchmarks/loops_anywhere.py {args.note}".rstrip(), f"# cores: {os.cpu_count()}"]
    with tempfile.TemporaryDirectory() as folder:
        for name in args.scene or sorted(SCENES, reverse=True):
            lines += run_scene(name, Path(folder), args.timeout)
    text = "\n".join(lines)
    print(text)
    with open(ROOT / "benchmarks" / "results" / "loops_anywhere.txt", "a") as results:
        results.write(text + "\n\n")


if __name__ == "__main__":
    main()
