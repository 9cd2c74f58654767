"""balloon-cg: nonlinear mechanics of inflatable magnetoelastic membranes.

The dense systems here are small (a few hundred unknowns at most), where multi-threaded BLAS only adds
synchronisation cost (measured: the SPOM1 M = 0 stability picture took 4.4 s with one BLAS thread and 83 s
with two on a loaded 2-core machine). Importing balloon_cg therefore limits BLAS to one thread; set
BALLOON_CG_BLAS_THREADS to another number to change that.

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
import importlib.util
import os
import sys
from pathlib import Path

import numpy  # noqa: F401  (load numpy's and scipy's BLAS first: threadpoolctl limits loaded libraries only)
import scipy.linalg  # noqa: F401
from threadpoolctl import threadpool_limits

__version__ = "0.1.0"


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
threadpool_limits(int(os.environ.get("BALLOON_CG_BLAS_THREADS", "1")), user_api="blas")
