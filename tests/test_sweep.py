"""Sweeps: member expansion, local pool = serial = dask cluster, one writer, resume after an interruption."""
import json
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest

from balloon_cg.app import sweep as sweep_module
from balloon_cg.app.cli import main
from balloon_cg.scene import SceneError, load_scene
from balloon_cg.app.sweep import DASK_WORKER_CONFIG, SlowWorkersWarning, expand, run_sweep, scene_hash
from balloon_cg.io.sweep_file import Store, SweepError, read_sweep, store_path
from netcdf_groups import uncoordinated

SCENE_FILE = Path(__file__).resolve().parents[1] / "scenes" / "spom1_single_coil.toml"
SPECS = ["M=0:0.004:3"]
MODE = "primary-only"


@pytest.fixture(scope="module")
def scene():
    return load_scene(SCENE_FILE).with_overrides({"continuation.stop_stretch": 2.0})


@pytest.fixture(scope="module")
def serial(scene, tmp_path_factory):
    path = tmp_path_factory.mktemp("serial") / "serial.h5"
    result = run_sweep(scene, SPECS, path, mode=MODE, workers=1)
    assert result.computed == [0, 1, 2] and not result.failed
    return read_sweep(path)


def assert_same_members(a: dict, b: dict):
    assert sorted(a["members"]) == sorted(b["members"])
    for index, ma in a["members"].items():
        mb = b["members"][index]
        assert ma["overrides"] == mb["overrides"] and ma["scene_hash"] == mb["scene_hash"]
        assert list(ma["branches"]) == list(mb["branches"])
        for name, ba in ma["branches"].items():
            bb = mb["branches"][name]
            for key in ("unknowns", "pressure", "lam2_top", "residual", "error_estimate"):
                np.testing.assert_allclose(ba[key], bb[key], rtol=1e-12, atol=1e-14, err_msg=f"{index}/{name}/{key}")
            np.testing.assert_allclose(ba["profiles"]["rho"], bb["profiles"]["rho"], rtol=1e-12, atol=1e-14)
            assert [s["kind"] for s in ba["special_points"]] == [s["kind"] for s in bb["special_points"]]


# --- expansion ---------------------------------------------------------------------------------------------

def test_expand_bare_name_range_and_product(scene):
    members = expand(scene, ["M=0:0.004:3", "field.coils[0].radius=4,5"])
    assert len(members) == 6
    assert [m.overrides for m in members[:2]] == [{"field.M": 0.0, "field.coils[0].radius": 4},
                                                  {"field.M": 0.0, "field.coils[0].radius": 5}]
    assert members[-1].scene.field.M == pytest.approx(0.004) and members[-1].scene.field.coils[0].radius == 5
    assert [m.index for m in members] == list(range(6))
    assert members[2].scene_hash == scene_hash(scene.with_overrides({"field.M": 0.002}))


def test_expand_list_entry_key(scene):
    (m,) = expand(scene, ["material.alpha[0]=1.4"])
    assert m.scene.material.alpha[0] == 1.4
    assert m.scene.material.alpha[1:] == scene.material.alpha[1:]


def test_the_range_spellings_agree(scene):
    """START:STOP:num=COUNT and linspace(START, STOP, COUNT) (unambiguous to a MATLAB user, for whom a:b:c is
    start:step:stop) give the short START:STOP:COUNT's values; a step where the count belongs is refused."""
    from balloon_cg.app.sweep import parse_vary

    short = parse_vary("M=0:0.003:4", scene)
    assert short == ("field.M", [0.0, 0.001, 0.002, 0.003])
    assert parse_vary("M=0:0.003:num=4", scene) == short == parse_vary("M=linspace(0, 0.003, 4)", scene)
    with pytest.raises(SweepError, match="COUNT an integer .the number of values, not a step"):
        parse_vary("M=0:0.001:0.003", scene)
    with pytest.raises(SweepError, match="three fields"):
        parse_vary("M=linspace(0, 0.003)", scene)


@pytest.mark.parametrize("specs, message", [
    (["M"], "expected KEY=START:STOP:num=COUNT"),
    (["M=0:1"], "three fields"),
    (["degree=20,30"], "exactly one scene table"),
    (["M=0,1", "field.M=2"], "varied twice"),
])
def test_bad_specs(scene, specs, message):
    with pytest.raises(SweepError, match=message):
        expand(scene, specs)


