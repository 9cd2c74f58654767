"""Voltage continuations (Φ̄ at fixed P) get the whole picture: branch points, pear branches, plots.

The neo-Hookean sphere under a voltage (tests/test_dielectric.py's module docstring; every closed form written out
here or there, independently of model/sphere.py): P = 4(λ⁻¹ − λ⁻⁷) − 4Φ̄²λ, so at fixed P the sphere's voltage is
Φ̄² = λ⁻² − λ⁻⁸ − P/(4λ). Its pear (n = 1) condition d(λP)/dλ = 0 at fixed Φ̄ is 24λ⁻⁷ = 8Φ̄²λ, i.e. Φ̄² = 3λ⁻⁸;
on the branch of fixed P that gives 4λ⁻¹ − 16λ⁻⁷ = P (at P = 0: λ⁶ = 4, the pull-in stretch 2^(1/3) itself, so
the tests take P = 0.5, where the pear point lies past the fold). The n = 2, 3 points are the zeros of the
sphere's conditions Δ_n (``sphere_mode_condition``) along the same branch.
"""
from dataclasses import replace

import numpy as np
import pytest
from matplotlib.figure import Figure
from scipy.optimize import brentq

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Block, Classification, Status
from balloon_cg.analysis.switching.pear import trace_pear
from balloon_cg.app.api import Result, plot as api_plot
from balloon_cg.app.cli import main
from balloon_cg.app.summaries import format_run
from balloon_cg.io.run_file import read_run
from balloon_cg.model.shooting import shoot_general
from balloon_cg.post.labels import GID
from balloon_cg.post.plotting import PlotError, applicable_kinds, load_branches, plot
from balloon_cg.scene import parse_scene
from test_dielectric import NEO, sphere_mode_condition

PRESSURE = 0.5
VOLTAGE_SCENE = (NEO + f'[electric]\n[continuation]\nparameter = "voltage"\npressure = {PRESSURE}\n'
                 "start_stretch = 1.1\nstop_stretch = 1.45\n")


def sphere_voltage(lam, P=PRESSURE):
    """Φ̄ of the neo-Hookean sphere of stretch λ at pressure P (module docstring)."""
    return np.sqrt(lam**-2 - lam**-8 - P / (4 * lam))


def pear_stretch(P):
    """The root of 4λ⁻¹ − 16λ⁻⁷ = P past the pull-in stretch (module docstring)."""
    return brentq(lambda lam: 4 / lam - 16 / lam**7 - P, 1.2, 1.7, xtol=1e-15)


TWO_COILS = ("[field]\nM = 0.003\n[[field.coils]]\nradius = 1.7321\nheight = 1.0\ncurrent = 1.0\n"
             "[[field.coils]]\nradius = 1.7321\nheight = -1.0\ncurrent = -1.0\n")  # the paper's opposed coils


def fixed_voltage_scene(voltage, name="fixed", field=""):
    return parse_scene(NEO + f"[electric]\nvoltage = {voltage!r}\n[continuation]\nstart_stretch = 1.2\n"
                       "stop_stretch = 1.45\n" + field, name=name)


def stretch(branch, X) -> float:
    return float(branch.pole_values(X)["lam2_top"][0])


@pytest.fixture(scope="module")
def voltage_picture():
    return analyse(parse_scene(VOLTAGE_SCENE, name="voltage_run"), pear=False)


@pytest.fixture(scope="module")
def voltage_file(voltage_picture, tmp_path_factory):
    p = voltage_picture
    path = tmp_path_factory.mktemp("voltage") / "voltage_run.h5"
    Result.of(p.primary.scene, p.branches, p.snaps, p.incomplete, p).save(path)
    return path


def test_the_pear_formula_meets_the_pull_in_at_zero_pressure():
    """At P = 0 the pear point is the pull-in, where the tension vanishes and every mode n crosses at once."""
    pull_in = 2 ** (1 / 3)
    assert pear_stretch(0.0) == pytest.approx(pull_in, abs=1e-12)
    for n in range(1, 6):
        assert sphere_mode_condition(pull_in, sphere_voltage(pull_in, 0.0), n) == pytest.approx(0.0, abs=1e-12)
    lam = pear_stretch(PRESSURE)
    assert sphere_mode_condition(lam, sphere_voltage(lam), 1) == pytest.approx(0.0, abs=1e-12)


