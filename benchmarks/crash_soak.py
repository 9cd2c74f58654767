"""Crash soak: SIGKILL a `balloon-cg sweep` process group (parent and pool workers) at random instants, resume,
and check that nothing is lost or corrupted; then start pairs of `balloon-cg run` on one output at once.

Kills: each `sweep` (6 short primary-only members, 2 workers) is killed after a random delay drawn uniformly from
a window 1.5 times as long as an uninterrupted sweep, measured first (imports, members, the view rebuild); a
sweep that finishes first ends its round and the next round starts on a new output. After every kill, what is on disk must be readable
(the sweep file if present, every member file of the store); every round ends with an uninterrupted resume that
must exit 0 with every member bitwise equal (all datasets, and the members' results attributes) to an
uninterrupted serial sweep and leave no debris (temporary files, lock files, staging folders).

Collisions: two `run`s on one output, the second started 0-20 ms after the first, no --force: exactly one may
write it; the other must exit 2 with "in use by PID"; a "lost result" is both exiting 0.

Run: python benchmarks/crash_soak.py [KILLS [COLLISIONS]]  (default 200 and 20; output also in
benchmarks/results/crash_soak.txt; the test suite runs the same code with 6 kills (20 under -m slow) and 3 collisions:
tests/test_crash.py)
"""
import hashlib
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

CLI = "import sys; from balloon_cg.app.cli import main; sys.exit(main(sys.argv[1:]))"
SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 1.5\n'
VARY = "material.alpha[0]=1.3:1.4:6"
COLLIDE_SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 5\n'  # about 3 s of tracing
RESULT_ATTRS = ("overrides", "scene_hash", "branch_point_kinds", "branch_point_classifications",
                "branch_point_blocks", "branch_point_pressures", "complete", "incomplete_gaps")


def cli(*args) -> list[str]:
    """argv running the balloon-cg command line in a fresh interpreter."""
    return [sys.executable, "-c", CLI, *map(str, args)]


def sweep_argv(scene: Path, out: Path, workers: int = 2) -> list[str]:
    return cli("sweep", scene, "--vary", VARY, "-o", out, "--primary-only", "--workers", workers, "--quiet")


def member_digests(path: Path) -> dict:
    """{index: sha256 of every dataset (path, dtype, shape, bytes) and the results attributes} of a sweep file."""
    out = {}
    with h5py.File(path, "r") as f:
        for name, group in f["members"].items():
            h = hashlib.sha256()
            for key in RESULT_ATTRS:
                h.update(repr(np.asarray(group.attrs.get(key)).tolist()).encode())

            def visit(item_name, item):
                if isinstance(item, h5py.Dataset):
                    data = item[()]
                    h.update(f"{item_name} {data.dtype} {np.shape(data)}".encode())
                    h.update(np.asarray(data).tobytes() if data.dtype != object else repr(data.tolist()).encode())

            group.visititems(visit)
            out[int(name)] = h.hexdigest()
    return out


def debris(out: Path) -> list[str]:
    """What an interrupted sweep may leave beside its output and inside its store, after a resume: nothing."""
    from balloon_cg.io.sweep_file import store_path

    leftovers = [p.name for p in out.parent.iterdir() if p.name.startswith(f".{out.name}.")
                 or p.name in (f"{out.name}.members-new", f"{out.name}.members-old")]
    store = store_path(out)
    if store.is_dir():
        leftovers += [f"{store.name}/{p.name}" for p in store.iterdir() if p.name.startswith(".")]
    return leftovers


def temporary_files(out: Path) -> list[Path]:
    """The temporary files of writes in progress (or cut short) of a sweep: beside the output and in its store."""
    from balloon_cg.io.sweep_file import store_path

    found = list(out.parent.glob(f".{out.name}.*.tmp"))
    return found + (list(store_path(out).glob(".*.tmp")) if store_path(out).is_dir() else [])


def readable(out: Path) -> str:
    """'' if what a killed sweep left is readable (the sweep file if present, each stored member), else why not."""
    from balloon_cg.io.sweep_file import read_store, read_sweep, store_path

    try:
        if out.exists():
            read_sweep(out)
        if store_path(out).is_dir():
            read_store(store_path(out))
    except Exception as e:  # noqa: BLE001 - counted and reported
        return f"{type(e).__name__}: {e}"
    return ""


