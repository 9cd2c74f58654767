"""A capsule continued in the voltage Φ̄ at a fixed pressure (``continuation.parameter = "voltage"``): the sphere's
voltage continuation on any meridian, its start solved (analysis/branches/primary.held_by_voltage) where the sphere
has its closed form.

Checked against
- the neo-Hookean sphere's closed form (tests/test_voltage_branches.py: Φ̄² = λ⁻² − λ⁻⁸ − P/(4λ), λ the stretch):
  the capsule of length 0 is the sphere, so every point of its voltage branch has that voltage, and its pull-in
  (the fold in Φ̄) is the maximum of Φ̄(λ), d(Φ̄²)/dλ = −2λ⁻³ + 8λ⁻⁹ + P/(4λ²) = 0;
- a second continuation (length 3): a fold of Φ̄ at fixed P and a fold of P at fixed Φ̄ are the same singular
  ∂R/∂u, so the capsule traced in P at Φ̄ = 0.3 has its pressure maximum P* where the capsule traced in Φ̄ at P* has
  its pull-in at Φ̄ = 0.3;
- ``continue --parameter voltage`` from a UZ of that P-branch: the branch through it in Φ̄ is the one ``run`` traces
  from its own start at that pressure (the same pull-in).
"""
import numpy as np
import pytest
from scipy.optimize import brentq

from balloon_cg.analysis.branches.tracer import ContinuationError
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Kind, Status
from balloon_cg.app.cli import main
from balloon_cg.io.run_file import read_run
from balloon_cg.scene import parse_scene
from test_dielectric import NEO

PRESSURE = 0.5
CAPSULE = NEO + '[geometry]\nshape = "capsule"\nlength = {length}\n[stability]\nm_max = 0\n'


def voltage_scene(length, pressure=PRESSURE, start=1.1, stop=1.6):
    return parse_scene(CAPSULE.format(length=length) + f'[electric]\n[continuation]\nparameter = "voltage"\n'
                       f"pressure = {pressure!r}\nstart_stretch = {start}\nstop_stretch = {stop}\n")


def charged_scene(length, voltage=0.3, events=""):
    return CAPSULE.format(length=length) + (f"[electric]\nvoltage = {voltage}\n[continuation]\nstart_stretch = 1.1\n"
                                            f"stop_stretch = 1.5\n{events}")


def folds(branch):
    return [s for s in branch.special if s.kind == Kind.LP and s.status == Status.LOCATED]


def test_capsule_of_length_zero_has_the_sphere_voltage_closed_form():
    """Neo-Hookean, P = 0.5, start stretch 1.1 (its voltage solved, not the closed form's): every point's Φ̄² is
    λ⁻² − λ⁻⁸ − P/(4λ) at its pole stretch to 1e-10, and the one located fold (the pull-in) is the closed form's
    maximum of Φ̄ to 1e-9 in λ and Φ̄."""
    branch = analyse(voltage_scene(0.0), pear=False).primary
    lam = np.array([branch.pole_values(X)["lam2_top"][0] for X in branch.X])
    assert np.abs(branch.X[:, -1] ** 2 - (lam**-2 - lam**-8 - PRESSURE / (4 * lam))).max() <= 1e-10
    peak = brentq(lambda x: -2 * x**-3 + 8 * x**-9 + PRESSURE / (4 * x**2), 1.1, 1.6, xtol=1e-15)
    (fold,) = folds(branch)
    assert abs(branch.pole_values(fold.X)["lam2_top"][0] - peak) <= 1e-9
    assert abs(fold.X[-1] - np.sqrt(peak**-2 - peak**-8 - PRESSURE / (4 * peak))) <= 1e-9


def test_capsule_pull_in_is_the_pressure_maximum_at_that_voltage():
    """Length 3: the capsule traced in P at Φ̄ = 0.3 has one located pressure maximum P*; traced in Φ̄ at P* (from
    its own start) it has its pull-in at Φ̄ = 0.3, to 1e-8 (both folds located to the solver's tolerance)."""
    in_pressure = analyse(parse_scene(charged_scene(3.0)), pear=False).primary
    (maximum,) = folds(in_pressure)
    in_voltage = analyse(voltage_scene(3.0, pressure=float(maximum.X[-1])), pear=False).primary
    (pull_in,) = folds(in_voltage)
    assert abs(pull_in.X[-1] - 0.3) <= 1e-8, pull_in.X[-1]


def test_capsule_voltage_continuation_from_a_uz_is_the_run_s_branch(tmp_path):
    """Length 3: ``continue FILE LABEL --parameter voltage`` from the UZ at P = 0.5 of the branch traced in P at
    Φ̄ = 0.3 gives the branch in Φ̄ at P = 0.5 through that point; its pull-in is the one ``run`` finds from its own
    start at P = 0.5 (1e-8)."""
    scene = tmp_path / "charged.toml"
    scene.write_text(charged_scene(3.0, events=f'[[events]]\nquantity = "pressure"\nvalue = {PRESSURE}\n'))
    run, again = tmp_path / "charged.h5", tmp_path / "voltage.h5"
    assert main(["run", str(scene), "-o", str(run), "--quiet", "--primary-only"]) in (0, 1)
    label = next(s["label"] for s in read_run(run)["branches"]["primary"]["special_points"] if s["kind"] == "UZ")
    assert main(["continue", str(run), str(label), "--parameter", "voltage", "-o", str(again), "--quiet"]) == 0
    restarted = read_run(again)["branches"]["primary"]
    (pull_in,) = [s for s in restarted["special_points"] if s["kind"] == "LP"]
    (expected,) = folds(analyse(voltage_scene(3.0), pear=False).primary)
    assert abs(pull_in["voltage"] - expected.X[-1]) <= 1e-8


def test_capsule_voltage_start_refused_above_its_voltage_free_pressure():
    """P above the capsule's voltage-free pressure at the start stretch (a voltage lowers it): no voltage holds it
    there, refused before any continuation (one line)."""
    with pytest.raises(ContinuationError, match=r"pressure = 1.9: no voltage holds the capsule there \(its voltage-free "
                                                r"pressure there is 1\.\d+, and a voltage moves it by dP/dΦ̄² = -") as e:
        analyse(voltage_scene(3.0, pressure=1.9), pear=False)
    assert "\n" not in str(e.value)
