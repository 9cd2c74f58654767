"""balloon-cg: nonlinear mechanics of inflatable magnetoelastic membranes.

The public API (docs/api.md) is importable from here and loaded on first use, so ``import balloon_cg`` stays
light (no numpy, numba or matplotlib until a name needs them)::

    import balloon_cg as bc
    scene = bc.Scene.from_toml("spom1_two_coils_M0.002").with_overrides({"field.M": 0.001})  # a shipped scene
    result = bc.analyse(scene)          # or bc.trace(scene): the primary branch only
    result.to_dataframe(); result.save("spom1.h5"); bc.plot(result, "pressure-pole")

Importing balloon_cg leaves the process's BLAS threads alone: the computation limits them inside its own
entry points (``numerics.threads``).

numba's on-disk cache of compiled kernels (``cache=True``) goes to NUMBA_CACHE_DIR, which importing balloon_cg
sets, unless it is set already, to ``$XDG_CACHE_HOME/balloon-cg/numba`` (``~/.cache/balloon-cg/numba``):
never into the package. Cache files inside an installed package are files pip did not install, so they
survive ``pip uninstall`` (a regular install replaced by an editable one then leaves a namespace package
balloon_cg in site-packages that shadows the editable one). numba names each cache entry after the folder of
its source file (folder name and a hash of its path), so several checkouts and installs share the cache
folder without collisions.

Importing balloon_cg also checks that balloon_cg.generated (the kernels of codegen/) comes from the same tree:
<site-packages>/balloon_cg/generated when installed, <root>/generated next to <root>/src/balloon_cg in a
checkout (editable install). Anything else mixes two versions of the code and raises ImportError.
"""
import importlib
import importlib.util
import os
import sys
from pathlib import Path

__version__ = "0.1.0"

_API = {
    "Scene": "balloon_cg.scene", "SceneError": "balloon_cg.scene", "load_scene": "balloon_cg.scene",
    "parse_scene": "balloon_cg.scene", "shipped_scenes": "balloon_cg.scene", "PlotError": "balloon_cg.post.plotting",
    "Result": "balloon_cg.app.api", "BranchData": "balloon_cg.app.api", "trace": "balloon_cg.app.api",
    "analyse": "balloon_cg.app.api", "load": "balloon_cg.app.api", "plot": "balloon_cg.app.api",
    "continue_from": "balloon_cg.app.api",
    "SweepResult": "balloon_cg.app.sweep_result", "CurveResult": "balloon_cg.app.curve_result",
    "TubeResult": "balloon_cg.app.tube_result",
    "SpecialPoints": "balloon_cg.app.tables",
    "journal_style": "balloon_cg.post.style", "JOURNAL_STYLE": "balloon_cg.post.style",
}
__all__ = ["__version__", *_API]


def __getattr__(name: str):
    """The public API on first use (PEP 562)."""
    if name not in _API:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_API[name]), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(__all__)


def _numba_cache_dir() -> Path:
    """$XDG_CACHE_HOME/balloon-cg/numba, XDG_CACHE_HOME defaulting to ~/.cache."""
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "balloon-cg" / "numba"


if not os.environ.get("NUMBA_CACHE_DIR"):
    os.environ["NUMBA_CACHE_DIR"] = str(_numba_cache_dir())
    if "numba.core.config" in sys.modules:  # numba imported before balloon_cg: it read its settings already
        sys.modules["numba.core.config"].reload_config()


def _check_generated_tree() -> None:
    """ImportError unless balloon_cg.generated is <package>/generated or, in a checkout, <root>/generated."""
    package = Path(__file__).resolve().parent
    expected = [package / "generated"]
    if package.parent.name == "src":
        expected.append(package.parent.parent / "generated")
    spec = importlib.util.find_spec(f"{__name__}.generated")
    found = Path(spec.origin).resolve().parent if spec is not None and spec.has_location else None
    if found not in expected:
        where = "not found" if spec is None else (
            f"from {found}" if found else f"a namespace package over {list(spec.submodule_search_locations)}")
        raise ImportError(
            f"balloon_cg is imported from {package} but balloon_cg.generated is {where}; expected "
            f"{' or '.join(map(str, expected))}. Two trees are mixed (a sys.path entry of one checkout and an "
            "install of another, or the leftovers of an earlier install): reinstall from one tree "
            "(pip uninstall balloon-cg, then pip install . or pip install -e . there) and run without "
            "sys.path/PYTHONPATH entries pointing into another checkout.")


_check_generated_tree()
