"""Pool workers die with their parent (numerics.hygiene): killing only the sweep's parent, as the OOM killer does,
leaves no worker running."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

CLI = "import sys; from balloon_cg.app.cli import main; sys.exit(main(sys.argv[1:]))"
SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 4\n'


def children(pid: int) -> list[int]:
    found = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        found += [int(c) for c in (task / "children").read_text().split()]
    return found


def alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_workers_exit_when_the_parent_is_killed(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE)
    parent = subprocess.Popen([sys.executable, "-c", CLI, "sweep", str(scene), "--vary", "material.alpha[0]=1.3:1.4:8",
                               "-o", str(tmp_path / "s.h5"), "--primary-only", "--workers", "2", "--quiet"],
                              start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        workers = []
        while len(workers) < 2 and time.monotonic() < deadline and parent.poll() is None:
            time.sleep(0.05)
            workers = children(parent.pid)
        assert len(workers) == 2, "the pool did not start"
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        deadline = time.monotonic() + 60  # a hang guard: the loop ends as soon as they are gone
        while any(map(alive, workers)) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(map(alive, workers)), f"workers {workers} outlived their parent"
    finally:
        for pid in [parent.pid]:
            try:
                os.killpg(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


def test_the_watchdog_fallback_exits_when_the_parent_dies(tmp_path):
    """The path taken where prctl is not available: a thread polling os.getppid()."""
    pid_file = tmp_path / "child.pid"
    script = ("import os, sys, threading, time\n"
              "from balloon_cg.numerics import hygiene\n"
              "pid = os.fork()\n"
              "if pid == 0:\n"
              "    threading.Thread(target=hygiene._watch, args=(os.getppid(),), daemon=True).start()\n"
              f"    open({str(pid_file)!r}, 'w').write(str(os.getpid()))\n"
              "    time.sleep(60)\n"
              "    os._exit(0)\n"
              "time.sleep(60)\n")
    parent = subprocess.Popen([sys.executable, "-c", script], start_new_session=True)
    try:
        deadline = time.monotonic() + 30
        while not (pid_file.exists() and pid_file.read_text()) and time.monotonic() < deadline:
            time.sleep(0.05)
        child = int(pid_file.read_text())
        assert alive(child)
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        deadline = time.monotonic() + 30  # a hang guard (the child sleeps 60 s): ends as soon as it is gone
        while alive(child) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not alive(child), "the watchdog did not end the orphaned child"
    finally:
        try:
            os.killpg(parent.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def test_a_worker_whose_parent_is_a_zombie_exits_at_once():
    """A worker starting while its killed parent is not yet reaped (a zombie: the pid still answers ``os.kill``)
    asked for the death signal too late: it exits at once (test_workers_exit_when_the_parent_is_killed failed once
    under load, its workers running on after the kill: a worker's initializer ran between the kill and the reaping)."""
    zombie = subprocess.Popen([sys.executable, "-c", "pass"])
    deadline = time.monotonic() + 60
    while alive(zombie.pid) and time.monotonic() < deadline:  # exited, not waited for: a zombie
        time.sleep(0.05)
    try:
        assert Path(f"/proc/{zombie.pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z"
        worker = subprocess.run([sys.executable, "-c", "from balloon_cg.numerics.hygiene import worker_hygiene; "
                                 f"worker_hygiene({zombie.pid}); print('running')"], capture_output=True, text=True,
                                timeout=120)
        assert worker.returncode == 1 and "running" not in worker.stdout, (worker.returncode, worker.stdout)
    finally:
        zombie.wait()
