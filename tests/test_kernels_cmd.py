"""``balloon-cg kernels SCENE``: generated once into the cache, then reused; without SymPy one clear line."""
import importlib.metadata
import json

from balloon_cg.app.cli import main
from balloon_cg.model import kernel_cache
from balloon_cg.model.kernels import PLAIN

SCENE = '[material]\nenergy = "c*(I1 - 3) + d*(I1 - 3)*(I2 - 3)"\n[material.parameters]\nc = 1.0\nd = 0.002\n'


def test_kernels_generates_then_reuses(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(kernel_cache.CACHE_ENV, str(tmp_path / "cache"))
    scene = tmp_path / "user.toml"
    scene.write_text(SCENE)
    reports = []
    for _ in range(2):
        assert main(["kernels", str(scene), "--json"]) == 0
        reports.append(json.loads(capsys.readouterr().out))
    first, second = reports
    assert (first["source"], second["source"]) == ("generated", "cached")
    assert first["class"] == second["class"] == f"energy_{first['key'][:32]}"
    assert {"derive", "lower", "print", "write", "import"} <= set(first["stages"])
    assert "derive" not in second["stages"] and set(first["jit"]) == set(second["jit"]) >= {"energy_hessian"}


def test_without_sympy_one_line_says_what_to_install(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(kernel_cache.CACHE_ENV, str(tmp_path / "cache"))
    real = importlib.metadata.version

    def version(name):
        if name == "sympy":
            raise importlib.metadata.PackageNotFoundError(name)
        return real(name)

    monkeypatch.setattr(importlib.metadata, "version", version)
    scene = tmp_path / "user.toml"
    scene.write_text(SCENE)
    assert main(["kernels", str(scene)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "pip install 'balloon-cg[codegen]'" in err


def test_run_and_inspect_name_the_user_class_and_its_key(tmp_path, monkeypatch, capsys):
    """A run of a user formula stores the scene TOML (formula and parameters) and the class; inspect shows the
    class, energy_<first 32 hex digits of the cache key>."""
    import h5py

    from balloon_cg.scene import load_scene

    monkeypatch.setenv(kernel_cache.CACHE_ENV, str(tmp_path / "cache"))
    scene = tmp_path / "user.toml"
    scene.write_text(SCENE + "[continuation]\nstop_stretch = 1.5\n")
    out = tmp_path / "user.h5"
    assert main(["run", str(scene), "-o", str(out), "--primary-only"]) == 0
    key = kernel_cache.class_key(load_scene(scene).material.formula, PLAIN)
    capsys.readouterr()
    assert main(["inspect", str(out)]) == 0
    assert f"energy_{key[:32]}" in capsys.readouterr().out
    with h5py.File(out) as f:
        assert 'energy = "c*(I1 - 3) + d*(I1 - 3)*(I2 - 3)"' in f.attrs["scene_toml"]
