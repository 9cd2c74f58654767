"""The sweep store (io.sweep_file): one file per member, the sweep file a view rebuilt from it; --force replaces
an old sweep only once the new one is complete; single-file sweeps of format /1 still read and resume."""
import shutil
from pathlib import Path

import h5py
import pytest

from balloon_cg.app import sweep as sweep_module
from balloon_cg.app.cli import main
from balloon_cg.app.sweep import run_sweep
from balloon_cg.io.sweep_file import (SweepError, SweepFileError, read_sweep, staging_path, store_path)
from balloon_cg.scene import parse_scene

SCENE = parse_scene('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 1.5\n', "small")
SPECS = ["material.alpha[0]=1.3,1.35"]
MODE = "primary-only"


def failing(index, *args):
    raise RuntimeError("boom")


@pytest.fixture
def done(tmp_path) -> Path:
    path = tmp_path / "s.h5"
    assert run_sweep(SCENE, SPECS, path, mode=MODE, workers=1).computed == [0, 1]
    return path


def test_members_are_files_and_the_view_is_rebuilt_from_them(done):
    assert sorted(p.name for p in store_path(done).iterdir()) == ["000000.h5", "000001.h5", "sweep.h5"]
    view = read_sweep(done)
    assert sorted(view["members"]) == [0, 1] and view["attrs"]["format"] == "balloon-cg-sweep/3"
    done.unlink()  # the view is never the only copy: a resume rebuilds it without computing
    again = run_sweep(SCENE, SPECS, done, mode=MODE, workers=1)
    assert again.computed == [] and again.skipped == [0, 1] and sorted(read_sweep(done)["members"]) == [0, 1]


def test_force_whose_members_all_fail_keeps_the_old_sweep(done, monkeypatch):
    before = done.read_bytes()
    other = ["material.alpha[0]=1.3,1.4"]
    monkeypatch.setattr(sweep_module, "compute_member", failing)
    result = run_sweep(SCENE, other, done, mode=MODE, workers=1, force=True)
    assert sorted(result.failed) == [0, 1] and not result.replaced
    assert done.read_bytes() == before and sorted(read_sweep(done)["members"]) == [0, 1]
    monkeypatch.undo()
    result = run_sweep(SCENE, other, done, mode=MODE, workers=1, force=True)  # the replacement resumes, completes
    assert result.replaced and result.computed == [0, 1]
    assert read_sweep(done)["members"][1]["overrides"] == {"material.alpha[0]": 1.4}
    assert not staging_path(done).exists() and not done.with_name("s.h5.members-old").exists()


def test_cli_force_that_fails_says_the_old_file_is_kept(done, monkeypatch, capsys, tmp_path):
    scene = tmp_path / "small.toml"
    scene.write_text(SCENE.text)
    monkeypatch.setattr(sweep_module, "compute_member", failing)
    argv = ["sweep", str(scene), "--vary", "material.alpha[0]=1.3,1.4", "-o", str(done), "--primary-only",
            "--workers", "1", "--quiet", "--force"]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "2 of 2 sweep members failed" in err and "is kept" in err


def test_a_replacement_cut_between_its_renames_is_rolled_forward(done, monkeypatch):
    other = ["material.alpha[0]=1.3,1.4"]
    real = sweep_module.commit_replacement

    def cut(path):  # killed after the old store moved away, before the new one moved in
        store_path(path).rename(path.with_name(path.name + ".members-old"))
        raise KeyboardInterrupt

    monkeypatch.setattr(sweep_module, "commit_replacement", cut)
    with pytest.raises(KeyboardInterrupt):
        run_sweep(SCENE, other, done, mode=MODE, workers=1, force=True)
    monkeypatch.setattr(sweep_module, "commit_replacement", real)
    result = run_sweep(SCENE, other, done, mode=MODE, workers=1)
    assert result.computed == [] and result.skipped == [0, 1]
    assert read_sweep(done)["members"][1]["overrides"] == {"material.alpha[0]": 1.4}


