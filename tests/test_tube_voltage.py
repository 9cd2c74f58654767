"""A tube continued in the voltage Φ̄ at a fixed pressure (tube/voltage.py) against the uniform closed tube under the
effective energy derived here (MODEL.md §2, units μ/2)

    Φ_eff(λ1 = λz, λ2 = λθ) = Φ − Φ̄² λz² λθ²:   P = ∂Φ_eff/∂λθ/(λθλz),   N = ∂Φ_eff/∂λz − λθ ∂Φ_eff/∂λθ/(2λz) = 0,

(tests/test_tube_electric.py's balances): at fixed P = P0 the uniform states form a curve in (λθ, λz, Φ̄), and its
fold in Φ̄ (the pull-in voltage) is where ∂(P, N)/∂(λθ, λz) is singular: P = P0, N = 0, det = 0, solved by nsolve
at 30 digits. Every stored point is also checked against model/tube.closed_end_state of model/membrane.Charged."""
import numpy as np
import pytest
import sympy as sp

import balloon_cg
from balloon_cg.analysis.branches.tracer import ContinuationError
from balloon_cg.analysis.results import Kind, StopCode
from balloon_cg.app.cli import main
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.io.tube_file import discretisation, read_tube_run
from balloon_cg.model.membrane import Charged
from balloon_cg.model.tube import closed_end_state
from balloon_cg.scene import SceneError
from balloon_cg.tube.accuracy import accuracy
from balloon_cg.tube.voltage import voltage_branch
from test_interval import tube_scene
from test_tube import bulge_determinant, symbolic_energy, theta, z

PHI = sp.Symbol("Phi", positive=True)
CASES = {"neo-Hookean": 0.8, "SPOM1": 1.2}  # P0, below each tube's pressure maximum (1.4997, 1.4905)


def voltage_scene(preset, pressure, extra="", m_max=0):
    """A closed tube of length 10 (sliding ends) continued in Φ̄ at ``pressure``, m ≥ 1 not read."""
    return tube_scene(preset, 10.0, "[solver]\ndegree = 16\n[electric]\n[continuation]\nparameter = \"voltage\"\n"
                                    f"pressure = {pressure}\nstop_stretch = 4\nstep_max = 0.5\n[stability]\n"
                                    f"m_max = {m_max}\n" + extra)


def balances(preset, pressure):
    """(P − P0, N, det ∂(P, N)/∂(λθ, λz)) of the module docstring as SymPy expressions in (λθ, λz, Φ̄)."""
    energy = symbolic_energy(tube_scene(preset).material) - PHI**2 * theta**2 * z**2
    P = sp.diff(energy, theta) / (theta * z)
    N = sp.diff(energy, z) - theta * sp.diff(energy, theta) / (2 * z)
    det = sp.Matrix([P, N]).jacobian([theta, z]).det()
    return P - sp.Rational(repr(pressure)), N, det


@pytest.fixture(scope="module", params=list(CASES))
def traced(request):
    preset = request.param
    return preset, CASES[preset], voltage_branch(voltage_scene(preset, CASES[preset]))


def test_pull_in_voltage_is_the_fold_of_the_uniform_closed_tube(traced):
    """The branch's one LP in Φ̄ is the pull-in: Φ̄ within 1e-12 of the fold solved here, λθ and λz within 1e-10
    (measured: 1.3e-15 and 8.9e-16 for SPOM1, neo-Hookean's to rounding), and P stays P0."""
    preset, pressure, branch = traced
    folds = [s for s in branch.special if s.kind == Kind.LP]
    assert len(folds) == 1 and folds[0].status == "located"
    fold = folds[0]
    axial = fold.u[branch.disc.axial_index]
    root = sp.nsolve(balances(preset, pressure), [theta, z, PHI], [fold.u[0], axial, fold.voltage], prec=30)
    hoop_exact, axial_exact, voltage_exact = (float(v) for v in root)
    assert abs(fold.voltage - voltage_exact) <= 1e-12
    assert abs(fold.u[0] - hoop_exact) <= 1e-10 and abs(axial - axial_exact) <= 1e-10
    assert fold.pressure == pressure and np.all(branch.pressure == pressure)
    assert branch.voltage.max() <= voltage_exact + 1e-10


