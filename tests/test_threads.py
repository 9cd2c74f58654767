"""Importing balloon_cg limits every loaded BLAS (numpy's and scipy's) to one thread (see balloon_cg/__init__)."""
import subprocess
import sys


def test_blas_is_single_threaded_after_import():
    code = (
        "import balloon_cg, balloon_cg.analysis.picture\n"
        "from threadpoolctl import threadpool_info\n"
        "blas = [i for i in threadpool_info() if i['user_api'] == 'blas']\n"
        "assert blas and all(i['num_threads'] == 1 for i in blas), blas\n"
    )
    env = {"PATH": "", "OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2"}
    subprocess.run([sys.executable, "-c", code], check=True, env=env)