def test_invalid_members_reported_once_before_any_work(scene, tmp_path):
    with pytest.raises(SceneError) as info:
        run_sweep(scene, ["M=-0.002:0.002:5"], tmp_path / "s.h5", mode=MODE, workers=1)
    message = str(info.value)
    assert message.startswith("2 of 5 sweep members are invalid")
    assert message.count("must be in [0, 1000]") == 2 and "(member 0)" in message and "(member 1)" in message
    assert not (tmp_path / "s.h5").exists()


# --- parallel backends -------------------------------------------------------------------------------------

def test_local_pool_equals_serial(scene, serial, tmp_path):
    path = tmp_path / "pool.h5"
    result = run_sweep(scene, SPECS, path, mode=MODE, workers=2)
    assert sorted(result.computed) == [0, 1, 2]
    pool = read_sweep(path)
    assert_same_members(serial, pool)
    assert len({m["attrs"]["worker_pid"] for m in pool["members"].values()}) >= 1
    with h5py.File(path) as f:
        assert sorted(f["members"]) == ["0", "1", "2"]
        assert json.loads(f["members/1"].attrs["overrides"]) == {"field.M": 0.002}
        assert f.attrs["mode"] == MODE and f.attrs["members"] == 3


try:  # loaded before any dask.config.set: a set made before distributed's defaults exist removes them on exit
    import distributed  # noqa: F401
except ImportError:
    pass


def local_cluster(n_workers: int):
    distributed = pytest.importorskip("distributed")
    return distributed.LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                                    dashboard_address=None)


def test_dask_cluster_equals_local_pool(scene, serial, tmp_path, monkeypatch):
    """Also: DASK_WORKER_CONFIG reaches the workers (their malloc variables unset: no SlowWorkersWarning)."""
    import dask
    for name in ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_"):  # inherited by the workers, else
        monkeypatch.delenv(name, raising=False)
    with dask.config.set(DASK_WORKER_CONFIG), local_cluster(2) as cluster, warnings.catch_warnings():
        warnings.simplefilter("error", SlowWorkersWarning)
        result = run_sweep(scene, SPECS, tmp_path / "dask.h5", mode=MODE, scheduler=cluster.scheduler_address)
    assert sorted(result.computed) == [0, 1, 2] and not result.failed
    assert_same_members(serial, read_sweep(tmp_path / "dask.h5"))


def test_dask_workers_with_a_frozen_mmap_threshold_are_reported(scene, tmp_path, monkeypatch):
    monkeypatch.setenv("MALLOC_TRIM_THRESHOLD_", "65536")  # what dask's nanny sets by default
    monkeypatch.delenv("MALLOC_MMAP_THRESHOLD_", raising=False)
    with local_cluster(1) as cluster, pytest.warns(SlowWorkersWarning, match="1 dask worker"):
        result = run_sweep(scene, ["M=0"], tmp_path / "dask.h5", mode=MODE, scheduler=cluster.scheduler_address)
    assert result.computed == [0]


# --- interruption and resume -------------------------------------------------------------------------------

