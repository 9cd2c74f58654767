"""Exclusive ownership of an output (io.lock): a second writer fails at once naming the owner's PID and never
advises --force; a killed owner's lock is stale and taken over; debris of killed writers is removed."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from balloon_cg.app.cli import main
from balloon_cg.io.lock import OutputInUse, claim, lock_path

CLI = "import sys; from balloon_cg.app.cli import main; sys.exit(main(sys.argv[1:]))"
SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = {stop}\n'


def scene_file(tmp_path, stop=1.5) -> Path:
    path = tmp_path / f"s{stop}.toml"
    path.write_text(SCENE.format(stop=stop))
    return path


def test_second_claim_fails_at_once_naming_the_owner(tmp_path):
    out = tmp_path / "out.h5"
    with claim(out):
        assert lock_path(out).read_text().split()[0] == str(os.getpid())
        with pytest.raises(OutputInUse, match=rf"in use by PID {os.getpid()}") as info:
            with claim(out):
                pass
        assert "--force" not in str(info.value)
    assert not lock_path(out).exists()
    with claim(out):  # released: free again
        pass


def test_lock_of_a_killed_owner_is_taken_over(tmp_path):
    out = tmp_path / "out.h5"
    holder = subprocess.Popen([sys.executable, "-c", "import sys, time; from balloon_cg.io.lock import claim\n"
                               "with claim(sys.argv[1]):\n    print('held', flush=True); time.sleep(60)", str(out)],
                              stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline().strip() == "held"
    with pytest.raises(OutputInUse, match=f"PID {holder.pid}"):
        with claim(out):
            pass
    holder.send_signal(signal.SIGKILL)
    holder.wait()
    assert lock_path(out).exists()  # left behind by the killed owner: stale
    with claim(out):
        assert lock_path(out).read_text().split()[0] == str(os.getpid())


def test_run_on_an_output_in_use_fails_without_advising_force(tmp_path, capsys):
    out = tmp_path / "run.h5"
    with claim(out):
        assert main(["run", str(scene_file(tmp_path)), "-o", str(out), "--primary-only", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"in use by PID {os.getpid()}" in err and "--force" not in err and err.count("\n") == 1
    assert not out.exists()


def test_second_sweep_on_a_running_sweep_is_refused_and_the_first_completes(tmp_path):
    out, scene = tmp_path / "sweep.h5", scene_file(tmp_path, stop=4)  # about 0.4 s a member
    argv = [sys.executable, "-c", CLI, "sweep", str(scene), "--vary", "material.alpha[0]=1.3:1.4:16", "-o", str(out),
            "--primary-only", "--workers", "1", "--quiet"]
    first = subprocess.Popen(argv, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not lock_path(out).exists() and time.monotonic() < deadline:
        time.sleep(0.02)
    second = subprocess.run(argv, capture_output=True, text=True)
    assert first.wait() == 0, first.stderr.read()
    assert second.returncode == 2
    assert f"in use by PID {first.pid}" in second.stderr and "--force" not in second.stderr
    from balloon_cg.io.sweep_file import read_sweep

    assert sorted(read_sweep(out)["members"]) == list(range(16))


def test_debris_of_killed_writers_is_removed_on_start_and_none_left_on_exit(tmp_path):
    out, scene = tmp_path / "run.h5", scene_file(tmp_path)
    old = [tmp_path / f".run.h5.{h}.tmp" for h in ("0123456789ab", "deadbeef0000")]
    for p in old:
        p.write_bytes(b"half a file")
    unrelated = tmp_path / ".other.h5.0123456789ab.tmp"
    unrelated.write_bytes(b"not ours")
    assert main(["run", str(scene), "-o", str(out), "--primary-only", "--quiet"]) == 0
    assert not any(p.exists() for p in old) and unrelated.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([".other.h5.0123456789ab.tmp", "run.h5", scene.name])


def test_critical_on_an_output_in_use_fails_at_once(tmp_path, capsys):
    out = tmp_path / "curve.h5"
    with claim(out):
        assert main(["critical", str(scene_file(tmp_path)), "--parameter", "alpha1", "-o", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"in use by PID {os.getpid()}" in err and "--force" not in err
