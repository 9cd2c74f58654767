"""``balloon-cg continue`` from a tube run file's label (issue 38): at the onset of bulging (an odd branch point of
the primary branch) the bulge branch switched there with new continuation settings is the one ``run`` traces with
them, bit for bit (the bulge traced further than the file's); with ``--parameter M`` the onset curve is
``critical``'s; any other label, setting or parameter exits 2 with one line and writes nothing."""
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.app.cli import main
from balloon_cg.galerkin.interval import Mirror
from balloon_cg.io.tube_file import read_tube_run, stored_branch
from balloon_cg.scene import load_scene
from balloon_cg.tube.bulge import bulge_branch
from balloon_cg.tube.primary import scene_parameters

from shared_pictures import first_bulge_picture, tube_critical_file, tube_run_file

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "scenes" / "tube_spom1_L10.toml"
COIL_SCENE = ROOT / "scenes" / "tube_spom1_L10_coil.toml"


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    """`balloon-cg run` of SCENE at degree 16 to a hoop stretch of 3 (shared_pictures.TUBE_FAST), written once per session (tests/shared_pictures.py)."""
    return tube_run_file(tmp_path_factory)


def test_the_bulge_from_the_onset_label_is_runs_with_the_new_settings(run_file, tmp_path, capsys):
    out = tmp_path / "further.h5"
    assert main(["continue", str(run_file), "1", "--set", "continuation.stop_stretch=4", "-o", str(out)]) == 0
    assert capsys.readouterr().out.startswith("branch bulge from label 1: ")
    continued, stored = read_tube_run(out), read_tube_run(run_file)
    assert np.array_equal(continued["branches"]["primary"]["unknowns"], stored["branches"]["primary"]["unknowns"])
    scene = load_scene(SCENE).with_overrides({"solver.degree": 16, "continuation.stop_stretch": 4})
    bulge = first_bulge_picture(scene).branches["bulge"]  # run's (shared_pictures.py)
    assert np.array_equal(continued["branches"]["bulge"]["unknowns"], bulge.states)
    assert [s["pressure"] for s in continued["branches"]["bulge"]["special_points"]] == \
        [s.pressure for s in bulge.special]
    assert len(bulge.pressure) > len(stored["branches"]["bulge"]["pressure"])  # further than the file's


def test_the_branch_from_an_even_label_is_bulge_branchs(run_file, tmp_path, capsys):
    """Label 2, the primary branch's first even branch point (the mode cos(2πS/L) of the uniform tube): the branch
    switched there (tube/bulge.bulge_branch, traced on the even block: mirror-symmetric), bit for bit."""
    out = tmp_path / "even.h5"
    assert main(["continue", str(run_file), "2", "-o", str(out)]) == 0
    assert capsys.readouterr().out.startswith("branch bulge_2 from label 2: ")
    scene = load_scene(SCENE).with_overrides({"solver.degree": 16, "continuation.stop_stretch": 3})
    primary = stored_branch(read_tube_run(run_file), "primary", scene_parameters(scene))
    assert (primary.special[2].kind, primary.special[2].block) == ("BP", "even")
    even = bulge_branch(scene, primary, primary.special[2], stop_stretch=3)
    continued = read_tube_run(out)["branches"]["bulge_2"]
    assert np.array_equal(continued["unknowns"], even.states) and len(even.pressure) > 5
    assert (continued["attrs"]["parent_branch"], continued["attrs"]["parent_label"]) == ("primary", 2)
    assert np.array_equal(continued["unknowns"], read_tube_run(run_file)["branches"]["bulge_2"]["unknowns"])  # run's
    assert np.abs(even.states[:, even.disc.block(Mirror.ODD)]).max() == 0


def test_the_onset_in_m_from_the_label_is_critical_s(tmp_path_factory, tmp_path, capsys):
    critical = tube_critical_file(tmp_path_factory)  # `critical` of COIL_SCENE, once per session
    stored = read_tube_run(critical)
    label = next(k for k, s in enumerate(stored["branches"]["primary"]["special_points"])
                 if (s["kind"], s["block"]) == ("BP", "odd"))
    out = tmp_path / "onset.h5"
    assert main(["continue", str(critical), str(label), "--parameter", "M", "-o", str(out)]) == 0
    onset = read_tube_run(out)["onset"]
    assert np.array_equal(onset["q"], stored["onset"]["q"]) and np.array_equal(onset["unknowns"],
                                                                                stored["onset"]["unknowns"])


@pytest.mark.parametrize("extra, message", [
    (["0"], "label 0: LP on branch primary; a tube continues from a branch point of its primary branch (odd: the "
            "onset of bulging; even: on its uniform branch): labels 1, 2, 3, 4, 5"),
    (["2", "--parameter", "M"], "label 2: BP even on branch primary; a tube continues from an odd branch point of "
                                "its primary branch (the onset of bulging): labels 1, 3, 5"),
    (["6"], "label 6: LV on branch bulge;"),
    (["17"], "label 17: no such label;"),
    (["1", "--set", "material.preset=TPOM1"], "--set material.preset=TPOM1: the stored branch belongs to the file's "
                                              "scene; allowed: continuation.* keys"),
    (["1", "--parameter", "chi"], "--parameter chi: a tube's onset is followed in M"),
    (["1", "--parameter", "M"], "continue --parameter M needs coils"),
])
def test_other_labels_settings_and_parameters_exit_2_in_one_line(run_file, tmp_path, capsys, extra, message):
    out = tmp_path / "x.h5"
    assert main(["continue", str(run_file), *extra, "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err
    assert not out.exists()
