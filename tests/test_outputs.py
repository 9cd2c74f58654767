"""The one rule for outputs (io.output): an existing file of any kind, or a sweep's member store, is replaced only
with --force; the store belongs to its sweep file; the folder is checked before anything is computed."""
import os
import stat

import h5py
import pytest

from balloon_cg.app.cli import main
from balloon_cg.io.output import check_output, companions, store_path
from balloon_cg.io.sweep_file import read_sweep

SCENE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 1.3\nmax_points = 40\n'


@pytest.fixture
def scene(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(SCENE)
    return path


def sweep_argv(scene, out, *extra):
    return ["sweep", str(scene), "--vary", "stop_stretch=1.2,1.3", "--primary-only", "--workers", "1",
            "--quiet", "-o", str(out), *extra]


def one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def test_issue30_repro1_a_sweep_never_replaces_a_run_file_without_force(scene, tmp_path, capsys):
    out = tmp_path / "s.h5"
    assert main(sweep_argv(scene, out)) == 0
    assert store_path(out).is_dir()
    assert main(["run", str(scene), "-o", str(out), "--force", "--quiet", "--primary-only"]) == 0
    assert not any(c.exists() for c in companions(out))  # the store went with the sweep file it belonged to
    run_bytes = out.read_bytes()
    capsys.readouterr()
    assert main(sweep_argv(scene, out)) == 2
    line = one_error_line(capsys)
    assert str(out) in line and "--force" in line
    assert out.read_bytes() == run_bytes and not store_path(out).exists()
    assert main(sweep_argv(scene, out, "--force")) == 0
    assert read_sweep(out)["attrs"]["format"] == "balloon-cg-sweep/3"


def test_a_store_without_its_view_is_refused_by_run_and_resumed_by_its_sweep(scene, tmp_path, capsys):
    out = tmp_path / "s.h5"
    assert main(sweep_argv(scene, out)) == 0
    out.unlink()
    capsys.readouterr()
    assert main(["run", str(scene), "-o", str(out), "--quiet", "--primary-only"]) == 2
    assert "s.h5.members" in one_error_line(capsys) and not out.exists()
    assert main(sweep_argv(scene, out)) == 0 and sorted(read_sweep(out)["members"]) == [0, 1]


@pytest.mark.parametrize("content", [b"", b"some notes\n", b"\x89PNG\r\n\x1a\n"])
def test_every_kind_of_existing_file_needs_force(scene, tmp_path, capsys, content):
    out = tmp_path / "x.h5"
    out.write_bytes(content)
    for argv in (["run", str(scene), "-o", str(out), "--quiet", "--primary-only"], sweep_argv(scene, out)):
        assert main(argv) == 2
        assert "already exists" in one_error_line(capsys)
        assert out.read_bytes() == content and not store_path(out).exists()


def test_plot_replaces_an_image_only_with_force(scene, tmp_path, capsys):
    run = tmp_path / "r.h5"
    assert main(["run", str(scene), "-o", str(run), "--quiet", "--primary-only"]) == 0
    image = tmp_path / "p.png"
    image.write_bytes(b"mine")
    argv = ["plot", str(run), "--what", "pressure-pole", "-o", str(image)]
    assert main(argv) == 2
    assert "already exists" in one_error_line(capsys) and image.read_bytes() == b"mine"
    assert main([*argv, "--force"]) == 0 and image.read_bytes().startswith(b"\x89PNG")
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_outputs_that_are_not_regular_files_are_refused_even_with_force(tmp_path):
    fifo = tmp_path / "pipe.h5"
    os.mkfifo(fifo)
    with pytest.raises(IsADirectoryError, match="not a regular file"):
        check_output(fifo, force=True)
    with pytest.raises(IsADirectoryError, match="a directory"):
        check_output(tmp_path, force=True)
    with pytest.raises(FileNotFoundError, match="empty output path"):
        check_output("", force=True)
    with pytest.raises(FileNotFoundError, match="no such folder"):
        check_output(tmp_path / "nowhere" / "x.h5", force=True)


def test_empty_output_path_is_bad_input(scene, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for argv in (["run", str(scene), "-o", "", "--quiet"], sweep_argv(scene, "")):
        assert main(argv) == 2
        assert "empty path" in one_error_line(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes in read-only folders")
def test_a_read_only_folder_names_the_output_not_the_lock(scene, tmp_path, capsys):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        assert main(["run", str(scene), "-o", str(folder / "x.h5"), "--quiet"]) == 2
        line = one_error_line(capsys)
        assert "x.h5:" in line and ".lock" not in line
    finally:
        folder.chmod(stat.S_IRWXU)


def test_sweep_file_over_which_run_writes_with_force_loses_its_store(tmp_path):
    out = tmp_path / "s.h5"
    with h5py.File(out, "w") as f:
        f.attrs["format"] = "balloon-cg-sweep/3"
    for folder in companions(out):
        folder.mkdir()
    with pytest.raises(FileExistsError, match="a sweep file"):
        check_output(out, force=False)
    assert check_output(out, force=False, sweep=True) == out


def test_an_immutable_output_is_refused_before_computing_even_with_force(scene, tmp_path, capsys):
    import subprocess

    out = tmp_path / "old.h5"
    out.write_bytes(b"keep me")
    if subprocess.run(["chattr", "+i", str(out)], capture_output=True).returncode != 0:
        pytest.skip("chattr +i is not available here")
    try:
        assert main(["run", str(scene), "-o", str(out), "--force", "--quiet"]) == 2
        line = one_error_line(capsys)
        assert "old.h5: exists and is not writable" in line and ".tmp" not in line
        assert out.read_bytes() == b"keep me" and not [p for p in tmp_path.iterdir() if p.suffix == ".tmp"]
    finally:
        subprocess.run(["chattr", "-i", str(out)], capture_output=True)


def test_plot_points_are_bounded(tmp_path, capsys):
    argv = ["plot", str(tmp_path / "r.h5"), "--what", "shapes", "--points", ",".join(["0"] * 20_000)]
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2 and "at most 100" in capsys.readouterr().err
