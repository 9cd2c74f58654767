"""Importing balloon_cg leaves the process's BLAS threads alone; the computation limits them to one thread
inside its entry points only (numerics.threads)."""
import subprocess
import sys

CODE = """
import numpy, scipy.linalg
from threadpoolctl import threadpool_info
def counts():
    return [i['num_threads'] for i in threadpool_info() if i['user_api'] == 'blas']
before = counts()
assert before and all(n == 2 for n in before), before
import balloon_cg, balloon_cg.analysis.picture
balloon_cg.analyse  # the API loaded
assert counts() == before, (counts(), before)
from balloon_cg.numerics.threads import blas_threads, limited_blas
inside = []
@limited_blas
def work():
    with blas_threads():  # nested: still limited, and the outer exit restores
        inside.append(counts())
    inside.append(counts())
work()
assert all(n == 1 for c in inside for n in c), inside
assert counts() == before, (counts(), before)
"""


def test_import_leaves_blas_threads_and_entry_points_limit_them():
    env = {"PATH": "", "OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2", "MKL_NUM_THREADS": "2"}
    subprocess.run([sys.executable, "-c", CODE], check=True, env=env)