def test_interrupted_sweep_resumes_without_recomputing(scene, serial, tmp_path, monkeypatch):
    path, written = tmp_path / "resume.h5", []
    write = Store.write_member

    def write_then_interrupt(store, member, result):
        write(store, member, result)
        written.append(member.index)
        raise KeyboardInterrupt  # the user presses Ctrl-C after the first member is written

    monkeypatch.setattr(Store, "write_member", write_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        run_sweep(scene, SPECS, path, mode=MODE, workers=2)
    monkeypatch.setattr(Store, "write_member", write)
    assert len(written) == 1
    with h5py.File(path) as f:  # the view was rebuilt on the way out
        assert list(f["members"]) == [str(written[0])]
        first = dict(f["members"][str(written[0])].attrs)
    debris = store_path(path) / ".000002.h5.0123abcd.tmp"
    debris.write_bytes(b"half a member")  # a member file whose write was cut before its rename

    result = run_sweep(scene, SPECS, path, mode=MODE, workers=2)
    assert result.skipped == written
    assert sorted(result.computed) == sorted({0, 1, 2} - set(written))
    assert not debris.exists()
    with h5py.File(path) as f:
        assert sorted(f["members"]) == ["0", "1", "2"]
        again = f["members"][str(written[0])].attrs
        assert again["created"] == first["created"] and again["worker_pid"] == first["worker_pid"]
    assert_same_members(serial, read_sweep(path))

    done = run_sweep(scene, SPECS, path, mode=MODE, workers=2)
    assert done.computed == [] and done.skipped == [0, 1, 2]


@pytest.mark.parametrize("workers", [1, 2])
def test_a_swallowed_interrupt_still_stops_the_sweep(scene, tmp_path, monkeypatch, workers):
    """A signal whose KeyboardInterrupt was swallowed (it landed in a weakref callback once in CI, and the sweep
    ran to the end with exit 0) has still set the interrupt flag: the sweep stops at the flag."""
    from balloon_cg.numerics import interrupt

    write = Store.write_member

    def write_then_flag(store, member, result):
        write(store, member, result)
        interrupt.request()  # what the signal handler does before raising

    monkeypatch.setattr(Store, "write_member", write_then_flag)
    try:
        with pytest.raises(KeyboardInterrupt):
            run_sweep(scene, SPECS, tmp_path / "s.h5", mode=MODE, workers=workers)
    finally:
        interrupt._flag.clear()
    assert 1 <= len(list(store_path(tmp_path / "s.h5").glob("0*.h5"))) < 3  # member files; not all 3 computed


def test_a_member_cut_short_by_a_signal_is_computed_again_on_resume(scene, serial, tmp_path, monkeypatch):
    """A serial sweep computes its members in this process: a signal stops the member's trace where it is (its
    file says interrupted) and then the sweep. The same command resumes and computes that member again: what
    an interrupted member's file holds is not the member."""
    from balloon_cg.numerics import interrupt

    trace = sweep_module.trace_primary

    def signalled_trace(member_scene):
        interrupt.request()  # what the signal handler does, while the member is computed
        return trace(member_scene)

    path = tmp_path / "cut.h5"
    monkeypatch.setattr(sweep_module, "trace_primary", signalled_trace)
    try:
        with pytest.raises(KeyboardInterrupt):
            run_sweep(scene, SPECS, path, mode=MODE, workers=1)
    finally:
        interrupt._flag.clear()
    monkeypatch.setattr(sweep_module, "trace_primary", trace)
    with h5py.File(store_path(path) / "000000.h5") as f:
        assert not f.attrs["complete"] and "interrupted" in list(f.attrs["incomplete_gaps"])

    result = run_sweep(scene, SPECS, path, mode=MODE, workers=1)
    assert result.skipped == [] and result.computed == [0, 1, 2]
    assert_same_members(serial, read_sweep(path))


# A pool whose worker is killed in the middle of sending its result: the parent's manager thread has read the
# message's length and waits for the rest; the process must still exit once the pool is stopped.
CUT_SEND = r"""
import os, struct, sys, time
from concurrent.futures import ProcessPoolExecutor
from balloon_cg.app.sweep import _terminate

pool = ProcessPoolExecutor(1)
pool.submit(time.sleep, 600)  # a worker computing
writer = pool._result_queue._writer.fileno()  # as the worker writes a result: its length, then only its start
os.write(writer, struct.pack("!i", 2**20) + b"partial")
_terminate(pool)
print("stopped", flush=True)
"""


def test_a_worker_killed_while_sending_its_result_does_not_hang_the_exit():
    """Found by the interrupt study (tests/test_interrupt_moments.py, 1 of 10 two-coil sweeps hung after its line:
    Python's exit joined the manager thread, which read the rest of a result for ever). The timeout is a hang guard:
    the process ends at once when it ends."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", CUT_SEND], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stdout == "stopped\n", done.stderr


def test_resume_refuses_changed_scene(scene, tmp_path):
    path = tmp_path / "s.h5"
    run_sweep(scene, ["M=0,0.002"], path, mode=MODE, workers=1)
    moved = scene.with_overrides({"field.coils[0].radius": 4.5})
    with pytest.raises(SweepError, match=r"base scene differs \(field.coils"):
        run_sweep(moved, ["M=0,0.002"], path, mode=MODE, workers=1)
    with pytest.raises(SweepError, match="--vary differs"):
        run_sweep(scene, ["M=0,0.003"], path, mode=MODE, workers=1)
    with pytest.raises(SweepError, match="mode differs"):
        run_sweep(scene, ["M=0,0.002"], path, mode="no-pear", workers=1)
    with h5py.File(store_path(path) / "000001.h5", "a") as f:  # a member stored for another scene
        f.attrs["scene_hash"] = scene_hash(moved)
    with pytest.raises(SweepError, match=r"member 1 \(field.M=0.002\) was computed for another scene"):
        run_sweep(scene, ["M=0,0.002"], path, mode=MODE, workers=1)
    result = run_sweep(moved, ["M=0,0.002"], path, mode=MODE, workers=1, force=True)
    assert result.computed == [0, 1]
    assert read_sweep(path)["members"][0]["scene_hash"] == scene_hash(moved.with_overrides({"field.M": 0.0}))


def test_failed_member_is_reported_and_retried(scene, tmp_path, monkeypatch):
    path = tmp_path / "s.h5"
    compute = sweep_module.compute_member

    def flaky(index, *args):
        if index == 1:
            raise RuntimeError("boom")
        return compute(index, *args)

    monkeypatch.setattr(sweep_module, "compute_member", flaky)
    result = run_sweep(scene, ["M=0,0.002"], path, mode=MODE, workers=1)
    assert result.computed == [0] and result.failed == {1: "RuntimeError: boom"}
    monkeypatch.setattr(sweep_module, "compute_member", compute)
    again = run_sweep(scene, ["M=0,0.002"], path, mode=MODE, workers=1)
    assert again.skipped == [0] and again.computed == [1]


# --- command line ------------------------------------------------------------------------------------------

def test_cli_sweep_and_resume(tmp_path, capsys):
    out = tmp_path / "cli.h5"
    argv = ["sweep", str(SCENE_FILE), "--vary", "M=0,0.004", "--vary", "stop_stretch=2", "-o", str(out),
            "--primary-only", "--workers", "2"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "2 computed, 0 already in the file" in text and "field.M=0.004, continuation.stop_stretch=2" in text
    assert main(argv) == 0
    assert "0 computed, 2 already in the file" in capsys.readouterr().out
    assert main(argv[:3] + ["M=0,0.003"] + argv[4:]) == 2
    assert f"{out}: holds a different sweep: --vary differs" in capsys.readouterr().err  # not its store's manifest
    assert main(["sweep", str(SCENE_FILE), "--vary", "M=-1", "-o", str(tmp_path / "x.h5")]) == 2
    assert "must be in [0, 1000]" in capsys.readouterr().err


def test_cli_no_pear_reports_branch_points(tmp_path, capsys):
    out = tmp_path / "np.h5"
    argv = ["sweep", str(SCENE_FILE), "--vary", "M=0", "--vary", "stop_stretch=3", "-o", str(out), "--no-pear",
            "--workers", "1"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    member = read_sweep(out)["members"][0]
    pears = [p for p, b in zip(member["attrs"]["branch_point_pressures"], member["attrs"]["branch_point_blocks"])
             if b == "odd_held"]
    assert len(pears) == 1 and f"{pears[0]:.6g}" in text
    assert list(member["branches"]) == ["primary"] and "stability" in member["branches"]["primary"]


def test_phase_diagram_from_a_sweep_file(tmp_path):
    """`plot SWEEP.h5 --what phase`: the pear pitchfork pressures of every member against the varied key."""
    from balloon_cg.app.cli import main as cli_main
    from balloon_cg.post.plotting import plot

    scene = tmp_path / "spom1.toml"
    scene.write_text('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 4.0\n')
    out = tmp_path / "sweep.h5"
    assert cli_main(["sweep", str(scene), "--vary", "material.alpha[0]=1.3,1.5", "-o", str(out), "--quiet",
                     "--no-pear", "--workers", "1"]) == 0
    fig = plot([out], "phase")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "material.alpha[0]" and "bifurcation pressure" in ax.get_ylabel()
    lines = [line for line in ax.get_lines() if "pear pitchfork" in line.get_label()]
    assert len(lines) == 2 and all(len(line.get_xdata()) == 2 for line in lines)
    [fold] = [line for line in ax.get_lines() if "fold (LP)" in line.get_label()]
    assert len(fold.get_xdata()) == 2 and np.all(np.asarray(fold.get_ydata()) > 2.5)  # P_max ≈ 2.57 (α1 = 1.3)


def test_phase_diagram_of_a_primary_only_sweep_is_refused(tmp_path):
    """A primary-only sweep has no stability, so no branch points: one clear line, not a diagram that shows no
    pitchforks (as if there were none)."""
    from balloon_cg.post.plotting import PlotError, plot

    scene = load_scene("spom1").with_overrides({"continuation.stop_stretch": 1.5})
    out = tmp_path / "primary.h5"
    run_sweep(scene, ["material.alpha[0]=1.3,1.5"], out, mode="primary-only", workers=1)
    with pytest.raises(PlotError, match="primary-only sweep has no branch points"):
        plot([out], "phase")


def test_every_group_of_a_sweep_file_opens_with_xarray(serial):
    """The members copied into the sweep file keep valid dimension scales: h5py follows them to the member's own
    scales, and xarray (h5netcdf) opens every group with named dimensions."""
    xr = pytest.importorskip("xarray")
    path = serial["path"]
    groups = []
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, item: groups.append(name) if isinstance(item, h5py.Group) else None)
        pressure = f["members/1/branches/primary/pressure"]
        assert pressure.dims[0][0].name == "/members/1/branches/primary/point"
    assert "members/2/branches/primary/special_points" in groups
    for group in groups:
        with xr.open_dataset(path, engine="h5netcdf", group=group) as ds:
            if group.endswith("branches/primary"):
                assert ds.pressure.dims == ("point",) and ds.unknowns.dims == ("point", "unknown")
    assert uncoordinated(path) == []  # a member's profiles, stability, state opened alone: their coordinates


@pytest.fixture(scope="module")
def analysed_sweep(scene, tmp_path_factory):
    """The whole analysis (no surface branches) of M = 0, 0.002, 0.004 to λ2(0) = 2.5: every member has its
    fold and its pear pitchfork."""
    path = tmp_path_factory.mktemp("analysed") / "sweep.h5"
    member_scene = scene.with_overrides({"continuation.stop_stretch": 2.5, "surface.branches": "none"})
    run_sweep(member_scene, SPECS, path, workers=1)
    return path


def test_a_loaded_sweep_is_a_table_of_members(analysed_sweep):
    """bc.load(sweep): the members, and one row per member with the varied value, the fold and the critical
    pressures (each equal to the member's stored branch point)."""
    import balloon_cg as bc

    sweep = bc.load(analysed_sweep)
    assert isinstance(sweep, bc.SweepResult) and sorted(sweep.members) == [0, 1, 2]
    table = sweep.to_dataframe()
    assert list(table.index) == [0, 1, 2] and list(table["field.M"]) == [0.0, 0.002, 0.004]
    for index, member in sweep.members.items():
        special = member.branches["primary"].special_points
        pear = max(s["pressure"] for s in special if s["block"] == "odd_held")
        assert table.loc[index, "P_cr1"] == pear and table.loc[index, "P_BP1"] == special[
            [s["kind"] for s in special].index("BP")]["pressure"]
        assert table.loc[index, "P_LP"] == next(s["pressure"] for s in special if s["kind"] == "LP")
        assert member.to_xarray(group="special_points").sizes["special"] == len(special)
    assert table["complete"].all() and table["P_cr1"].is_monotonic_increasing  # 2.26473, 2.26480, 2.26487
    ds = sweep.to_xarray()
    assert ds.sizes["member"] == 3 and float(ds["P_cr1"][2]) == table.loc[2, "P_cr1"]
    xr = pytest.importorskip("xarray")
    with xr.open_dataset(analysed_sweep, engine="h5netcdf") as root:  # the file's root: the same table
        assert root.sizes == {"member": 3} and list(root["member"].values) == [0, 1, 2]
        assert "field.M" in root.coords and list(root["field.M"].values) == [0.0, 0.002, 0.004]
        assert root["P_cr1"].dims == ("member",) and root["P_cr1"].attrs["units"] == "1"
        for column in ("P_LP", "lam2_LP", "P_cr1", "P_cr2", "P_BP1", "P_BP2"):
            np.testing.assert_array_equal(root[column].values, table[column].values)
        assert list(root["block_BP1"].values) == list(table["block_BP1"]) and root["complete"].values.all()
        assert float(root["P_cr1"].sel(member=2)) == table.loc[2, "P_cr1"]
    assert "\n" not in repr(sweep) and len(repr(sweep)) <= 160 and sweep._repr_html_().count("<tr") == 1 + 3
