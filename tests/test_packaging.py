"""Installing: the wheel ships exactly the source tree (generated kernels and scenes included), and the README's
sequence `pip install .`, `make run`, `make test` on a fresh venv leaves a working package after each step
(numba's cache outside site-packages, so pip leaves nothing behind), and kernels of another tree are refused.

Offline and fast: builds without isolation from the current environment's setuptools, and the fresh venv has
no pip or dependencies of its own: a .pth file puts the current environment's site folders on its path.
"""
import importlib.metadata
import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
LEFT_OUT = shutil.ignore_patterns("build", "dist", "*.egg-info", "__pycache__", ".git", ".pytest_cache", "out")
CHECK = """
import json, sys
from importlib import resources
import balloon_cg, balloon_cg.generated as generated
from balloon_cg.model.elliptic import _agm
_agm(0.5, 0.5)  # a cache=True kernel: loaded from or written to numba's cache
print(json.dumps({"package": balloon_cg.__file__, "generated": generated.__file__, "classes": len(generated.CLASSES),
                  "scene": (resources.files("balloon_cg.scenes") / "spom1.toml").is_file(),
                  "cache_hits": sum(_agm.stats.cache_hits.values())}))
"""


def clean_copy(tmp_path) -> Path:
    """The source tree without build products (a stale build/lib would leak into a wheel built in place)."""
    return Path(shutil.copytree(ROOT, tmp_path / "tree", ignore=LEFT_OUT))


def shipped(tree: Path) -> set:
    """Wheel paths of every file the package must ship (package-dir of pyproject.toml)."""
    folders = {"balloon_cg": tree / "src" / "balloon_cg", "balloon_cg/generated": tree / "generated",
               "balloon_cg/scenes": tree / "scenes", "balloon_cg/codegen": tree / "codegen"}
    code = {f"{prefix}/{path.relative_to(folder).as_posix()}" for prefix, folder in folders.items()
            for path in folder.rglob("*") if path.suffix in (".py", ".toml", ".mplstyle")}
    docs = {f"balloon_cg/docs/{path.name}" for path in (tree / "docs").glob("*")  # the pages, not derivations/
            if path.suffix in (".md", ".png") or path.name == "__init__.py"}
    return code | docs


def test_wheel_ships_exactly_the_source_tree(tmp_path):
    tree = clean_copy(tmp_path)
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "--no-build-isolation",
                    "-w", str(tmp_path), str(tree)], check=True, capture_output=True)
    wheel = next(tmp_path.glob("balloon_cg-*.whl"))
    names = {n for n in zipfile.ZipFile(wheel).namelist() if ".dist-info/" not in n}
    assert names == shipped(tree)
    assert {"balloon_cg/scenes/spom1.toml", "balloon_cg/generated/__init__.py", "balloon_cg/docs/MODEL.md"} <= names


def test_the_shipped_model_page_is_the_shared_one():
    """docs/MODEL.md, which docstrings, docs pages and help texts cite, ships with the package; it is a copy of the
    project's shared MODEL.md (beside the clone in CI and in the work folders), so the two cannot drift."""
    shared = ROOT.parent / "shared" / "MODEL.md"
    if not shared.is_file():
        pytest.skip(f"no shared folder beside the clone ({shared})")
    assert (ROOT / "docs" / "MODEL.md").read_bytes() == shared.read_bytes()


def fresh_venv(tmp_path) -> tuple[Path, Path]:
    """(python, site-packages) of a new venv without pip that sees the current environment's distributions."""
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    python = venv / "bin" / "python"
    site = Path(subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                               check=True, capture_output=True, text=True).stdout.strip())
    folders = dict.fromkeys(str(d.locate_file("")) for d in importlib.metadata.distributions())
    # the source tree itself is left out (it must come from the installs under test), not an environment that
    # happens to live inside it (a venv in the clone)
    inside = [f for f in folders if f.startswith(str(ROOT)) and "site-packages" not in Path(f).parts]
    (site / "environment.pth").write_text("".join(f"{f}\n" for f in folders if f not in inside))
    return python, site


