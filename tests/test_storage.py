"""Run files: round trip, profiles of the M = 0 sphere, atomic and non-clobbering writes."""
import datetime
from dataclasses import replace
from pathlib import Path

import h5py
import numpy as np
import pytest

import balloon_cg
from balloon_cg.io import run_file as storage
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.model.kernels import generated_digest, module_signature
from balloon_cg.galerkin.profiles import equator_values, fields, profiles, theta_grid
from balloon_cg.scene import load_scene
from balloon_cg.io.run_file import RunFileError, read_run, write_run

SPOM1 = Path(__file__).resolve().parents[1] / "scenes" / "spom1.toml"


@pytest.fixture(scope="module")
def scene():
    return load_scene(SPOM1).with_overrides({"continuation.stop_stretch": 2.0})


@pytest.fixture(scope="module")
def branch(scene):
    return trace_primary(scene)


@pytest.fixture(scope="module")
def free_branch(scene):
    """The same sphere without the equator-symmetric subspace (every Legendre degree kept but b_0)."""
    return trace_primary(scene, symmetric=False)


@pytest.fixture
def run_file(tmp_path, scene, branch):
    return write_run(tmp_path / "run.h5", scene, [branch], extra_attrs={"note": "test"})


def test_generated_digest_reads_the_signatures_the_modules_hold():
    """The provenance digest reads each module's SIGNATURE line from its text (no import); it must be the
    constant the imported module holds, for every class, its whole-sphere module, the coil field and the mass
    matrices."""
    import hashlib
    import importlib

    from balloon_cg import generated

    names = sorted(generated.CLASSES) + sorted(generated.SURFACE_CLASSES.values()) + ["coil_field", "inertia"]
    signatures = [importlib.import_module(f"balloon_cg.generated.{n}").SIGNATURE for n in names]
    assert [module_signature(n) for n in names] == signatures
    assert generated_digest() == hashlib.sha256("".join(signatures).encode()).hexdigest()


def test_round_trip(run_file, scene, branch):
    run = read_run(run_file)
    attrs = run["attrs"]
    assert run["scene_name"] == scene.name == attrs["scene_name"]
    assert attrs["format"] == "balloon-cg/6"
    assert attrs["scene_toml"] == scene.text
    assert attrs["package_version"] == balloon_cg.__version__
    assert attrs["generated_digest"] == generated_digest()
    assert attrs["tolerance"] == scene.solver.tol
    assert attrs["note"] == "test" and isinstance(attrs["command"], str)
    created = datetime.datetime.fromisoformat(attrs["created"])
    assert created.utcoffset() == datetime.timedelta(0)

    b = run["branches"]["primary"]
    n, n_theta = len(branch.X), scene.output.theta_points
    np.testing.assert_array_equal(b["unknowns"], branch.X)
    np.testing.assert_array_equal(b["pressure"], branch.pressure)
    for name, values in branch.pole_values().items():
        np.testing.assert_array_equal(b[name], values)
    for name, values in equator_values(branch.disc, branch.X).items():
        np.testing.assert_array_equal(b[name], values)
    np.testing.assert_array_equal(b["residual"], branch.residual)
    np.testing.assert_array_equal(b["error_estimate"], branch.error_estimate)
    np.testing.assert_array_equal(b["newton_iterations"], branch.iterations)
    assert b["converged"].dtype == bool and b["converged"].all() and b["converged"].shape == (n,)
    np.testing.assert_array_equal(b["theta"], np.linspace(0, np.pi, n_theta))
    assert set(b["profiles"]) == {"lam1", "lam2", "rho", "eta"}
    assert all(p.shape == (n, n_theta) for p in b["profiles"].values())

    a = b["attrs"]
    assert a["stop_reason"] == branch.stop_reason and a["wall_time"] == branch.wall_time
    assert (a["degree"], a["symmetric"], a["pin_translation"]) == (scene.solver.degree, True, True)
    assert a["kernel_class"] == "ogden_spom1" == branch.kernel_class
    assert a["kernel_signature"] == branch.kernel_signature
    assert (a["M"], a["chi"]) == (0.0, 1.0)

    assert [s["kind"] for s in b["special_points"]] == [s.kind for s in branch.special] == ["EP", "LP", "EP"]
    for stored, sp in zip(b["special_points"], branch.special):
        assert stored["index"] == sp.index and stored["stop_code"] == (sp.stop.code.value if sp.stop else "")
        assert stored["note"] == (sp.stop.message if sp.stop else sp.note)
        assert stored["pressure"] == sp.X[-1]
        assert stored["lam2_top"] == pytest.approx(branch.pole_values(sp.X)["lam2_top"][0], rel=1e-15)
    np.testing.assert_array_equal(b["special_unknowns"], [sp.X for sp in branch.special])


