"""Damaged files: every read path checks the layout first (io.layout) and the CLI prints one line naming the file
and what is wrong (exit 2); a bug is exit 3 with a pointer to report it, the traceback only with --debug."""
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from balloon_cg.app import summaries
from balloon_cg.app.cli import main
from shared_pictures import small_run_file



@pytest.fixture(scope="module")
def good(tmp_path_factory) -> Path:
    """A full-analysis run file: primary and pear branches, stability, special points, snap-throughs (the session's
    shared_pictures.small_run_file, read here or copied before it is damaged)."""
    return small_run_file(tmp_path_factory)


def _zero_points(f):
    g = f["branches/primary"]
    n = len(g["pressure"])
    for name, item in list(g.items()) + [(f"profiles/{k}", v) for k, v in g["profiles"].items()] + \
            [(f"stability/{k}", v) for k, v in g.get("stability", {}).items()]:
        if isinstance(item, h5py.Dataset) and item.shape and item.shape[0] == n and name != "theta":
            data = item[()][:0]
            del g[name]
            g.create_dataset(name, data=data)


def _replace(group, name, data):
    del group[name]
    group[name] = data


DAMAGE = {
    "missing residual": lambda f: f["branches/primary"].__delitem__("residual"),
    "missing pressure": lambda f: f["branches/primary"].__delitem__("pressure"),
    "zero points": _zero_points,
    "missing scene_name": lambda f: f.attrs.__delitem__("scene_name"),
    "missing created": lambda f: f.attrs.__delitem__("created"),
    "missing degree": lambda f: f["branches/primary"].attrs.__delitem__("degree"),
    "wall_time as text": lambda f: f["branches/primary"].attrs.__setitem__("wall_time", "slow"),
    "pressure as text": lambda f: _replace(f["branches/primary"], "pressure",
                                           np.array(["x"] * len(f["branches/primary/pressure"]), dtype=object)),
    "branches as a dataset": lambda f: _replace(f, "branches", np.arange(3)),
    "a branch as a dataset": lambda f: _replace(f["branches"], "primary", np.arange(3)),
    "missing primary": lambda f: f["branches"].__delitem__("primary"),  # was read as an empty, complete run
    "missing special_points": lambda f: f["branches/primary"].__delitem__("special_points"),
    "missing special kind": lambda f: f["branches/primary/special_points"].__delitem__("kind"),
    "missing special state": lambda f: f["branches/primary/special_points"].__delitem__("state"),
    "special unknowns short": lambda f: _replace(f["branches/primary/special_points/state"], "unknowns",
                                                 f["branches/primary/special_points/state/unknowns"][:1]),
    "special unknowns narrow": lambda f: _replace(f["branches/primary/special_points/state"], "unknowns",
                                                  f["branches/primary/special_points/state/unknowns"][:, :3]),
    "unknowns 1-d": lambda f: _replace(f["branches/primary"], "unknowns", f["branches/primary/unknowns"][:, 0]),
    "profiles shape": lambda f: _replace(f["branches/primary/profiles"], "rho", np.zeros((2, 2))),
    "stability length": lambda f: _replace(f["branches/primary/stability"], "stable_pressure", np.ones(2, bool)),
    "snap_throughs column": lambda f: f["snap_throughs"].__delitem__("to_index"),
    "no format": lambda f: f.attrs.__delitem__("format"),
    "complete without incomplete_gaps": lambda f: f.attrs.__delitem__("incomplete_gaps"),
    "phase_names without phase_seconds": lambda f: f.attrs.__delitem__("phase_seconds"),
    "phase_seconds shorter than phase_names": lambda f: f.attrs.__setitem__("phase_seconds",
                                                                            f.attrs["phase_seconds"][:-1]),
}


def one_line(capsys, path) -> str:
    captured = capsys.readouterr()
    err = captured.err
    assert err.count("\n") == 1 and err.startswith("balloon-cg: error: ") and "Traceback" not in err, err
    assert str(path) in err
    return err


@pytest.mark.parametrize("damage", DAMAGE)
@pytest.mark.parametrize("command", ["inspect", "plot"])
def test_damaged_run_file_is_one_line_and_exit_2(good, tmp_path, capsys, damage, command):
    path = tmp_path / "damaged.h5"
    shutil.copy(good, path)
    with h5py.File(path, "a") as f:
        DAMAGE[damage](f)
    argv = ["inspect", str(path)] if command == "inspect" else \
        ["plot", str(path), "--what", "pressure-pole", "-o", str(tmp_path / "p.png")]
    assert main(argv) == 2
    one_line(capsys, path)


def test_truncated_and_foreign_files(good, tmp_path, capsys):
    path = tmp_path / "cut.h5"
    path.write_bytes(good.read_bytes()[:4096])
    assert main(["inspect", str(path)]) == 2
    assert "not a readable HDF5 file" in one_line(capsys, path)
    text = tmp_path / "notes.h5"
    text.write_text("hello")
    assert main(["inspect", str(text)]) == 2
    one_line(capsys, text)


def test_deeply_nested_toml_is_one_line(tmp_path, capsys):
    deep = tmp_path / "deep.toml"
    deep.write_text('[material]\npreset = "SPOM1"\n[field]\nchi = ' + "[" * 5000 + "]" * 5000 + "\n")
    assert main(["run", str(deep), "-o", str(tmp_path / "x.h5")]) == 2
    assert "nested deeper than 8 levels" in one_line(capsys, "deep.toml")


def test_internal_error_is_exit_3_with_a_pointer_and_traceback_only_with_debug(good, monkeypatch, capsys):
    def bug(path):
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(summaries, "summarise_file", bug)
    assert main(["inspect", str(good)]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "internal error (ZeroDivisionError: division by zero)" in err
    assert "please report it" in err and "--debug" in err and "Traceback" not in err
    with pytest.raises(ZeroDivisionError):
        main(["--debug", "inspect", str(good)])
