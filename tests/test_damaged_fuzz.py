"""Damaged run, sweep and curve files (issue 30, items 7 and 13): every reader checks presence, dtype (float64
exactly), shape and declared size (bounded by the file's size) before it reads, maps h5py's OSError and
RuntimeError to the one-line bad-file error, and ``bc.load`` raises only its documented errors. A seeded,
time-bounded hypothesis fuzz damages good files (attributes deleted or retyped, datasets replaced by empty, wrong
type, wrong shape, NaN, long double or huge declared ones, objects deleted, bytes flipped, the file truncated) and
runs the readers: exit 0 or 2, never 3 (a bug), never an allocation beyond the file."""
import os
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, seed, settings, strategies as st

import balloon_cg as bc
from balloon_cg.app.cli import main
from balloon_cg.io.layout import FileError
from shared_pictures import SMALL, small_run_file

@pytest.fixture(scope="module")
def good_files(tmp_path_factory) -> dict:
    """The session's small run file (shared_pictures.small_run_file: copied before it is damaged) and a sweep."""
    folder = tmp_path_factory.mktemp("good")
    (folder / "s.toml").write_text(SMALL)
    sweep = folder / "sweep.h5"
    assert main(["sweep", str(folder / "s.toml"), "--vary", "stop_stretch=1.4,1.5", "--primary-only",
                 "--workers", "1", "--quiet", "-o", str(sweep)]) == 0
    shutil.rmtree(sweep.with_name(sweep.name + ".members"))  # the view alone: what the readers read
    return {"run": small_run_file(tmp_path_factory), "sweep": sweep}


def _objects(f) -> list:
    found = [f]
    f.visititems(lambda name, item: found.append(item))
    return found


