"""CPU time of writing and reading a run file (issue 37): this checkout against another interpreter's install.

    python benchmarks/run_file_io.py --make CACHE          # analyse the scenes once, pickle what write_run takes
    python benchmarks/run_file_io.py --compare CACHE OTHER_PYTHON [--reps N]

``--make`` runs spom1 to stop_stretch 2 and the two-coil scene (spom1_two_coils_M0.002, stop_stretch 1.7) and pickles
(scene, branches, snaps, found) per scene, so both installs write the same analysis. ``--compare`` runs ``--time``
in both interpreters (each its own process, alternately per repetition) and prints the median CPU seconds
(time.process_time) of ``write_run``, ``read_run`` and ``io.layout.file_kind`` (what the CLI asks before it
reads) per scene and their ratio other / this; the load average is
printed with the table.
"""
import argparse
import json
import os
import pickle
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SCENES = {"spom1": ("spom1", {"continuation.stop_stretch": "2"}),
          "two_coils": ("spom1_two_coils_M0.002", {"continuation.stop_stretch": "1.7"})}


def make(cache: Path) -> None:
    from balloon_cg.app.api import computed
    from balloon_cg.app.cli import configured

    cache.mkdir(parents=True, exist_ok=True)
    for key, (name, settings) in SCENES.items():
        scene, _ = configured(argparse.Namespace(scene=name, settings=[f"{k}={v}" for k, v in settings.items()],
                                                 unset=[]))
        branches, snaps, found, _, _ = computed(scene)
        (cache / f"{key}.pkl").write_bytes(pickle.dumps((scene, branches, snaps, found)))


def time_once(cache: Path) -> dict:
    """CPU seconds of one write_run and one read_run of each cached scene."""
    from balloon_cg.io.layout import file_kind
    from balloon_cg.io.run_file import read_run, write_run

    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for key in SCENES:
            scene, branches, snaps, found = pickle.loads((cache / f"{key}.pkl").read_bytes())
            path = Path(tmp) / f"{key}.h5"
            t0 = time.process_time()
            write_run(path, scene, branches, snaps=snaps, found=found, extra_attrs={"command": "benchmark"})
            t1 = time.process_time()
            read_run(path)
            t2 = time.process_time()
            file_kind(path)
            out[key] = {"write": t1 - t0, "read": t2 - t1, "kind": time.process_time() - t2}
    return out


def compare(cache: Path, other: str, reps: int) -> None:
    runs = {"this": [], "other": []}
    for _ in range(reps):
        for who, python in (("other", other), ("this", sys.executable)):
            text = subprocess.run([python, __file__, "--time", str(cache)], check=True, capture_output=True,
                                  text=True, cwd=Path(__file__).parent).stdout
            runs[who].append(json.loads(text.splitlines()[-1]))
    print(f"load average after: {os.getloadavg()[0]:.2f} (1 min); reps {reps}; CPU s, median; other = {other}")
    print(f"{'scene':<10} {'op':<6} {'other':>8} {'this':>8} {'other/this':>11}")
    for key in SCENES:
        for op in ("write", "read", "kind"):
            a = statistics.median(r[key][op] for r in runs["other"])
            b = statistics.median(r[key][op] for r in runs["this"])
            print(f"{key:<10} {op:<6} {a:8.3f} {b:8.3f} {a / b:11.2f}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--make", type=Path)
    parser.add_argument("--time", type=Path)
    parser.add_argument("--compare", nargs=2)
    parser.add_argument("--reps", type=int, default=5)
    args = parser.parse_args()
    if args.make:
        make(args.make)
    elif args.time:
        print(json.dumps(time_once(args.time)))
    else:
        print(f"load average: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
        compare(Path(args.compare[0]), args.compare[1], args.reps)