def test_first_odd_branch_point_is_the_bulge_onset_in_the_voltage(traced):
    """The first odd branch point (the onset of the bulge cos(πS/L) in Φ̄ at P0) solves P = P0, N = 0 and the
    dispersion relation of tests/test_tube.py (bulge_determinant of Φ_eff at k = π/L = 0), at 30 digits: Φ̄, λθ and
    λz within 1e-10; past the pull-in on this finite tube (Φ̄ below its LP's, later along the branch)."""
    preset, pressure, branch = traced
    fold = next(s for s in branch.special if s.kind == Kind.LP)
    onset = next(s for s in branch.special if s.kind == Kind.BP and s.block == "odd")
    P, N, _ = balances(preset, pressure)
    energy = symbolic_energy(tube_scene(preset).material) - PHI**2 * theta**2 * z**2
    det, k = bulge_determinant(energy)
    axial = onset.u[branch.disc.axial_index]
    root = sp.nsolve([P, N, det.subs(k, sp.pi / 10)], [theta, z, PHI], [onset.u[0], axial, onset.voltage], prec=30)
    assert onset.status == "located"
    assert abs(onset.voltage - float(root[2])) <= 1e-10
    assert abs(onset.u[0] - float(root[0])) <= 1e-10 and abs(axial - float(root[1])) <= 1e-10
    assert onset.voltage < fold.voltage and branch.special.index(onset) > branch.special.index(fold)


def test_every_point_is_the_charged_uniform_tube(traced):
    """Each stored point is uniform, with λz and P of model/tube.closed_end_state of Charged(material, Φ̄) at its λθ
    (1e-10); the first one is the voltage-free tube at P0 (Φ̄ = 0)."""
    preset, pressure, branch = traced
    material = tube_scene(preset).material
    disc = branch.disc
    assert branch.voltage[0] == 0.0
    for u, voltage in zip(branch.states, branch.voltage):
        state = closed_end_state(Charged(material, voltage), u[0])
        assert abs(u[disc.axial_index] - state.axial) <= 1e-10
        assert abs(state.pressure - pressure) <= 1e-10
        assert np.abs(np.delete(u, [0, disc.axial_index])).max() <= 1e-10


def test_stability_changes_at_the_pull_in(traced):
    """Under pressure control (Φ̄ and P fixed) the points before the pull-in are stable and those after it are not:
    the even block's lowest eigenvalue changes sign in the LP's interval; the branch ends where Φ̄ falls back to 0 (the
    other voltage-free state at P0) or passes the stop stretch."""
    _, _, branch = traced
    fold = next(s for s in branch.special if s.kind == Kind.LP)
    unstable = branch.unstable["pressure"]
    assert np.all(unstable[: fold.index + 1] == 0) and np.all(unstable[fold.index + 1:] >= 1)
    even = branch.lowest["even"]
    assert even[fold.index] > 0 > even[fold.index + 1]
    assert branch.stop.code in (StopCode.ZERO_VOLTAGE, "hoop_stretch")


def test_run_writes_the_voltage_branch_and_inspect_shows_it(tmp_path, capsys):
    """``run`` on a tube's voltage continuation writes Φ̄ per point and at the LP; ``inspect`` names the continuation
    and the LP's Φ̄, ``load`` gives it in its tables; stop_voltage ends the branch before the pull-in."""
    scene = tmp_path / "v.toml"
    scene.write_text(voltage_scene("neo-Hookean", 0.8).to_toml())
    out = tmp_path / "v.h5"
    assert main(["run", str(scene), "-o", str(out), "--quiet"]) == 0
    primary = read_tube_run(out)["branches"]["primary"]
    lp = [s for s in primary["special_points"] if s["kind"] == "LP"]
    assert len(lp) == 1 and lp[0]["voltage"] == pytest.approx(primary["voltage"].max(), abs=1e-3)
    capsys.readouterr()
    assert main(["inspect", str(out)]) == 0
    shown = capsys.readouterr().out
    assert "continued in Φ̄ at P = 0.8" in shown and f"Φ̄ = {lp[0]['voltage']:.10g}" in shown
    loaded = balloon_cg.load(out)
    special = loaded.to_dataframe("special")
    assert list(special["voltage"]) == [s["voltage"] for s in primary["special_points"]]
    assert list(special.loc[special["kind"] == "LP", "voltage"]) == [lp[0]["voltage"]]
    assert np.array_equal(loaded.to_xarray("primary")["voltage"].values, primary["voltage"])
    short = voltage_branch(voltage_scene("neo-Hookean", 0.8).with_overrides({"continuation.stop_voltage": 0.3}))
    assert short.stop.code == StopCode.STOP_VOLTAGE and short.voltage.max() <= 0.3 and not short.special


@pytest.mark.parametrize("m_max, extra, message", [
    (1, "", "stability.m_max = 1: a tube's voltage continuation"),
    (0, '[[events]]\nquantity = "volume"\nvalue = 40\n', "events: 1 [[events]]: a tube's voltage continuation"),
    (0, "[dynamics]\nfrequencies = true\n", "dynamics.frequencies = true: a tube's voltage continuation"),
])
def test_what_a_voltage_continuation_does_not_read_is_refused(m_max, extra, message):
    """The m ≥ 1 blocks (stability.m_max defaults to 1: it must be set to 0), events and frequencies: one line each."""
    with pytest.raises(SceneError, match=message.replace("[", r"\[")) as error:
        voltage_scene("SPOM1", 1.0, extra, m_max)
    assert "\n" not in str(error.value)