@pytest.mark.parametrize("which", ["branch", "free_branch"])
def test_sphere_profiles(request, scene, which):
    """M = 0: a centred sphere, ρ² + η² = λ², λ1 = λ2 = λ, η = ±λ at the poles."""
    branch = request.getfixturevalue(which)
    theta = theta_grid(scene.output.theta_points)
    shape = profiles(branch.disc, branch.X, theta)
    lam = branch.pole_values()["lam2_top"][:, None]
    np.testing.assert_allclose(shape["rho"] ** 2 + shape["eta"] ** 2, lam**2 * np.ones_like(theta), rtol=0, atol=1e-10)
    np.testing.assert_allclose(shape["lam1"], lam * np.ones_like(theta), rtol=0, atol=1e-10)
    np.testing.assert_allclose(shape["lam2"], lam * np.ones_like(theta), rtol=0, atol=1e-10)
    np.testing.assert_allclose(shape["eta"][:, 0], lam[:, 0], rtol=0, atol=1e-10)
    np.testing.assert_allclose(shape["eta"][:, -1], -lam[:, 0], rtol=0, atol=1e-10)
    equator = equator_values(branch.disc, branch.X)
    middle = len(theta) // 2  # θ = π/2 for an odd number of points
    np.testing.assert_allclose(equator["lam1_equator"], shape["lam1"][:, middle], rtol=1e-14)
    np.testing.assert_allclose(equator["lam2_equator"], shape["lam2"][:, middle], rtol=1e-14)


@pytest.mark.parametrize("which", ["branch", "free_branch"])
def test_fields_match_evaluate(request, which):
    branch = request.getfixturevalue(which)
    theta = np.linspace(0, np.pi, 13)
    rng = np.random.default_rng(0)
    U = rng.normal(size=(3, branch.disc.size))
    batched = fields(branch.disc, U, theta)
    for i, u in enumerate(U):
        for got, want in zip(batched, branch.disc.evaluate(u, theta)):
            np.testing.assert_allclose(got[i], want, rtol=1e-13, atol=1e-13)


def _temp_files(directory):
    return sorted(p.name for p in Path(directory).iterdir() if p.name.endswith(".tmp"))


def test_existing_file_kept_without_force(tmp_path, scene, branch):
    path = tmp_path / "run.h5"
    path.write_bytes(b"keep me")
    with pytest.raises(FileExistsError, match="--force"):
        write_run(path, scene, [branch])
    assert path.read_bytes() == b"keep me"
    write_run(path, scene, [branch], force=True)
    assert read_run(path)["branches"]["primary"]["pressure"].size == len(branch.X)


def test_unconverged_point_is_not_written(tmp_path, scene, branch):
    path = tmp_path / "run.h5"
    path.write_bytes(b"keep me")
    residual = branch.residual.copy()
    residual[3] = np.nan
    with pytest.raises(ValueError, match=r"points \[3\] are not converged"):
        write_run(path, scene, [replace(branch, residual=residual)], force=True)
    assert path.read_bytes() == b"keep me"
    assert _temp_files(tmp_path) == []


def test_failure_mid_write_leaves_file_untouched(tmp_path, scene, branch, monkeypatch):
    path = tmp_path / "run.h5"
    path.write_bytes(b"keep me")

    def fail(*args):
        raise RuntimeError("disk full")

    monkeypatch.setattr(storage, "write_special", fail)
    with pytest.raises(RuntimeError, match="disk full"):
        write_run(path, scene, [branch], force=True)
    assert path.read_bytes() == b"keep me"
    assert _temp_files(tmp_path) == []


def test_read_run_rejects_other_files(tmp_path):
    junk = tmp_path / "junk.h5"
    junk.write_text("not hdf5")
    with pytest.raises(RunFileError, match="not a readable HDF5 file"):
        read_run(junk)
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f.attrs["format"] = "something/2"
    with pytest.raises(RunFileError, match="not a balloon-cg run file"):
        read_run(other)
    with pytest.raises(FileNotFoundError):
        read_run(tmp_path / "missing.h5")