def test_branch_points_of_a_voltage_continuation_are_the_sphere_modes(voltage_picture):
    """n = 1 (pear, odd block), n = 2 (even) and n = 3 (odd) located at the sphere's λ and Φ̄ to 1e-9."""
    branch = voltage_picture.primary
    assert not voltage_picture.not_searched and branch.parameter == "voltage"
    expected = [(Block.ODD_HELD, pear_stretch(PRESSURE)),
                (Block.EVEN, brentq(lambda lam: sphere_mode_condition(lam, sphere_voltage(lam), 2), 1.31, 1.37)),
                (Block.ODD_HELD, brentq(lambda lam: sphere_mode_condition(lam, sphere_voltage(lam), 3), 1.37, 1.44))]
    found = voltage_picture.branch_points
    assert [bp.block for bp in found] == [block for block, _ in expected]
    for bp, (_, lam) in zip(found, expected):
        assert bp.status == Status.LOCATED
        assert abs(stretch(branch, bp.X) - lam) < 1e-9
        assert abs(bp.X[-1] - sphere_voltage(lam)) < 1e-9
    pear = found[0]
    assert abs(pear.X[-1] ** 2 - 3 * pear_stretch(PRESSURE) ** -8) < 1e-9
    assert [bp.classification for bp in found] == [Classification.PITCHFORK_SUPER, Classification.TRANSCRITICAL,
                                                  Classification.PITCHFORK_SUB]


@pytest.mark.parametrize("field", ["", TWO_COILS], ids=["no field", "two coils"])
def test_the_pear_point_is_the_same_from_a_pressure_continuation(voltage_picture, field):
    """Continuing P at the located Φ̄* finds the branch point at P = 0.5 and the same stretch, with the same
    reduced energy (the energy at fixed P and Φ̄ does not know which parameter was continued); also between the
    paper's two coils (no closed form there)."""
    if field:
        voltage_picture = analyse(parse_scene(VOLTAGE_SCENE + field, name="voltage_coils"), pear=False)
    from_voltage = voltage_picture.branch_points[0]
    assert from_voltage.block == Block.ODD_HELD and from_voltage.status == Status.LOCATED
    moved = abs(stretch(voltage_picture.primary, from_voltage.X) - pear_stretch(PRESSURE))
    assert (moved > 1e-3) if field else (moved < 1e-9)  # the field moves the pear point off the sphere's
    picture = analyse(fixed_voltage_scene(float(from_voltage.X[-1]), field=field), pear=False)
    from_pressure = picture.primary.branch_points(Block.ODD_HELD)[0]
    assert from_pressure.status == Status.LOCATED
    assert abs(from_pressure.X[-1] - PRESSURE) < 1e-9
    assert abs(stretch(picture.primary, from_pressure.X) - stretch(voltage_picture.primary, from_voltage.X)) < 1e-9
    assert from_pressure.classification == from_voltage.classification
    assert from_pressure.E[2] == pytest.approx(from_voltage.E[2], rel=1e-5)


def test_the_pear_branch_is_traced_in_the_voltage_at_fixed_pressure(voltage_picture):
    """The branch leaving the pear point keeps P = 0.5, breaks the equator symmetry, and its points are
    equilibria of the independent shooting method at their own Φ̄ (P and λ2(π) to 1e-8)."""
    primary = voltage_picture.primary
    short = replace(primary, scene=primary.scene.with_overrides({"continuation.max_points": 6}))
    pear = trace_pear(short, voltage_picture.branch_points[0], 1.0, "pear_0")
    assert pear.parameter == "voltage" and np.all(pear.pressure == PRESSURE)
    poles = pear.pole_values()
    asymmetry = poles["lam2_top"] - poles["lam2_bottom"]
    assert abs(pear.X[0, -1] - voltage_picture.branch_points[0].X[-1]) < 1e-4 and abs(asymmetry[-1]) > 0.01
    k = len(pear.X) - 1
    shot = shoot_general(fixed_voltage_scene(float(pear.X[k, -1]), "shot"), poles["lam2_top"][k], PRESSURE,
                         poles["eta_top"][k], poles["lam2_bottom"][k], poles["eta_bottom"][k])
    assert shot.converged
    assert abs(shot.P - PRESSURE) < 1e-8 and abs(shot.lam2_bottom - poles["lam2_bottom"][k]) < 1e-8


