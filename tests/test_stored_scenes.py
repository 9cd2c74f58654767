"""A file says what it was computed with: the scene text stored in a run file is read as it was written, also where
a later version refuses that setting for a new run (scene.tables.startable: continuation.stop_volume at or below the
reference volume, [surface] branches on a capsule of length 0 without a field). `inspect`, `plot` and ``bc.load``
read such a file; `continue` from it, a new run, is refused in one line (exit 2), as a new run with the setting
is."""
import shutil

import h5py
import pytest

import balloon_cg as bc
from balloon_cg.app.cli import main
from balloon_cg.scene import SceneError, parse_scene

from shared_pictures import tube_run_file

SPHERE = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 1.6\n'
CAPSULE = ('[material]\npreset = "SPOM1"\n[geometry]\nshape = "capsule"\nlength = 0.0\n[solver]\ndegree = 24\n'
           '[stability]\nm_max = 0\n[continuation]\nstop_stretch = 1.4\n')


def with_stored_scene(path, edit) -> str:
    """Replace the file's stored scene text by ``edit(text)`` (as a file written before a check would hold it)."""
    with h5py.File(path, "r+") as f:
        text = edit(f.attrs["scene_toml"])
        f.attrs["scene_toml"] = text
    return text


def stop_volume(value: float):
    def edit(text: str) -> str:
        assert "stop_volume" not in text
        return text.replace("[continuation]\n", f"[continuation]\nstop_volume = {value}\n", 1)
    return edit


def surface_first(text: str) -> str:
    assert "[surface]" not in text
    return text + '\n[surface]\nbranches = "first"\nmax_points = 30\n'


@pytest.fixture(scope="module")
def sphere_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("sphere") / "s.h5"
    bc.trace(parse_scene(SPHERE, "s")).save(path)
    return path


@pytest.fixture(scope="module")
def capsule_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("capsule") / "c.h5"
    bc.trace(parse_scene(CAPSULE, "c")).save(path)
    return path


def refused_as_new(text: str) -> str:
    """The one line a new run with the scene ``text`` is refused with."""
    with pytest.raises(SceneError) as refused:
        parse_scene(text, "new")
    return str(refused.value)


def read_what_it_says(path, text: str, capsys, tmp_path, continued: list) -> None:
    """`inspect`, `plot` and ``bc.load`` read the file (its scene the stored one); `continue ... continued` is
    refused in one line naming what a new run may not start."""
    assert main(["inspect", str(path)]) == 0, capsys.readouterr().err
    assert main(["plot", str(path), "--what", "pressure-volume" if "tube" in text else "pressure-pole",
                 "-o", str(tmp_path / "p.png")]) == 0, capsys.readouterr().err
    repr(bc.load(path))
    capsys.readouterr()
    assert main(["continue", str(path), *continued, "-o", str(tmp_path / "c.h5"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and refused_as_new(text).split(": ", 1)[1] in err[0], err
    assert not (tmp_path / "c.h5").exists()


@pytest.mark.parametrize("edit", [stop_volume(2.0), stop_volume(4 / 3 * 3.141592653589793)], ids=["below", "at"])
def test_a_sphere_file_whose_stop_volume_is_now_refused_is_read(sphere_file, tmp_path, capsys, edit):
    path = shutil.copy(sphere_file, tmp_path / "old.h5")
    text = with_stored_scene(path, edit)
    read_what_it_says(path, text, capsys, tmp_path, ["1"])
    assert bc.load(path).scene.continuation.stop_volume == float(text.split("stop_volume = ")[1].split()[0])


def test_a_capsule_file_with_surface_branches_is_read(capsule_file, tmp_path, capsys):
    path = shutil.copy(capsule_file, tmp_path / "old.h5")
    text = with_stored_scene(path, surface_first)
    read_what_it_says(path, text, capsys, tmp_path, ["1"])
    assert bc.load(path).scene.surface.branches == "first"


def test_a_tube_file_whose_stop_volume_is_now_refused_is_read(tmp_path_factory, tmp_path, capsys):
    """The tube (length 10: V0 = 10π): stop_volume = 10 (V/V0 meant, the refused slip) in the stored text."""
    path = shutil.copy(tube_run_file(tmp_path_factory), tmp_path / "old.h5")
    text = with_stored_scene(path, stop_volume(10.0))
    read_what_it_says(path, text, capsys, tmp_path, ["1"])
    assert bc.load(path).geometry["length"] == 10.0


def test_the_api_starts_no_run_from_a_stored_scene_a_new_run_may_not_start():
    """A Scene read from a file's stored text (``parse_stored``: not checked as new input) handed back to the API is
    checked as a new run's before it starts (``bc.trace`` ran such a spom1 with stop_volume 0.1 to completion)."""
    from balloon_cg.scene.tables import parse_stored

    text = stop_volume(0.1)(SPHERE)
    with pytest.raises(SceneError, match="stop_volume"):
        parse_scene(text)
    with pytest.raises(SceneError, match="stop_volume"):
        bc.trace(parse_stored(text))