def soak(kills: int, workdir: Path, seed: int = 0, log=None) -> dict:
    """Kill sweeps ``kills`` times; returns the figures (kills, rounds, recovered, unrecoverable, lost, debris).

    The kill instants are uniform in (0.05 s, 1.5 T), T the wall time of an uninterrupted sweep on 2 workers
    measured first (so on a loaded machine the instants still cover the whole sweep, not only the imports)."""
    workdir = Path(workdir)
    scene = workdir / "scene.toml"
    scene.write_text(SCENE)
    reference = workdir / "reference.h5"
    subprocess.run(sweep_argv(scene, reference, workers=1), check=True, capture_output=True)
    expected = member_digests(reference)
    start = time.perf_counter()
    subprocess.run(sweep_argv(scene, workdir / "timing.h5"), check=True, capture_output=True)
    window = (0.05, 1.5 * (time.perf_counter() - start))
    rng = random.Random(seed)
    figures = {"kills": 0, "rounds": 0, "recovered": 0, "unrecoverable": [], "lost": 0, "debris": [],
               "failed_resumes": [], "window": window, "cut_writes": 0}
    start = time.perf_counter()
    out, killed_in_round = None, 0
    while figures["kills"] < kills or killed_in_round:
        if out is None:
            out = workdir / f"round{figures['rounds']}.h5"
            figures["rounds"] += 1
            killed_in_round = 0
        process = subprocess.Popen(sweep_argv(scene, out), start_new_session=True, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.PIPE)
        kill_now = figures["kills"] < kills
        try:
            _, err = process.communicate(timeout=rng.uniform(*window) if kill_now else 120)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.communicate()
            _wait_group_gone(process.pid)
            figures["kills"] += 1
            killed_in_round += 1
            figures["cut_writes"] += bool(temporary_files(out))
            problem = readable(out)
            if problem:
                figures["unrecoverable"].append(problem)
            continue
        if process.returncode != 0:  # a resume must complete
            figures["failed_resumes"].append(err.decode(errors="replace").strip())
            out = None
            continue
        if killed_in_round:
            figures["recovered"] += 1
        found = member_digests(out)
        figures["lost"] += sum(found.get(i) != d for i, d in expected.items())
        figures["debris"] += debris(out)
        if log:
            log(f"round {figures['rounds']}: {killed_in_round} kills, resumed; {figures['kills']} kills so far")
        out = None
    figures["seconds"] = time.perf_counter() - start
    return figures


def _wait_group_gone(pgid: int, timeout: float = 10.0) -> None:
    """Wait until no process of the group is alive (SIGKILL is asynchronous for the workers)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return
        if all(_zombie(pid) for pid in _group_members(pgid)):
            return
        time.sleep(0.02)


def _group_members(pgid: int) -> list[int]:
    pids = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[2]) == pgid:
                pids.append(int(entry.name))
    return pids


def _zombie(pid: int) -> bool:
    try:
        return (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()[0] == "Z"
    except OSError:
        return True


def collide(count: int, workdir: Path, seed: int = 1) -> dict:
    """Pairs of `run` on one output (no --force), the second 0-20 ms after the first: tried, lost, refused."""
    workdir = Path(workdir)
    scene = workdir / "collide.toml"
    scene.write_text(COLLIDE_SCENE)
    rng = random.Random(seed)
    figures = {"collisions": 0, "lost": 0, "refused_in_use": 0, "sequential": 0, "other": []}
    for i in range(count):
        out = workdir / f"collide{i}.h5"
        argv = cli("run", scene, "-o", out, "--primary-only", "--quiet")
        first = subprocess.Popen(argv, stderr=subprocess.PIPE, text=True)
        time.sleep(rng.uniform(0, 0.02))
        second = subprocess.Popen(argv, stderr=subprocess.PIPE, text=True)
        results = [(p.wait(), p.stderr.read()) for p in (first, second)]
        figures["collisions"] += 1
        codes = sorted(code for code, _ in results)
        if codes == [0, 0]:
            figures["lost"] += 1
        elif codes == [0, 2] and any("in use by PID" in err and "--force" not in err for _, err in results):
            figures["refused_in_use"] += 1
        elif codes == [0, 2] and any("already exists" in err for _, err in results):
            figures["sequential"] += 1  # the second claimed only after the first had finished (a loaded machine)
        else:
            figures["other"].append(results)
    return figures


def main(argv) -> int:
    kills = int(argv[0]) if argv else 200
    count = int(argv[1]) if len(argv) > 1 else 20
    with tempfile.TemporaryDirectory() as tmp:
        figures = soak(kills, Path(tmp), log=lambda line: print(line, file=sys.stderr))
        clash = collide(count, Path(tmp))
    rows = [("kills tried (SIGKILL to the sweep's process group)", figures["kills"]),
            ("rounds (each ends with an uninterrupted resume)", figures["rounds"]),
            ("kills that cut a file write (temporary file left)", figures["cut_writes"]),
            ("rounds with kills recovered by the resume", figures["recovered"]),
            ("states left unreadable by a kill", len(figures["unrecoverable"])),
            ("resumes that failed", len(figures["failed_resumes"])),
            ("members lost or not bitwise equal", figures["lost"]),
            ("debris after the resumes", len(figures["debris"])),
            ("kill instants drawn in (s)", "({:.2f}, {:.2f})".format(*figures["window"])),
            ("soak time (s)", f"{figures['seconds']:.0f}"),
            ("concurrent-run collisions tried", clash["collisions"]),
            ("collisions with a lost result (both exit 0)", clash["lost"]),
            ("collisions refused at once with 'in use by PID'", clash["refused_in_use"]),
            ("pairs that did not overlap (second found the file written)", clash["sequential"])]
    width = max(len(r[0]) for r in rows)
    text = "\n".join([f"{name:<{width}}  {value}" for name, value in rows]
                     + [f"   {problem}" for problem in figures["unrecoverable"] + figures["failed_resumes"]
                        + figures["debris"] + clash["other"]])
    print(text)
    (Path(__file__).resolve().parent / "results" / "crash_soak.txt").write_text(text + "\n")
    bad = (figures["unrecoverable"] or figures["failed_resumes"] or figures["lost"] or figures["debris"]
           or clash["lost"] or clash["other"])
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
