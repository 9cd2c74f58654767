"""The default run's scenes at once (app/default_run.py): each but the last in a child process beside this one. A
child's outcome (its files and what failed, one JSON object) and its stderr reach the run's output and exit code; a
child that dies without its outcome is a failure."""
import os
import subprocess
import sys

import pytest

from balloon_cg.app import default_run


def _child(code: str):
    """A stand-in for ``default_run._started``: a child running ``code``."""
    return lambda name, outdir, quick, ahead: subprocess.Popen([sys.executable, "-c", code, name], stdout=subprocess.PIPE,
                                                       stderr=subprocess.PIPE, text=True)


@pytest.fixture
def last_scene_fails(monkeypatch):
    """The last scene's trace fails (no file), so that only the child's files could be listed."""
    monkeypatch.setattr(default_run, "run_and_draw", lambda scene, outdir, quick, quiet, **_: {
        "path": None, "images": [], "failure": f"{scene.name}: x"})


def test_a_childs_failure_and_output_reach_the_run(monkeypatch, tmp_path, capsys, last_scene_fails):
    monkeypatch.setattr(default_run, "_started", _child(
        "import json, sys; print('a warning', file=sys.stderr); print(json.dumps({'path': None, 'images': "
        "['figure.png'], 'failure': 'spom1: did not converge'})); sys.exit(1)"))
    assert default_run.main([str(tmp_path), "--quiet"]) == 1
    out, err = capsys.readouterr()
    assert "figure.png" in out
    assert "failed: spom1: did not converge" in err and "a warning" in err
    assert "failed: spom1_two_coils_M0.002: x" in err


def test_a_child_that_dies_without_a_word_is_a_failure(monkeypatch, tmp_path, capsys, last_scene_fails):
    monkeypatch.setattr(default_run, "_started", _child("import os; os._exit(3)"))
    assert default_run.main([str(tmp_path), "--quiet"]) == 1
    assert "failed: spom1: exit 3" in capsys.readouterr().err


def test_the_children_are_the_scenes_before_the_last(monkeypatch, tmp_path, last_scene_fails):
    started = []
    monkeypatch.setattr(default_run, "_started", lambda name, outdir, quick, ahead: started.append(name) or
                        subprocess.Popen([sys.executable, "-c", ""], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                         text=True))
    default_run.main([str(tmp_path), "--quiet"])
    assert started == list(default_run.SCENES[:-1])


def test_a_child_compiles_the_last_scenes_whole_sphere_kernels_between_its_run_file_and_its_figures(
        monkeypatch, tmp_path):
    """The child is told the scene this process runs (``--ahead``), and compiles its whole-sphere kernels
    (analysis.surface.branches.compile_kernels) once its own run file is written, before its figures."""
    commands = []
    monkeypatch.setattr(subprocess, "Popen", lambda command, **_: commands.append(command))
    default_run._started(default_run.SCENES[0], tmp_path, False, default_run.SCENES[-1])
    assert commands[0][-4:] == ["--only", default_run.SCENES[0], "--ahead", default_run.SCENES[-1]]
    done = []
    monkeypatch.setattr(default_run, "run_scene", lambda scene, path, **_: done.append(("run", scene.name)) or (
        path, []))
    monkeypatch.setattr(default_run, "compile_kernels", lambda scene: done.append(("compile", scene.name)))
    monkeypatch.setattr(default_run, "draw_figures", lambda paths, outdir, stem: done.append(("draw", stem)) or [])
    child, last = default_run.SCENES[0], default_run.SCENES[-1]
    assert default_run.main([str(tmp_path), "--quiet", "--only", child, "--ahead", last]) == 0
    assert done == [("run", child), ("compile", last), ("draw", child)]


AHEAD = """import sys
from balloon_cg.app.default_run import default_scenes
from balloon_cg.analysis.surface.branches import compile_kernels
compile_kernels(default_scenes()[-1])
"""
# the surface trace of the two-coil scene at another degree, symmetry and a wire map: what its surface branches
# call (residual, Jacobian, energy, a sector's Hessian reduced); prints the balloon_cg kernels compiled, not loaded
SURFACE = """import gc
import numpy as np
from numba.core.registry import CPUDispatcher
from balloon_cg.app.default_run import default_scenes
from balloon_cg.analysis.branches.primary import start_parameters
from balloon_cg.analysis.surface.branches import SurfaceTrace
from balloon_cg.galerkin.coordinate_map import WireMap
from balloon_cg.surface.basis import EQUATOR, MIRROR_Y, SphericalBasis
WIRE_MAP = WireMap((-0.4, 0.4), (0.3, 0.3))
scene = default_scenes()[-1]
params = start_parameters(scene, "P").with_value("M", scene.field.M)
trace = SurfaceTrace(scene, SphericalBasis(5, (MIRROR_Y, EQUATOR), order=3, mapping=WIRE_MAP), params)
c = np.zeros(trace.basis.size)
X = trace.system.point(c, params.P)
trace.system.residual(X), trace.system.jacobian(X), trace.eq.energy(c, params)
trace.gauge.reduce_matrix(trace.eq.hessian(c, params, SphericalBasis(5, (MIRROR_Y,), (-1,), order=3,
                                                                     mapping=WIRE_MAP)))
print(sorted(d.py_func.__qualname__ for d in gc.get_objects() if isinstance(d, CPUDispatcher)
             and d.py_func.__module__.startswith("balloon_cg") and sum(d._cache_misses.values())))
"""


def test_the_whole_sphere_kernels_compiled_ahead_are_those_a_surface_trace_loads(tmp_path):
    """After ``compile_kernels`` in one process (a fresh numba cache), a surface trace of the same scene in another
    (another degree, symmetry and order, on a wire map) compiles nothing: every kernel it calls is in the cache."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    subprocess.run([sys.executable, "-c", AHEAD], env=env, check=True, capture_output=True, text=True)
    out = subprocess.run([sys.executable, "-c", SURFACE], env=env, check=True, capture_output=True, text=True).stdout
    assert out.strip() == "[]"