def test_a_pressure_beyond_the_maximum_has_no_start():
    """P0 = 1.6 above the neo-Hookean tube's pressure maximum 1.4997: no voltage-free state to start from, one line."""
    with pytest.raises(ContinuationError, match="could not inflate the tube to continuation.pressure = 1.6"):
        voltage_branch(voltage_scene("neo-Hookean", 1.6))


def test_continue_in_the_voltage_from_an_event_label(tmp_path, capsys):
    """A SPOM1 tube continued in P under Φ̄0 = 0.1 with an event at P = 1 (label 0, UZ): ``continue --parameter
    voltage`` from it traces the tube in Φ̄ at P = 1 from Φ̄0; its LP is the pull-in at P = 1 solved here (1e-12)
    and that of the scene continued in the voltage from Φ̄ = 0 at P = 1 (another start: 1e-12); ``--direction -1``
    goes down to Φ̄ = 0 (ZERO_VOLTAGE), every point at P = 1."""
    scene = tmp_path / "p.toml"
    scene.write_text(tube_scene("SPOM1", 10.0, "[solver]\ndegree = 16\n[electric]\nvoltage = 0.1\n[continuation]\n"
                                               "stop_stretch = 2\nstep_max = 0.5\n[stability]\nm_max = 0\n"
                                               '[[events]]\nquantity = "pressure"\nvalue = 1.0\n').to_toml())
    run = tmp_path / "p.h5"
    assert main(["run", str(scene), "-o", str(run), "--quiet", "--primary-only"]) == 0
    up, down = tmp_path / "up.h5", tmp_path / "down.h5"
    assert main(["continue", str(run), "0", "--parameter", "voltage", "-o", str(up), "--set",
                 "continuation.stop_stretch=4"]) == 0
    assert "voltage continuation from label 0 at P = 1" in capsys.readouterr().out
    branch = read_tube_run(up)["branches"]["primary"]
    assert branch["voltage"][0] == pytest.approx(0.1, abs=1e-15) and np.all(branch["pressure"] == 1.0)
    lp = [s for s in branch["special_points"] if s["kind"] == "LP"]
    assert len(lp) == 1
    charged = voltage_branch(voltage_scene("SPOM1", 1.0))
    fold = next(s for s in charged.special if s.kind == Kind.LP)
    root = sp.nsolve(balances("SPOM1", 1.0), [theta, z, PHI],
                     [fold.u[0], fold.u[charged.disc.axial_index], fold.voltage], prec=30)
    assert abs(lp[0]["voltage"] - float(root[2])) <= 1e-12 and abs(lp[0]["voltage"] - fold.voltage) <= 1e-12
    assert main(["continue", str(run), "0", "--parameter", "voltage", "--direction", "-1", "-o", str(down)]) == 0
    falling = read_tube_run(down)["branches"]["primary"]
    assert falling["attrs"]["stop_code"] == "zero_voltage" and falling["voltage"].max() == pytest.approx(0.1)
    assert np.all(np.diff(falling["voltage"]) < 0)


