"""balloon-cg: nonlinear mechanics of inflatable magnetoelastic membranes.

The dense systems here are small (a few hundred unknowns at most), where multi-threaded BLAS only adds
synchronisation cost (measured: the SPOM1 M = 0 stability picture took 4.4 s with one BLAS thread and 83 s
with two on a loaded 2-core machine). Importing balloon_cg therefore limits BLAS to one thread; set
BALLOON_CG_BLAS_THREADS to another number to change that.
"""
import os

import numpy  # noqa: F401  (load numpy's and scipy's BLAS first: threadpoolctl limits loaded libraries only)
import scipy.linalg  # noqa: F401
from threadpoolctl import threadpool_limits

__version__ = "0.1.0"

threadpool_limits(int(os.environ.get("BALLOON_CG_BLAS_THREADS", "1")), user_api="blas")
