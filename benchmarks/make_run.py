"""Benchmark: a fresh clone's ``make run`` (issue 37's floor: ≤ 45 s on an idle 2-core machine, the install and
the first numba compile included), where its time goes, two commits against each other.

Per commit and round: a fresh clone (``git clone`` of this repository, the commit checked out), a fresh venv
(``python3 -m venv``) and a fresh cache folder (XDG_CACHE_HOME: numba's cache and pip's), then three phases:

    install   ``make install``: pip resolves, builds the editable wheel and installs the dependencies
    run cold  what ``make run`` runs after its install, the first time: numba compiles every kernel it calls
              into its cache, Python compiles the bytecode of what it imports that the install left uncompiled
    run warm  the same again: the cold run's extra is the difference

``make run`` on a fresh clone is install + run cold. Each phase's wall time and CPU time (user + system of the
process and every descendant it waited for: the default run's child and its forked workers, pip's build
process); the CPU ratio is the steadier one on a loaded machine. The commits alternate within a round and swap
their order from one round to the next. PYTHONDONTWRITEBYTECODE is left unset in the phases (an ordinary machine;
the Makefile compiles at install time where it is set), unless ``--no-bytecode`` sets it.

    python benchmarks/make_run.py --old main --new HEAD [--rounds 2] [--no-bytecode]
"""
import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PHASES = ("install", "run cold", "run warm")


def timed(args, env, cwd) -> tuple[float, float]:
    """(wall, CPU) seconds of one command and its waited-for descendants; its output is discarded."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([str(a) for a in args], env=env, cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        sys.exit(f"{' '.join(map(str, args))} failed ({done.returncode}):\n{done.stdout[-2000:]}{done.stderr[-2000:]}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def commit_of(ref: str) -> str:
    return subprocess.run(["git", "-C", ROOT, "rev-parse", "--verify", f"{ref}^{{commit}}"], check=True,
                          capture_output=True, text=True).stdout.strip()


def measured(commit: str, folder: Path, bytecode: bool) -> dict:
    """{phase: (wall, CPU)} of one fresh clone of ``commit`` in ``folder``."""
    common = subprocess.run(["git", "-C", ROOT, "rev-parse", "--path-format=absolute", "--git-common-dir"],
                            check=True, capture_output=True, text=True).stdout.strip()
    clone, venv, out = folder / "clone", folder / "venv", folder / "out"
    subprocess.run(["git", "clone", "--quiet", "--no-checkout", common, clone], check=True)
    subprocess.run(["git", "-C", clone, "checkout", "--quiet", commit], check=True)
    subprocess.run([sys.executable, "-m", "venv", venv], check=True)
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "PYTHONPATH", "VIRTUAL_ENV", "PYTHONDONTWRITEBYTECODE")}
    env.update(XDG_CACHE_HOME=str(folder / "cache"), **({} if bytecode else {"PYTHONDONTWRITEBYTECODE": "1"}))
    python = venv / "bin" / "python"
    run = [python, "-m", "balloon_cg.app.default_run", out, "--quiet"]
    return {"install": timed(["make", "-C", clone, "install", f"PYTHON={python}"], env, folder),
            "run cold": timed(run, env, folder), "run warm": timed(run, env, folder)}


def load() -> str:
    one, five, _ = os.getloadavg()
    return f"load {one:.1f} (1 min), {five:.1f} (5 min)"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", default="main", help="the commit measured first in round 1 (default: main)")
    parser.add_argument("--new", default="HEAD", help="the commit against it (default: HEAD)")
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument("--no-bytecode", action="store_true", help="PYTHONDONTWRITEBYTECODE=1 in every phase")
    options = parser.parse_args()
    commits = {"old": commit_of(options.old), "new": commit_of(options.new)}
    print(f"old {options.old} = {commits['old'][:10]}, new {options.new} = {commits['new'][:10]}; "
          f"{os.cpu_count()} CPUs; PYTHONDONTWRITEBYTECODE {'set' if options.no_bytecode else 'unset'}")
    results = {"old": [], "new": []}
    with tempfile.TemporaryDirectory(prefix="make_run_") as tmp:
        for r in range(options.rounds):
            for side in ("old", "new") if r % 2 == 0 else ("new", "old"):
                folder = Path(tmp) / f"{side}{r}"
                folder.mkdir()
                before = load()
                results[side].append(measured(commits[side], folder, not options.no_bytecode))
                row = results[side][-1]
                print(f"round {r + 1} {side}: " + ", ".join(f"{p} {w:.1f} s wall / {c:.1f} s CPU"
                                                           for p, (w, c) in row.items()) + f"; {before}, then {load()}")
    print(f"\n{'phase':<26} {'old wall':>9} {'new wall':>9} {'ratio':>6} {'old CPU':>8} {'new CPU':>8} {'ratio':>6}")
    for r in range(options.rounds):
        rows = {p: (results["old"][r][p], results["new"][r][p]) for p in PHASES}
        rows["make run (install + cold)"] = tuple(
            tuple(a + b for a, b in zip(run["install"], run["run cold"])) for run in
            (results["old"][r], results["new"][r]))
        rows["cold - warm (compiles)"] = tuple(
            tuple(c - w for c, w in zip(run["run cold"], run["run warm"])) for run in
            (results["old"][r], results["new"][r]))
        for name, ((ow, oc), (nw, nc)) in rows.items():
            print(f"{name:<26} {ow:9.1f} {nw:9.1f} {nw / ow:6.2f} {oc:8.1f} {nc:8.1f} {nc / oc:6.2f}")
        print()


if __name__ == "__main__":
    main()