def test_continue_in_the_voltage_refuses_in_one_line(tmp_path, capsys):
    """From a label that is no UZ of the primary branch, or a scene without [electric]: exit 2, one line, no file;
    from a UZ without --parameter the line says how."""
    for electric, argv, message in (
            ("[electric]\nvoltage = 0.1\n", ["1", "--parameter", "voltage"], "label 1: LP on branch primary; a tube "
             "continues in the voltage from a user point (UZ) of its primary branch: labels 0"),
            ("", ["0", "--parameter", "voltage"], "--parameter voltage needs an [electric] table"),
            ("", ["0"], "label 0: UZ on branch primary; a tube continues from a branch point of its primary branch "
             "(odd: the onset of bulging; even: on its uniform branch): labels 2, 3 (from a UZ: --parameter voltage, "
             "in Φ̄ at its P)")):
        scene = tmp_path / "p.toml"
        scene.write_text(tube_scene("SPOM1", 10.0, f"[solver]\ndegree = 16\n{electric}[continuation]\n"
                                    "stop_stretch = 1.8\n[stability]\nm_max = 0\n"
                                    '[[events]]\nquantity = "pressure"\nvalue = 1.0\n').to_toml())
        run = tmp_path / "p.h5"
        assert main(["run", str(scene), "-o", str(run), "--quiet", "--primary-only", "--force"]) == 0
        capsys.readouterr()
        assert main(["continue", str(run), *argv, "-o", str(tmp_path / "v.h5")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and message in err[0], err
        assert not (tmp_path / "v.h5").exists()


@pytest.mark.parametrize("command", [["critical", "--parameter", "voltage", "-o", "o.h5"],
                                     ["solve", "--hoop-stretch", "2"],
                                     ["sweep", "--vary", "geometry.length=8,10", "-o", "o.h5"]])
def test_commands_on_a_pressure_continuation_refuse_a_voltage_one(tmp_path, capsys, monkeypatch, command):
    """critical (the onset on a pressure continuation), solve (a state at a hoop stretch on it) and sweep (its table
    reads a pressure continuation's points) on a tube's voltage continuation: exit 2, one line, no file."""
    monkeypatch.chdir(tmp_path)
    scene = tmp_path / "v.toml"
    scene.write_text(voltage_scene("neo-Hookean", 0.8).to_toml())
    assert main([command[0], str(scene), *command[1:]]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'continues in the voltage (continuation.parameter = "voltage")' in err[0], err
    assert sorted(path.name for path in tmp_path.iterdir()) == ["v.toml"]


def test_plugged_tube_keeps_the_first_integral_of_its_charged_energy(tmp_path):
    """A plugged SPOM1 tube (not uniform: the plugs hold ρ = 1) continued in Φ̄ at P = 1 through its pull-in (20
    points, degree 30): the first integral H = λ1Φ_1 − Φ of the effective energy at each point's Φ̄ is constant along
    the tube to its discretisation (the file's first_integral_spread ≤ 1e-3; measured 1.1e-4), and with the
    voltage-free Φ it is not (> 1e-2 past Φ̄ = 0.2): each state is an equilibrium of its own voltage."""
    scene = tmp_path / "plugged.toml"
    scene.write_text(tube_scene("SPOM1", 10.0, 'ends = "plugged"\n[solver]\ndegree = 30\n[electric]\n[continuation]\n'
                                "parameter = \"voltage\"\npressure = 1.0\nmax_points = 20\nstep_max = 0.5\n"
                                "[stability]\nm_max = 0\n").to_toml())
    out = tmp_path / "plugged.h5"
    assert main(["run", str(scene), "-o", str(out), "--quiet"]) == 0
    primary = read_tube_run(out)["branches"]["primary"]
    assert [s["kind"] for s in primary["special_points"]][0] == "LP"
    assert primary["first_integral_spread"].max() <= 1e-3
    plugged = tube_scene("SPOM1", 10.0, 'ends = "plugged"\n[electric]\n')
    eq = Equilibrium(plugged, discretisation(read_tube_run(out)["attrs"]))
    voltage_free = accuracy(eq, primary["unknowns"])[1]
    assert voltage_free[primary["voltage"] > 0.2].min() > 1e-2


def test_a_label_of_a_branch_continued_in_the_voltage_is_refused_away_from_the_scenes(tmp_path, capsys):
    """A branch continued in Φ̄ (``continue --parameter voltage``) has its labels at other voltages than the file's
    scene: the bulge branch from one of its odd branch points was traced at the scene's Φ̄ (P jumped 1 → 1.236 in its
    first step, exit 0): refused, one line naming both voltages, no file."""
    scene = tmp_path / "p.toml"
    scene.write_text(tube_scene("SPOM1", 10.0, "[solver]\ndegree = 16\n[electric]\nvoltage = 0.1\n[continuation]\n"
                                               "stop_stretch = 2\nstep_max = 0.5\n[stability]\nm_max = 0\n"
                                               '[[events]]\nquantity = "pressure"\nvalue = 1.0\n').to_toml())
    run, up = tmp_path / "p.h5", tmp_path / "up.h5"
    assert main(["run", str(scene), "-o", str(run), "--quiet", "--primary-only"]) == 0
    assert main(["continue", str(run), "0", "--parameter", "voltage", "-o", str(up), "--quiet", "--set",
                 "continuation.stop_stretch=4"]) == 0
    labels = read_tube_run(up)["branches"]["primary"]["special_points"]
    odd = next(i for i, s in enumerate(labels) if s["kind"] == "BP" and s["block"] == "odd")
    capsys.readouterr()
    assert main(["continue", str(up), str(odd), "-o", str(tmp_path / "b.h5")]) == 2
    err = capsys.readouterr().err
    assert (f"label {odd}: its branch was continued in voltage, this point at Φ̄ = {labels[odd]['voltage']:.10g}, "
            "the file's scene at Φ̄ = 0.1" in err and err.count("\n") == 1 and not (tmp_path / "b.h5").exists())