def curve_pieces(ax) -> list:
    """The branch curves drawn in ``ax`` (not the special-point labels' leader lines)."""
    return [line for line in ax.get_lines() if len(line.get_xdata()) > 1 and line.get_gid() != GID]


def test_voltage_pole_draws_the_stored_voltage_and_stability(voltage_file):
    """On an Axes: the curve pieces are the file's (λ2(0), Φ̄), solid exactly on the stable points, and the
    markers sit at the special points' stored (λ2(0), Φ̄)."""
    data = read_run(voltage_file)["branches"]["primary"]
    ax = Figure().add_subplot()
    assert plot(voltage_file, "voltage-pole", axes=ax) is ax.figure
    assert ax.get_ylabel().startswith("voltage")
    pieces = curve_pieces(ax)
    x = np.concatenate([pieces[0].get_xdata()] + [line.get_xdata()[1:] for line in pieces[1:]])
    y = np.concatenate([pieces[0].get_ydata()] + [line.get_ydata()[1:] for line in pieces[1:]])
    np.testing.assert_array_equal(x, data["lam2_top"])
    np.testing.assert_array_equal(y, data["voltage"])
    stable = data["stability"]["stable_pressure"]
    assert stable.any() and not stable.all()
    for line in pieces:
        first = int(np.flatnonzero(data["lam2_top"] == line.get_xdata()[0])[0])
        assert line.get_linestyle() == ("-" if stable[first] else "--")
    markers = [(line.get_xdata()[0], line.get_ydata()[0]) for line in ax.get_lines() if len(line.get_xdata()) == 1]
    assert markers == [(s["lam2_top"], s["voltage"]) for s in data["special_points"]]
    kinds = {t.get_text().partition(" ")[2] for t in ax.texts}  # "2 LP": the label, then what it is
    assert {"LP", "pitchfork-super", "transcritical", "pitchfork-sub"} <= kinds
    assert "voltage control at fixed P" in ax.get_legend().get_title().get_text()
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [f"M = 0, P = {PRESSURE:g}"]


def test_voltage_equator_and_energy_name_the_voltage(voltage_file):
    data = read_run(voltage_file)["branches"]["primary"]
    axes = Figure().subplots(1, 2)
    plot(voltage_file, "voltage-equator", axes=axes)
    for ax, key in zip(axes, ("lam2_equator", "lam1_equator")):
        pieces = curve_pieces(ax)
        np.testing.assert_array_equal(np.concatenate([pieces[0].get_ydata()] + [p.get_ydata()[1:] for p in pieces[1:]]),
                                      data["voltage"])
        np.testing.assert_array_equal(np.concatenate([pieces[0].get_xdata()] + [p.get_xdata()[1:] for p in pieces[1:]]),
                                      data[key])
    ax = Figure().add_subplot()
    plot(voltage_file, "energy", axes=ax)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    bps = [s for s in data["special_points"] if s["kind"] == "BP"]
    assert len(labels) == len(bps) == 3
    assert all(f"at $\\bar\\Phi$ = {s['voltage']:.6g}" in label for s, label in zip(bps, labels))


def test_per_point_labels_give_the_voltage(voltage_file):
    data = read_run(voltage_file)["branches"]["primary"]
    fig = plot(voltage_file, "shapes", points=[0, -1])
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    for index in (0, len(data["voltage"]) - 1):
        assert any(text.startswith(f"#{index}  $\\bar\\Phi$ = {data['voltage'][index]:.4g},") for text in texts)