@pytest.mark.parametrize("shape", ["sphere", "spheroid"])
def test_a_file_from_before_a_change_of_its_shapes_readings_says_so(tmp_path, scene, shape):
    """A spheroid's held and m = 1 readings changed meaning in readings revisions 1 and 2 (io.legacy.CHANGED_READINGS):
    a spheroid file without the root attribute ``readings`` (written before it) is shown OUTDATED by inspect and
    its summary lists the change; the same file with it, and a sphere's file either way, are not."""
    from balloon_cg.app.summaries import format_run, summarise_run
    from balloon_cg.io.legacy import READINGS

    shaped = scene.with_overrides({"geometry.shape": shape, "geometry.aspect": 1.2 if shape == "spheroid" else 1.0,
                                   "continuation.stop_stretch": 1.3})
    path = write_run(tmp_path / "run.h5", shaped, [trace_primary(shaped)])
    assert read_run(path)["attrs"]["readings"] == READINGS and summarise_run(read_run(path))["stale_readings"] == []
    with h5py.File(path, "r+") as f:
        del f.attrs["readings"]
    old = read_run(path)
    stale = summarise_run(old)["stale_readings"]
    assert (len(stale) == 2 and all("spheroid" in what for what in stale)) if shape == "spheroid" else stale == []
    assert ("OUTDATED" in format_run(old)) == (shape == "spheroid")


def test_a_sweep_member_from_before_a_change_of_its_shapes_readings_says_so(scene):
    """A sweep's members are judged each by its own provenance and scene (a resumed sweep may mix versions)."""
    from balloon_cg.app.summaries import _stale
    from balloon_cg.io.legacy import READINGS

    spheroid = scene.with_overrides({"geometry.shape": "spheroid", "geometry.aspect": 0.8}).to_toml()
    assert len(_stale({"scene_toml": spheroid})) == 2 and len(_stale({"scene_toml": spheroid,
                                                                                      "readings": 1})) == 1
    assert _stale({"scene_toml": spheroid, "readings": READINGS}) == []
    assert _stale({"scene_toml": scene.to_toml()}) == []


def test_a_continued_file_keeps_the_older_readings_of_its_source():
    """continue copies its source's branches and starts at its point: the file keeps the source's revision when
    that is older (io.legacy.inherited_readings), so an outdated source's continuation is shown OUTDATED too."""
    from balloon_cg.io.legacy import READINGS, inherited_readings

    assert inherited_readings({}) == 0 and inherited_readings({"readings": READINGS}) == READINGS
    assert inherited_readings({"readings": READINGS + 1}) == READINGS


def test_continue_from_a_file_whose_readings_changed_is_refused_in_one_line(tmp_path, scene, capsys):
    """A spheroid's branches stored before readings revision 2 were solved under another hold: continue refuses
    the file (exit 2, one line naming the change) and writes nothing."""
    from balloon_cg.app.cli import main

    shaped = scene.with_overrides({"geometry.shape": "spheroid", "geometry.aspect": 1.2,
                                   "continuation.stop_stretch": 1.3})
    path = write_run(tmp_path / "run.h5", shaped, [trace_primary(shaped)])
    with h5py.File(path, "r+") as f:
        f.attrs["readings"] = 1
    out = tmp_path / "continued.h5"
    assert main(["continue", str(path), "1", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "written before this version changed its readings" in err and not out.exists()


@pytest.mark.parametrize("held, named", [({"held_shape": "cube", "held_size": 1.2}, "held_shape = 'cube'"),
                                         ({"held_shape": "spheroid"}, "held_shape without held_size"),
                                         ({"held_shape": "spheroid", "held_size": -1.0}, "held_size = -1.0")])
def test_a_damaged_held_attribute_is_refused_in_one_line(run_file, held, named):
    """held_shape/held_size (a held general basis's area centroid) are both there or neither, a held shape and a
    finite positive size: else RunFileError naming it (before: an internal error at continue, a KeyError)."""
    with h5py.File(run_file, "r+") as f:
        f["branches/primary"].attrs.update(held)
    with pytest.raises(RunFileError) as refused:
        read_run(run_file)
    assert named in str(refused.value) and "\n" not in str(refused.value)
