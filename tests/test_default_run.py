"""The default run's scenes at once (app/default_run.py): each but the last in a child process beside this one. A
child's outcome (its files and what failed, one JSON object) and its stderr reach the run's output and exit code; a
child that dies without its outcome is a failure."""
import subprocess
import sys

import pytest

from balloon_cg.app import default_run


def _child(code: str):
    """A stand-in for ``default_run._started``: a child running ``code``."""
    return lambda name, outdir, quick: subprocess.Popen([sys.executable, "-c", code, name], stdout=subprocess.PIPE,
                                                       stderr=subprocess.PIPE, text=True)


@pytest.fixture
def last_scene_fails(monkeypatch):
    """The last scene's trace fails (no file), so that only the child's files could be listed."""
    monkeypatch.setattr(default_run, "run_and_draw",
                        lambda scene, outdir, quick, quiet: {"path": None, "images": [], "failure": f"{scene.name}: x"})


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
    monkeypatch.setattr(default_run, "_started", lambda name, outdir, quick: started.append(name) or
                        subprocess.Popen([sys.executable, "-c", ""], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                         text=True))
    default_run.main([str(tmp_path), "--quiet"])
    assert started == list(default_run.SCENES[:-1])
