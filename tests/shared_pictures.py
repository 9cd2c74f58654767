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


def shared_file(tmp_path_factory, name: str, write) -> Path:
    """``write(path)`` once per session into the shared folder as ``name`` (a file the callers only read); its path.
    ``write`` returns True when it succeeded: a failure raises in every caller, and the next caller tries again."""
    folder = shared_folder(tmp_path_factory)
    path = folder / name
    with open(folder / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not path.exists():
            partial = folder / f"partial-{name}"
            assert write(partial), f"writing the shared {name} failed"
            partial.replace(path)
        return path


def two_coil_scene_to(stretch: float) -> bc.Scene:
    """The shipped two-coil scene without surface branches, traced up to λ2(0) = ``stretch``."""
    return bc.Scene.from_toml(TWO_COILS).with_overrides({"continuation.stop_stretch": stretch,
                                                         "surface.branches": "none"})


def two_coil_run_file(tmp_path_factory) -> Path:
    """``balloon-cg run`` of the shipped two-coil scene up to λ2(0) = 1.7 (past its first held and free pear
    pitchforks, 1.669 and 1.681) without surface branches (primary, pear branches, assessed): a file the restarts of
    tests/test_restart.py and the ``surface.branches = "none"`` check of tests/test_surface.py read."""
    from balloon_cg.app.cli import main

    def write(path: Path) -> bool:
        scene = path.with_name("two_coils.toml")  # the scene's name: two_coils
        scene.write_text(two_coil_scene_to(1.7).to_toml())
        return main(["run", str(scene), "-o", str(path), "--quiet"]) == 0

    return shared_file(tmp_path_factory, "two_coils_1.7.h5", write)


SMALL = '[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 2.0\n'  # the whole analysis: ~1.5 s of CPU


def small_run_file(tmp_path_factory) -> Path:
    """``balloon-cg run small.toml`` of SMALL (SPOM1 to λ2(0) = 2: the primary branch with its fold and pear
    pitchfork, the pear branch and its mirror, stability, snap-throughs; complete): the run file the readers' tests
    read or copy and damage (tests/test_damaged_files.py, test_damaged_fuzz.py, test_schema.py, the inspect and plot
    checks of test_cli_conventions.py); made by one of them per session, never written to by any."""
    from balloon_cg.app.cli import main

    def write(path: Path) -> bool:
        scene = path.with_name("small.toml")  # the scene's name: small
        scene.write_text(SMALL)
        return main(["run", str(scene), "-o", str(path), "--quiet"]) == 0

    return shared_file(tmp_path_factory, "small.h5", write)


TUBE = Path(__file__).resolve().parents[1] / "scenes" / "tube_spom1_L10.toml"
TUBE_FAST = ["--set", "solver.degree=16", "--set", "continuation.stop_stretch=3"]  # ~3 s of CPU, every branch switched
TUBE_COIL = TUBE.with_name("tube_spom1_L10_coil.toml")
TUBE_COIL_FAST = ["--set", "continuation.stop_stretch=1.75", "--set", "continuation.max_points=60"]


def tube_run_file(tmp_path_factory) -> Path:
    """``balloon-cg run`` of the shipped SPOM1 tube at TUBE_FAST (the primary branch and the branches switched at its
    five branch points): a file the tube tests of the CLI, ``continue`` and ``load`` read (tests/test_tube_cli.py,
    test_tube_continue.py, test_tube_result.py)."""
    from balloon_cg.app.cli import main

    return shared_file(tmp_path_factory, "tube.h5",
                       lambda path: main(["run", str(TUBE), "-o", str(path), "--quiet", *TUBE_FAST]) == 0)


def tube_critical_file(tmp_path_factory) -> Path:
    """``balloon-cg critical --parameter M`` of the shipped coil tube at TUBE_COIL_FAST (its onset curve; exit 1: the
    fold's state is not resolved at degree 30, its tail above solver.max_error, the file written)."""
    from balloon_cg.app.cli import main

    return shared_file(tmp_path_factory, "tube_critical.h5", lambda path: main(
        ["critical", str(TUBE_COIL), "--parameter", "M", "-o", str(path), "--quiet", *TUBE_COIL_FAST]) == 1)


def first_bulge_picture(scene):
    """``tube_picture(scene)`` asking for less: the primary branch and the branch switched at its first branch point
    alone ("bulge", the first odd one on sliding ends), with Maxwell's pressure and the m ≥ 1 blocks; both branches
    those of the whole picture number for number (``bulge_picture`` switches its labels in order). For tests that
    read the primary and the bulge branch, not the switching at the later branch points (which tube/picture.py does
    at every one: the shipped tube_spom1_L10 has 8 branches)."""
    from balloon_cg.tube.picture import bulge_picture, maxwell, switchable
    from balloon_cg.tube.primary import primary_branch

    pm = maxwell(scene)
    primary = primary_branch(scene)
    return bulge_picture(scene, primary, switchable(scene, primary)[:1], pm)