def test_the_constant_ordinate_is_refused_in_one_line(voltage_file, tmp_path, capsys):
    with pytest.raises(PlotError, match="continued in voltage .P = 0.5.: pressure-pole .*; draw voltage-pole$"):
        plot(voltage_file, "pressure-pole")
    pressure_run = tmp_path / "fixed.h5"
    scene = fixed_voltage_scene(0.3).with_overrides({"continuation.stop_stretch": 1.3})
    picture = analyse(scene, pear=False)
    Result.of(scene, picture.branches, picture.snaps, picture.incomplete, picture).save(pressure_run)
    with pytest.raises(PlotError, match="continued in pressure .*= 0.3.: voltage-equator .*; draw pressure-equator$"):
        plot(pressure_run, "voltage-equator")
    assert main(["plot", str(voltage_file), "--what", "pressure-equator", "-o", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "draw voltage-equator" in err
    assert applicable_kinds(load_branches(voltage_file)) == ["voltage-pole", "voltage-equator", "shapes", "stresses",
                                                             "curvature", "energy"]
    assert "pressure-pole" in applicable_kinds(load_branches(pressure_run))
    assert "voltage-pole" not in applicable_kinds(load_branches(pressure_run))


def test_inspect_names_the_voltage_of_a_snap_through(voltage_file):
    run = read_run(voltage_file)
    assert run["snap_throughs"]  # the pull-in: the stable stretch ends at the fold in Φ̄
    assert "snap-through at voltage = " in format_run(run) and "snap-through at P" not in format_run(run)


def test_critical_refuses_a_voltage_continuation(tmp_path, capsys):
    """The curve of pitchforks lives in (q, P): a voltage branch's Φ̄ must not be read as P."""
    scene = tmp_path / "voltage.toml"
    scene.write_text(VOLTAGE_SCENE, encoding="utf-8")
    assert main(["critical", str(scene), "--parameter", "material.mu[0]", "-o", str(tmp_path / "c.h5")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "continuation.parameter = 'voltage'" in err
    assert not (tmp_path / "c.h5").exists()


def test_two_parameter_curves_refuse_a_voltage_branch(voltage_picture):
    from balloon_cg.analysis.critical.pitchfork_curve import TwoParameterError, continue_branch_point
    with pytest.raises(TwoParameterError, match="continued in voltage, not in P"):
        continue_branch_point(voltage_picture.primary, voltage_picture.branch_points[0], "material.mu[0]")


def test_a_sweep_of_voltage_runs_stores_the_pear_voltages_and_has_no_pressure_phase_diagram(tmp_path, capsys):
    from balloon_cg.io.sweep_file import read_sweep
    scene = tmp_path / "voltage.toml"
    scene.write_text(VOLTAGE_SCENE.replace("stop_stretch = 1.45", "stop_stretch = 1.32"), encoding="utf-8")
    sweep = tmp_path / "sweep.h5"
    assert main(["sweep", str(scene), "--vary", "continuation.pressure=0.5,0.6", "-o", str(sweep), "--no-pear",
                 "--workers", "1"]) == 0
    summary = capsys.readouterr().out
    for member in read_sweep(sweep)["members"].values():
        P = member["overrides"]["continuation.pressure"]
        assert list(member["attrs"]["branch_point_pressures"]) == [P]
        voltage = member["attrs"]["branch_point_voltages"][0]
        assert abs(voltage - sphere_voltage(pear_stretch(P), P)) < 1e-9 and f"{voltage:.6g}" in summary
    with pytest.raises(PlotError, match="member 0 is continued in voltage: phase draws the pitchfork pressures"):
        plot(sweep, "phase")


@pytest.mark.parametrize("control, parameter, symbol", [("pressure", "P", "P"), ("volume", "P", "V"), ("gas", "P", "n"),
                                                        ("pressure", "voltage", "voltage")])
def test_a_snap_through_value_is_named_by_what_it_is(control, parameter, symbol):
    from balloon_cg.app.summaries import _snap_symbol
    run = {"attrs": {"control": control}, "branches": {"primary": {"attrs": {"parameter": parameter}}}}
    assert _snap_symbol(run, "primary") == symbol


def test_the_default_kind_is_the_pole_curve_of_the_runs_own_parameter(voltage_file, tmp_path):
    """plot(source) with no kind: voltage-pole for a voltage run, pressure-pole for a pressure run."""
    from balloon_cg.analysis.branches.primary import trace_primary
    from balloon_cg.io.run_file import write_run

    ax = Figure().add_subplot()
    api_plot(voltage_file, ax=ax)
    assert ax.get_ylabel() == plot(voltage_file, "voltage-pole").axes[0].get_ylabel()
    scene = fixed_voltage_scene(0.3).with_overrides({"continuation.parameter": "pressure",
                                                     "continuation.stop_stretch": 1.3})
    pressure_file = tmp_path / "pressure.h5"
    write_run(pressure_file, scene, [trace_primary(scene)])
    ax = Figure().add_subplot()
    api_plot(pressure_file, ax=ax)
    assert ax.get_ylabel() == plot(pressure_file, "pressure-pole").axes[0].get_ylabel() != ""