def test_a_damaged_member_file_is_computed_again(done):
    (store_path(done) / "000001.h5").write_bytes(b"not hdf5")
    result = run_sweep(SCENE, SPECS, done, mode=MODE, workers=1)
    assert result.skipped == [0] and result.computed == [1]


def test_single_file_sweep_of_format_1_reads_and_resumes(done):
    shutil.rmtree(store_path(done))
    with h5py.File(done, "a") as f:  # the layout of balloon-cg-sweep/1: the same groups, appended in place
        f.attrs["format"] = "balloon-cg-sweep/1"
        del f.attrs["store"]
        del f["members/1"]
        f["members"].create_group(".tmp-1-deadbeef")  # a member cut before its rename
    assert sorted(read_sweep(done)["members"]) == [0]
    result = run_sweep(SCENE, SPECS, done, mode=MODE, workers=1)
    assert result.skipped == [0] and result.computed == [1]
    assert read_sweep(done)["attrs"]["format"] == "balloon-cg-sweep/3"


def test_a_damaged_single_file_sweep_is_one_line(tmp_path, capsys):
    path = tmp_path / "old.h5"
    path.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 200)  # a corrupted file: HDF5 signature, nothing else
    with pytest.raises(SweepFileError, match="not a readable HDF5 file"):
        read_sweep(path)
    with pytest.raises(SweepFileError, match="not a readable HDF5 file"):
        run_sweep(SCENE, SPECS, path, mode=MODE, workers=1)
    scene = tmp_path / "small.toml"
    scene.write_text(SCENE.text)
    assert main(["inspect", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and "Traceback" not in err
    assert run_sweep(SCENE, SPECS, path, mode=MODE, workers=1, force=True).replaced  # replaced once complete
    assert sorted(read_sweep(path)["members"]) == [0, 1]


def test_member_count_is_refused_before_expanding(tmp_path, capsys):
    import time

    scene = tmp_path / "small.toml"
    scene.write_text(SCENE.text)
    start = time.process_time()  # CPU time: a loaded machine stretches the wall clock, not the work
    assert main(["sweep", str(scene), "--vary", "material.alpha[0]=1:1.001:10000000", "-o", str(tmp_path / "x.h5")]) == 2
    assert time.process_time() - start < 5
    assert "at most 10000 members" in capsys.readouterr().err
    with pytest.raises(SweepError, match="200000 members; at most 10000"):
        run_sweep(SCENE, ["material.alpha[0]=1.2:1.4:400", "continuation.stop_stretch=2:3:500"], tmp_path / "y.h5")
    assert not (tmp_path / "x.h5").exists() and not store_path(tmp_path / "y.h5").exists()


def test_a_signal_while_an_old_sweep_is_imported_stops_after_the_import(done, monkeypatch):
    """Opening a /1 sweep copies its members into a store; a signal then is raised once the store is open (never
    inside h5py, where a KeyboardInterrupt can surface as a SystemError): the member copied, the old file as it
    was, and the same command resumes from the store."""
    import os
    import signal

    from balloon_cg.io import sweep_file
    from balloon_cg.numerics import interrupt

    shutil.rmtree(store_path(done))
    with h5py.File(done, "a") as f:
        f.attrs["format"] = "balloon-cg-sweep/1"
        del f.attrs["store"]
        del f["members/1"]
    copy = sweep_file.copy_tree

    def signalled_copy(source, target):
        os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C while the member is copied
        copy(source, target)

    monkeypatch.setattr(sweep_file, "copy_tree", signalled_copy)
    try:
        with pytest.raises(KeyboardInterrupt):
            run_sweep(SCENE, SPECS, done, mode=MODE, workers=1)
    finally:
        interrupt._flag.clear()  # the flag the held signal set (a process would exit here)
    monkeypatch.setattr(sweep_file, "copy_tree", copy)
    assert sorted(p.name for p in store_path(done).glob("0*.h5")) == ["000000.h5"]  # the import finished
    assert sorted(read_sweep(done)["members"]) == [0]
    result = run_sweep(SCENE, SPECS, done, mode=MODE, workers=1)
    assert result.skipped == [0] and result.computed == [1]
