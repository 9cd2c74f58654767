"""Pictures several test files read, computed once per test session and shared by the xdist workers.

The two-coil axisymmetric picture (SPOM1 between the paper's coils at M = 0.002, ``surface.branches = "none"``)
was analysed by four files, ~20 s each. ``shared(tmp_path_factory, name, compute)`` computes a result once per
session: the first worker to ask holds an exclusive lock on the session's shared folder while it computes and
pickles it (written to a temporary name, then renamed), the others wait on the lock and load the file. The folder
is the session's (xdist's run id names it under the workers' common base; a serial run uses its own base), so a
result never outlives the code that made it.
"""
import fcntl
import os
import pickle
from pathlib import Path

import balloon_cg as bc

TWO_COILS = "spom1_two_coils_M0.002"


def shared_folder(tmp_path_factory) -> Path:
    """This session's folder shared by every worker (xdist's base temp holds each worker's own)."""
    run = os.environ.get("PYTEST_XDIST_TESTRUNUID")
    base = tmp_path_factory.getbasetemp()
    folder = base.parent / f"shared-{run}" if run else base / "shared"
    folder.mkdir(exist_ok=True)
    return folder


def shared(tmp_path_factory, name: str, compute):
    """``compute()`` once per session, pickled to the shared folder as ``name``; every caller gets a fresh copy."""
    folder = shared_folder(tmp_path_factory)
    path = folder / f"{name}.pickle"
    with open(folder / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not path.exists():
            partial = path.with_suffix(".partial")
            partial.write_bytes(pickle.dumps(compute()))
            partial.replace(path)
        return pickle.loads(path.read_bytes())


def two_coil_result(tmp_path_factory) -> bc.Result:
    """``bc.analyse`` of the shipped two-coil scene without surface branches: primary, pear and free pear branches,
    assessed (``.picture``: the analysis objects)."""
    return shared(tmp_path_factory, "two_coil_result", lambda: bc.analyse(
        bc.Scene.from_toml(TWO_COILS).with_overrides({"surface.branches": "none"})))


def two_coil_picture(tmp_path_factory):
    """The analysis objects (analysis.picture.Picture) of ``two_coil_result``."""
    return two_coil_result(tmp_path_factory).picture