def _huge(group, name):
    """A dataset declaring about 1e11 doubles (745 GiB) in a small file, of the same rank: its header only."""
    rest = tuple(group[name].shape[1:]) if group[name].shape else ()
    del group[name]
    group.create_dataset(name, shape=(10**11 // max(int(np.prod(rest)), 1), *rest), dtype="f8")


REPLACEMENTS = {
    "empty": lambda d: np.zeros((0,) * max(len(d.shape or ()), 1)),
    "strings": lambda d: np.array(["x"] * max(d.shape[0] if d.shape else 1, 1), dtype=object),
    "long double": lambda d: np.ones(d.shape, dtype=np.longdouble) if d.dtype.kind == "f" else np.ones(3, np.longdouble),
    "int8": lambda d: np.ones(d.shape, dtype=np.int8) if d.shape else np.int8(1),
    "complex": lambda d: np.ones(d.shape, dtype=complex) if d.shape else 1j,
    "2-d": lambda d: np.zeros((2, 2, 2)),
    "nan": lambda d: np.full(d.shape, np.nan) if d.dtype.kind == "f" else np.full(3, np.nan),
    "inf": lambda d: np.full(d.shape, np.inf) if d.dtype.kind == "f" else np.full(3, np.inf),
    "scalar": lambda d: np.float64(1.0),
}
ATTRIBUTES = {"long double": np.longdouble(1), "text": "x", "array": np.arange(3.0), "int": 7, "nan": np.nan,
              "empty text": ""}


def damage(path: Path, data) -> None:
    kind = data.draw(st.sampled_from(["delete attribute", "retype attribute", "replace dataset", "delete object",
                                      "huge dataset", "flip bytes", "truncate"]))
    if kind in ("flip bytes", "truncate"):
        raw = bytearray(path.read_bytes())
        if kind == "truncate":
            raw = raw[:data.draw(st.integers(0, len(raw) - 1))]
        else:
            for _ in range(data.draw(st.integers(1, 16))):
                at = data.draw(st.integers(0, len(raw) - 1))
                raw[at] ^= 1 << data.draw(st.integers(0, 7))
        path.write_bytes(bytes(raw))
        return
    with h5py.File(path, "a") as f:
        objects = _objects(f)
        if kind in ("delete attribute", "retype attribute"):
            holders = [o for o in objects if len(o.attrs)]
            item = data.draw(st.sampled_from(holders))
            name = data.draw(st.sampled_from(sorted(item.attrs)))
            if kind == "delete attribute":
                del item.attrs[name]
            else:
                item.attrs[name] = ATTRIBUTES[data.draw(st.sampled_from(sorted(ATTRIBUTES)))]
            return
        datasets = [o for o in objects if isinstance(o, h5py.Dataset) and not h5py.h5ds.is_scale(o.id)]
        if kind == "delete object":
            item = data.draw(st.sampled_from([o for o in objects[1:]]))
            del f[item.name]
            return
        item = data.draw(st.sampled_from(datasets))
        parent, name = item.parent, item.name.rsplit("/", 1)[1]
        if kind == "huge dataset":
            _huge(parent, name)
            return
        replacement = REPLACEMENTS[data.draw(st.sampled_from(sorted(REPLACEMENTS)))](item)
        del parent[name]
        parent.create_dataset(name, data=replacement)


def read_everything(path: Path, tmp_path: Path, plot: bool) -> None:
    for argv in (["inspect", str(path)], ["inspect", "--json", str(path)],
                 *([["plot", str(path), "--what", "pressure-pole", "-o", str(tmp_path / "p.png"), "--force"]]
                   if plot else [])):
        code = main(argv)
        assert code in (0, 2), (argv, code)
    try:
        bc.load(path)
    except (FileError, FileNotFoundError, IsADirectoryError):
        pass


def _fuzz(good_files, tmp_path_factory, data, which: str, plot: bool) -> None:
    tmp_path = tmp_path_factory.mktemp("damaged")
    path = tmp_path / f"{which}.h5"
    shutil.copy(good_files[which], path)
    damage(path, data)
    read_everything(path, tmp_path, plot)


FAST = settings(max_examples=40, deadline=None, phases=(Phase.explicit, Phase.reuse, Phase.generate),
                suppress_health_check=list(HealthCheck), database=None)


@seed(7)
@FAST
@given(data=st.data(), which=st.sampled_from(["run", "sweep"]))
def test_damaged_files_are_read_or_refused_in_one_line(good_files, tmp_path_factory, data, which):
    _fuzz(good_files, tmp_path_factory, data, which, plot=which == "run")


@pytest.mark.slow
@seed(3007)
@settings(max_examples=1000, deadline=None, phases=(Phase.explicit, Phase.reuse, Phase.generate),
          suppress_health_check=list(HealthCheck), database=None)
@given(data=st.data(), which=st.sampled_from(["run", "sweep"]))
def test_damaged_files_1000(good_files, tmp_path_factory, data, which):
    _fuzz(good_files, tmp_path_factory, data, which, plot=which == "run")


@pytest.mark.parametrize("which", ["run", "sweep"])
@pytest.mark.parametrize("column", ["pressure", "lam2_top", "volume", "unknowns"])
def test_a_huge_declared_dataset_is_refused_without_allocating(good_files, tmp_path, capsys, which, column):
    path = tmp_path / f"{which}.h5"
    shutil.copy(good_files[which], path)
    with h5py.File(path, "a") as f:
        group = f["branches/primary"] if which == "run" else f["members/0/branches/primary"]
        _huge(group, column)
    assert os.path.getsize(path) < 10 * 1024**2
    assert main(["inspect", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "declares" in err
    if which == "run":
        with pytest.raises(FileError, match="declares"):
            bc.load(path)


@pytest.mark.parametrize("change", ["long double pressure", "missing parent_branch_point", "no primary (its snap-throughs name it)",
                                    "snap from nowhere", "volume as text", "missing amount", "special kind 2-d"])
def test_the_issues_damaged_files(good_files, tmp_path, capsys, change):
    path = tmp_path / "run.h5"
    shutil.copy(good_files["run"], path)
    with h5py.File(path, "a") as f:
        primary = f["branches/primary"]
        if change == "long double pressure":
            data = primary["pressure"][()].astype(np.longdouble)
            del primary["pressure"]
            primary.create_dataset("pressure", data=data)
        elif change == "missing parent_branch_point":
            pear = next((g for g in f["branches"].values() if "parent_branch" in g.attrs), None)
            if pear is None:
                pytest.skip("no child branch in this run")
            del pear.attrs["parent_branch_point"]
        elif change.startswith("no primary"):
            del f["branches/primary"]
        elif change == "snap from nowhere":
            snaps = f.require_group("snap_throughs")
            for name in list(snaps):
                del snaps[name]
            snaps.create_dataset("from_branch", data=np.array(["nowhere"], dtype=object), dtype=h5py.string_dtype())
            snaps.create_dataset("to_branch", data=np.array([""], dtype=object), dtype=h5py.string_dtype())
            snaps.create_dataset("from_index", data=np.array([0]))
            snaps.create_dataset("to_index", data=np.array([-1]))
            snaps.create_dataset("pressure", data=np.array([1.0]))
        elif change == "missing amount":
            del primary["amount"]
        elif change == "volume as text":
            n = primary["volume"].shape[0]
            del primary["volume"]
            primary.create_dataset("volume", data=np.array(["v"] * n, dtype=object), dtype=h5py.string_dtype())
        else:
            n = primary["special_points/kind"].shape[0]
            del primary["special_points/kind"]
            primary["special_points"].create_dataset("kind", data=np.array([["LP"] * 2] * max(n, 1), dtype=object),
                                                     dtype=h5py.string_dtype())
    for argv in (["inspect", str(path)], ["inspect", "--json", str(path)]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(path) in err and "internal error" not in err
    with pytest.raises(FileError):
        bc.load(path)


@pytest.fixture(scope="module")
def curve_file(tmp_path_factory) -> Path:
    """A two-parameter curve file (critical alpha1 of SPOM1, as tests/test_cli.py)."""
    folder = tmp_path_factory.mktemp("curve")
    (folder / "s.toml").write_text('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 4.0\n')
    assert main(["critical", str(folder / "s.toml"), "--parameter", "alpha1", "-o", str(folder / "curve.h5"),
                 "--quiet"]) == 0
    return folder / "curve.h5"


@pytest.mark.parametrize("change", ["nan q", "inf pressure", "missing degree", "missing end_description",
                                    "missing wall_time", "long double root attribute", "inf merge pressure"])
def test_the_issues_damaged_curve_files(curve_file, tmp_path, capsys, change):
    path = tmp_path / "curve.h5"
    shutil.copy(curve_file, path)
    with h5py.File(path, "a") as f:
        curve = f["two_parameter/pear"]
        if change == "long double root attribute":  # an undocumented attribute: shown, as a float
            f.attrs["remark"] = np.longdouble(1.5)
            curve.attrs["extra"] = np.clongdouble(1 + 2j)
        elif change == "inf merge pressure":
            special = curve["special_points"]
            special["pressure"][...] = np.full(special["pressure"].shape, np.inf)
        elif change.startswith("missing"):
            del curve.attrs[change.removeprefix("missing ")]
        else:
            name = "alpha1" if change == "nan q" else "pressure"  # q stored under its parameter's name
            data = curve[name][()]
            data[len(data) // 2] = np.nan if change == "nan q" else np.inf
            curve[name][...] = data
    if change == "long double root attribute":
        for argv in (["inspect", str(path)], ["inspect", "--json", str(path)]):
            assert main(argv) == 0  # a RecursionError in inspect --json before
        assert '"remark": 1.5' in capsys.readouterr().out
        return
    for argv in (["inspect", str(path)], ["plot", str(path), "--what", "phase", "-o", str(tmp_path / "p.png")]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(path) in err and "internal error" not in err


@pytest.mark.slow
@seed(3008)
@settings(max_examples=1000, deadline=None, phases=(Phase.explicit, Phase.reuse, Phase.generate),
          suppress_health_check=list(HealthCheck), database=None)
@given(data=st.data())
def test_damaged_curve_files_1000(curve_file, tmp_path_factory, data):
    tmp_path = tmp_path_factory.mktemp("damaged")
    path = tmp_path / "curve.h5"
    shutil.copy(curve_file, path)
    damage(path, data)
    read_everything(path, tmp_path, plot=False)
    assert main(["plot", str(path), "--what", "phase", "-o", str(tmp_path / "p.png"), "--force"]) in (0, 2)