def run(args, env, cwd):
    done = subprocess.run([str(a) for a in args], env=env, cwd=cwd, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def check(python, env, cwd) -> dict:
    return json.loads(run([python, "-c", CHECK], env, cwd).splitlines()[-1])


@pytest.mark.skipif(shutil.which("make") is None, reason="needs make")
def test_install_then_make_run_then_make_test_on_a_fresh_venv(tmp_path):
    tree = clean_copy(tmp_path)
    python, site = fresh_venv(tmp_path)
    cache = tmp_path / "cache"
    # PYTHONDONTWRITEBYTECODE unset: make's installs leave the bytecode to Python (pip --no-compile)
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "PYTHONPATH", "PYTHONDONTWRITEBYTECODE")}
    # PIP_NO_BUILD_ISOLATION=0 means --no-build-isolation (pip reads the variable as "isolation off")
    env.update(XDG_CACHE_HOME=str(cache), PIP_NO_INDEX="1", PIP_NO_BUILD_ISOLATION="0",
               PIP_DISABLE_PIP_VERSION_CHECK="1")

    run([python, "-m", "pip", "install", "--quiet", "--no-deps", tree], env, tmp_path)  # README: pip install .
    first, second = check(python, env, tmp_path), check(python, env, tmp_path)
    assert first["package"] == str(site / "balloon_cg" / "__init__.py")
    assert first["generated"] == str(site / "balloon_cg" / "generated" / "__init__.py")
    assert first["classes"] > 0 and first["scene"]
    record = (next(site.glob("balloon_cg-*.dist-info")) / "RECORD").read_text().splitlines()
    installed = {line.split(",")[0] for line in record}
    on_disk = {p.relative_to(site).as_posix() for p in (site / "balloon_cg").rglob("*") if p.is_file()}
    assert on_disk - installed == set()  # nothing pip would leave behind on uninstall
    assert first["cache_hits"] == 0 and second["cache_hits"] > 0  # compiled once, then loaded from the cache
    assert any((cache / "balloon-cg" / "numba").rglob("*.nbi"))

    out = tmp_path / "out"
    run(["make", "-C", tree, "run", f"PYTHON={python}", f"OUT={out}", "RUN_FLAGS=--quick --quiet"], env, tmp_path)
    assert (out / "spom1.h5").is_file() and (out / "spom1_two_coils_M0.002.h5").is_file()
    editable = check(python, env, tmp_path)
    assert editable["package"] == str(tree / "src" / "balloon_cg" / "__init__.py")
    assert editable["generated"] == str(tree / "generated" / "__init__.py")
    assert editable["scene"] and editable["cache_hits"] > 0

    run(["make", "-C", tree, "install-dev", f"PYTHON={python}"], env, tmp_path)  # the install step of make test
    assert check(python, env, tmp_path) == editable


@pytest.mark.skipif(shutil.which("make") is None, reason="needs make")
@pytest.mark.parametrize("target", ["install", "install-dev"])
def test_make_leaves_the_bytecode_to_python_unless_python_never_writes_it(target):
    """pip --no-compile (Python writes the bytecode of what it imports, at its first import), but pip's byte
    compilation where PYTHONDONTWRITEBYTECODE is set (Python would compile the sources at every start)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    writes, never = (run(["make", "--dry-run", "-C", ROOT, target, "PYTHON=python3"], e, ROOT)
                     for e in (env, env | {"PYTHONDONTWRITEBYTECODE": "1"}))
    assert "pip install" in writes and "--no-compile" in writes
    assert "pip install" in never and "--no-compile" not in never


def test_generated_kernels_of_another_tree_are_refused(tmp_path):
    """balloon_cg from a copy of src/ on PYTHONPATH, the kernels from the installed tree (or none): ImportError."""
    other = tmp_path / "other" / "src" / "balloon_cg"
    shutil.copytree(ROOT / "src" / "balloon_cg", other, ignore=LEFT_OUT)
    env = {**os.environ, "PYTHONPATH": str(other.parent)}
    done = subprocess.run([sys.executable, "-c", "import balloon_cg"], env=env, cwd=tmp_path,
                          capture_output=True, text=True)
    assert done.returncode != 0
    message = done.stderr.strip().splitlines()[-1]
    assert message.startswith("ImportError") and str(other) in message and "expected" in message


@pytest.mark.parametrize("first, user_dir", [("", False), ("import numba; ", False), ("", True)])
def test_numba_cache_folder(tmp_path, first, user_dir):
    """${XDG_CACHE_HOME}/balloon-cg/numba (also when numba was imported first), or the user's NUMBA_CACHE_DIR."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path / "xdg")
    if user_dir:
        env["NUMBA_CACHE_DIR"] = str(tmp_path / "mine")
    code = f"{first}from balloon_cg.model.elliptic import _agm; _agm(0.5, 0.5); print(_agm.stats.cache_path)"
    folder = run([sys.executable, "-c", code], env, tmp_path).strip()
    assert Path(folder).parent == (tmp_path / "mine" if user_dir else tmp_path / "xdg" / "balloon-cg" / "numba")
    assert any(Path(folder).glob("*.nbi"))
