"""One line on stderr before numba compiles a generated kernel module for the first time.

numba's on-disk cache (``cache=True``, NUMBA_CACHE_DIR: balloon_cg/__init__.py) keeps an index file per compiled
kernel; a module none of whose kernels has one is compiled on first use, which takes tens of seconds with no
other output. The line is written once per module and process, and only where someone watches: a terminal (as the
progress bars: app/progress.py) or a Jupyter kernel (the notebook shows its stderr), so logs, pipes and captured
output are unchanged.
"""
import os
import sys

from numba.core.registry import CPUDispatcher

FIRST_USE = "up to a minute"  # compiling one kernel module on first use (7 s for what solve needs, 2 cores)
_announced = set()


def compiled_before(module) -> bool:
    """Whether any kernel of ``module`` has an entry in numba's on-disk cache."""
    kernels = [k for k in vars(module).values() if isinstance(k, CPUDispatcher) and k._cache is not None]
    return any(os.path.exists(k._cache._cache_file._index_path) for k in kernels)


def watched() -> bool:
    """stderr is a terminal, or this process is a Jupyter kernel (``jupyter_kernel``)."""
    return sys.stderr.isatty() or jupyter_kernel()


def jupyter_kernel() -> bool:
    """Whether this process is a Jupyter kernel (IPython's kernel app: a notebook shows its stderr)."""
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    return shell is not None and "IPKernelApp" in shell.config


def announce_first_use(module) -> None:
    """Say on a terminal's or a notebook's stderr that ``module``'s kernels are being compiled, if they never were."""
    if module.__name__ in _announced or not watched():
        return
    _announced.add(module.__name__)
    if not compiled_before(module):
        name = module.__name__.rsplit(".", 1)[-1]
        print(f"balloon-cg: compiling the numba kernels {name} on first use ({FIRST_USE}; cached "
              "for later runs)", file=sys.stderr, flush=True)
