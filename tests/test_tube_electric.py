"""A tube under a voltage across its wall ([electric] on a tube, docs/tubes.md): the dielectric term on the tube's
kernels, the charged tube's start at P = 0, its uniform closed path and its onset of bulging, against closed forms
derived here from the effective energy (MODEL.md §2, units μ/2)

    Φ_eff(λ1, λ2) = Φ(λ1, λ2) − Φ̄² λ1² λ2².

Per 2π the tube's energy is E = ∫_0^L [Φ_eff(λ1, λ2) + ½ P ρ² η'] dS (tests/test_interval.py's with Φ_eff for Φ), and
the uniform closed tube's balances are those of tests/test_tube.py with Φ_eff: P = ∂Φ_eff/∂λθ/(λθλz),
N = ∂Φ_eff/∂λz − λθ ∂Φ_eff/∂λθ/(2λz) = 0.
"""
import json
import re

import mpmath
import numpy as np
import pytest
import sympy as sp

from balloon_cg.analysis.branches.tracer import ContinuationError
from balloon_cg.app.cli import main
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.galerkin.interval import IntervalDiscretisation, Mirror
from balloon_cg.io.tube_file import read_tube_run
from balloon_cg.model import tube
from balloon_cg.model.membrane import Charged, stretch_derivatives
from balloon_cg.tube.primary import primary_branch
from balloon_cg.analysis.results import IntervalStop
from test_interval import ogden, series, tube_scene
from test_tube import closed_end_path, dispersion_onset, symbolic_energy, theta, z

VOLTAGE = 0.1


def charged_scene(preset="SPOM1", voltage=VOLTAGE, extra="", degree=20, stop=1.75):
    """A closed tube of length 10 (sliding ends unless ``extra`` says otherwise) under ``voltage``."""
    return tube_scene(preset, 10.0, extra + f"[electric]\nvoltage = {voltage}\n").with_overrides(
        {"solver.degree": degree, "continuation.stop_stretch": stop})


def effective_energy(preset, voltage):
    """Φ_eff(λ1 = z, λ2 = θ) of the preset under ``voltage`` (SymPy, exact decimals)."""
    return symbolic_energy(tube_scene(preset).material) - sp.Rational(repr(voltage)) ** 2 * theta**2 * z**2


def energy_written_here(material, disc, u, P, voltage):
    """E/(2π) of the module docstring (Gauss–Legendre at 200 nodes: tests/test_interval.series)."""
    weights, lam1, lam2, slope = series(disc, u)
    return weights @ (ogden(material, lam1, lam2) - voltage**2 * lam1**2 * lam2**2 + 0.5 * P * lam2**2 * slope)


def test_charged_tube_is_stationary_for_the_energy_written_here():
    """The dielectric kernels on the tube: at a random state E/(2π) is the energy written here (1e-13) and R its
    gradient (central differences, 1e-8); a plugged SPOM1 tube under Φ̄ = 0.1 (non-uniform: the plugs hold ρ = 1),
    traced from its charged start to a hoop stretch of 1.4, is stationary along every basis direction for the energy
    written here with −Φ̄²λ1²λ2² (1e-8), and is not without it (> 1e-3)."""
    scene = charged_scene(extra='ends = "plugged"\n', degree=24, stop=1.4)
    disc = IntervalDiscretisation(10, 10.0, quadrature=120, ends=scene.geometry.ends)
    eq = Equilibrium(scene, disc)
    rng = np.random.default_rng(8)
    u = disc.reference() * 1.2 + 0.02 * rng.standard_normal(disc.size) / (1 + np.arange(disc.size) % 11)
    at = Parameters(0.8, voltage=VOLTAGE)
    E = energy_written_here(scene.material, disc, u, 0.8, VOLTAGE)
    assert abs(eq.energy(u, at) - E) <= 1e-13 * abs(E)
    h = 1e-6
    gradient = [(energy_written_here(scene.material, disc, u + h * e, 0.8, VOLTAGE)
                 - energy_written_here(scene.material, disc, u - h * e, 0.8, VOLTAGE)) / (2 * h)
                for e in np.eye(disc.size)]
    R = eq.residual(u, at)
    assert np.abs(R - gradient).max() <= 1e-8 * np.abs(R).max()

    branch = primary_branch(scene)
    assert branch.stop.code == IntervalStop.HOOP_STRETCH and branch.params.voltage == VOLTAGE
    u, P, disc = branch.states[-1], branch.pressure[-1], branch.disc
    rho = disc.profile(u, np.array([0.0, 5.0, 10.0]))[0]
    assert abs(rho[0] - 1) < 1e-12 and abs(rho[2] - 1) < 1e-12 and rho[1] > 1.3

    def energy_gradient(voltage):
        return np.array([energy_written_here(scene.material, disc, u + h * e, P, voltage)
                         - energy_written_here(scene.material, disc, u - h * e, P, voltage)
                         for e in np.eye(disc.size)]) / (2 * h)

    assert np.abs(energy_gradient(VOLTAGE)).max() < 1e-8
    assert np.abs(energy_gradient(0.0)).max() > 1e-3


@pytest.mark.parametrize("preset", ["SPOM1", "neo-Hookean"])
def test_charged_uniform_tube_is_the_closed_end_path(preset):
    """Sliding closed ends under Φ̄ = 0.1: the start at P = 0 is the equibiaxial state λ1 = λ2 = λ with
    ∂Φ_eff/∂λ1(λ, λ) = 0 (no load: the voltage alone thins the wall and widens the tube), solved here at 30 digits
    (1e-12); at every traced point P = ∂Φ_eff/∂λθ/(λθλz) and N = 0 (derived here, 1e-10), the tube uniform
    (1e-10) and model/tube's closed-end state of model/membrane.Charged; the fold in P is the pressure maximum of the
    effective energy, det ∂(P, N)/∂(λθ, λz) = 0 with N = 0 solved here at 30 digits (1e-10), as
    model/tube.pressure_maximum finds it (1e-10)."""
    scene = charged_scene(preset)
    energy = effective_energy(preset, VOLTAGE)
    P, N, axial_of = closed_end_path(energy)
    with mpmath.workdps(30):
        start = float(sp.nsolve(sp.diff(energy, z).subs(theta, z), z, 1.01, prec=30))
    branch = primary_branch(scene)
    k = branch.disc.axial_index
    assert start > 1.001 and branch.pressure[0] == 0.0
    assert abs(branch.states[0][0] - start) <= 1e-12 and abs(branch.states[0][k] - start) <= 1e-12
    P_of, N_of = sp.lambdify((theta, z), P), sp.lambdify((theta, z), N)
    charged = Charged(scene.material, VOLTAGE)
    for u, pressure in zip(branch.states, branch.pressure):
        assert abs(pressure - P_of(u[0], u[k])) <= 1e-10 * (1 + pressure) and abs(N_of(u[0], u[k])) <= 1e-10
        assert np.abs(np.delete(u, [0, k])).max() <= 1e-10
        state = tube.closed_end_state(charged, u[0])
        assert abs(u[k] - state.axial) <= 1e-10 and abs(pressure - state.pressure) <= 1e-10
    det = sp.diff(P, theta) * sp.diff(N, z) - sp.diff(P, z) * sp.diff(N, theta)
    (fold,) = [s for s in branch.special if s.kind == "LP"]
    with mpmath.workdps(30):
        hoop, axial = sp.nsolve((N, det), (theta, z), (1.6, axial_of(1.6)), prec=30)
    assert abs(fold.u[0] - float(hoop)) <= 1e-10 and abs(fold.u[k] - float(axial)) <= 1e-10
    assert abs(fold.pressure - float(P.subs({theta: hoop, z: axial}))) <= 1e-10
    peak = tube.pressure_maximum(charged, largest_hoop=3.0)
    assert abs(peak.hoop - float(hoop)) <= 1e-10 and abs(peak.pressure - fold.pressure) <= 1e-10


def test_charged_tube_with_its_ends_held_apart_is_the_fixed_stretch_path():
    """Sliding ends held at 1.5 L (SPOM1, Φ̄ = 0.1; the tube stretched at P = 0, then charged): the start is
    ∂Φ_eff/∂λθ(1.5, λθ) = 0 solved here at 30 digits (1e-12), and every traced point is uniform at λz = 1.5 with
    P = ∂Φ_eff/∂λθ/(λθλz) derived here (1e-10)."""
    scene = charged_scene(extra="axial_stretch = 1.5\n")
    energy = effective_energy("SPOM1", VOLTAGE).subs(z, sp.Rational(3, 2))
    with mpmath.workdps(30):
        start = float(sp.nsolve(sp.diff(energy, theta), theta, 0.8, prec=30))
    P_of = sp.lambdify(theta, sp.diff(energy, theta) / (theta * sp.Rational(3, 2)))
    branch = primary_branch(scene)
    k = branch.disc.axial_index
    assert abs(branch.states[0][0] - start) <= 1e-12 and branch.pressure[0] == 0.0 and len(branch.pressure) > 10
    for u, pressure in zip(branch.states, branch.pressure):
        assert u[k] == 1.5 and np.abs(np.delete(u, [0, k])).max() <= 1e-10
        assert abs(pressure - P_of(u[0])) <= 1e-10 * (1 + pressure)


@pytest.mark.parametrize("preset", ["SPOM1", "neo-Hookean"])
def test_onset_under_a_voltage_is_the_dispersion_relation(preset):
    """Sliding closed ends, L = 10, Φ̄ = 0.1: the first odd branch point of the primary branch is the onset of the mode
    cos(πS/L) of the dispersion relation with Φ_eff (tests/test_tube.dispersion_onset of the effective energy: N = 0
    and the determinant of the second variation derived there, solved at 30 digits): λθ, λz and P to 1e-8;
    model/tube.bulge_onset of model/membrane.Charged is the same to 1e-10."""
    scene = charged_scene(preset)
    energy = effective_energy(preset, VOLTAGE)
    ((hoop, axial),) = dispersion_onset(energy, (10.0,), largest_hoop=3.0)
    pressure = float((sp.diff(energy, theta) / (theta * z)).subs({theta: hoop, z: axial}))
    branch = primary_branch(scene)
    first, k = branch.branch_points()[0], branch.disc.axial_index
    assert first.block == Mirror.ODD and first.status == "located"
    assert abs(first.u[0] - float(hoop)) <= 1e-8 and abs(first.u[k] - float(axial)) <= 1e-8
    assert abs(first.pressure - pressure) <= 1e-8
    onset = tube.bulge_onset(Charged(scene.material, VOLTAGE), 10.0, largest_hoop=3.0)
    assert abs(onset.hoop - float(hoop)) <= 1e-10 and abs(onset.axial - float(axial)) <= 1e-10
    assert abs(onset.pressure - pressure) <= 1e-10


def test_onset_falls_with_the_voltage_and_recovers_the_field_free_one():
    """SPOM1, L = 10: the first odd branch point under Φ̄ = 0 ([electric] present: the dielectric kernels at zero
    voltage), 1e-3, 1e-2, 0.05, 0.1, 0.2, 0.3 (docs/tubes.md has the table). At Φ̄ = 0 it is the field-free tube's
    (another kernel module, 1e-12); at every voltage model/tube.bulge_onset of Φ_eff (1e-8); the onset pressure
    falls strictly with Φ̄, and as Φ̄ → 0 the gap P(0) − P(Φ̄) is O(Φ̄²): its ratio to Φ̄² at 1e-3 and 1e-2 agrees
    to 1e-3 (the next order, Φ̄⁴)."""
    voltages = (0.0, 1e-3, 1e-2, 0.05, 0.1, 0.2, 0.3)
    free = primary_branch(tube_scene("SPOM1", 10.0).with_overrides(
        {"solver.degree": 20, "continuation.stop_stretch": 1.75})).branch_points()[0]
    onsets = [primary_branch(charged_scene(voltage=v)).branch_points()[0] for v in voltages]
    assert abs(onsets[0].pressure - free.pressure) <= 1e-12 and np.abs(onsets[0].u - free.u).max() <= 1e-12
    material = tube_scene("SPOM1").material
    for voltage, found in zip(voltages, onsets):
        onset = tube.bulge_onset(Charged(material, voltage), 10.0, largest_hoop=3.0)
        assert found.block == Mirror.ODD and abs(found.pressure - onset.pressure) <= 1e-8
        assert abs(found.u[0] - onset.hoop) <= 1e-8
    pressures = np.array([p.pressure for p in onsets])
    assert np.all(np.diff(pressures) < 0)
    ratios = (pressures[0] - pressures[1:3]) / np.array(voltages[1:3]) ** 2
    assert ratios[0] > 0 and abs(ratios[1] / ratios[0] - 1) <= 1e-3


def test_run_on_a_charged_tube_switches_the_bulge_with_the_effective_maxwell_pressure(tmp_path, capsys):
    """`balloon-cg run` on a charged tube (SPOM1, L = 10, Φ̄ = 0.1, degree 20, to a hoop stretch of 3): the bulge
    branch switched at the first odd branch point and traced through its volume fold; Maxwell's pressure is that of
    the effective energy (model/tube.maxwell_pressure of Charged: below the field-free one); the charged start
    carries no stress (the smallest principal stress, elastic plus dielectric, zero to rounding) and every later
    point is taut; `inspect` (text and --json) names the voltage."""
    scene, path = tmp_path / "charged.toml", tmp_path / "charged.h5"
    scene.write_text(charged_scene(stop=3.0).to_toml())
    assert main(["run", str(scene), "-o", str(path), "--quiet"]) == 0
    run = read_tube_run(path)
    primary, bulge = run["branches"]["primary"], run["branches"]["bulge"]
    onset = next(s for s in primary["special_points"] if s["kind"] == "BP")
    assert abs(bulge["pressure"][0] - onset["pressure"]) < 1e-8
    assert [s["kind"] for s in bulge["special_points"]] == ["LV"]
    material = tube_scene("SPOM1").material
    assert run["attrs"]["maxwell_pressure"] == tube.maxwell_pressure(Charged(material, VOLTAGE))[0]
    assert run["attrs"]["maxwell_pressure"] < tube.maxwell_pressure(material)[0]
    stress = primary["smallest_stress"]
    assert abs(stress[0]) < 1e-10 and np.all(stress[1:] > 0)
    capsys.readouterr()
    assert main(["inspect", str(path)]) == 0
    assert "voltage        Φ̄ = 0.1" in capsys.readouterr().out
    assert main(["inspect", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["voltage"] == VOLTAGE


def test_a_charged_path_that_ends_has_no_maxwell_state_and_its_run_completes(tmp_path):
    """The charged neo-Hookean closed tube (Φ̄ = 0.1) loses its closed-end balance at large hoop stretch: N = ∂e/∂λz
    of Φ_eff written here (SymPy) has one sign for every λz at λθ = 14.5, so the path ends before P rises again
    (it falls through 0 near λθ = 10). The scans treat the end as the path's end (closed_end_axial NaN there, its
    λz below it the root of N written here), there is no Maxwell state, and `run` completes (it exited 3 on the
    scans' ValueError)."""
    material = Charged(tube_scene("neo-Hookean").material, VOLTAGE)
    N = sp.lambdify((theta, z), sp.diff(effective_energy("neo-Hookean", VOLTAGE), z)
                    - theta * sp.diff(effective_energy("neo-Hookean", VOLTAGE), theta) / (2 * z))
    axial = tube.closed_end_axial(material, np.array([3.0, 14.5]))
    assert abs(N(3.0, axial[0])) < 1e-10 and np.isnan(axial[1])
    assert np.all(N(14.5, np.geomspace(1e-3, 1e8, 2000)) < 0)
    assert tube.maxwell_pressure(material) is None
    assert tube.pressure_maximum(material) is not None
    scene, path = tmp_path / "nh.toml", tmp_path / "nh.h5"
    scene.write_text(charged_scene("neo-Hookean", stop=2.0).to_toml())
    assert main(["run", str(scene), "-o", str(path), "--quiet"]) == 0
    assert np.isnan(read_tube_run(path)["attrs"]["maxwell_pressure"])  # stored as NaN: none


def test_critical_follows_the_onset_in_the_voltage(tmp_path, capsys):
    """`critical --parameter voltage` on a charged tube (SPOM1, L = 10, Φ̄ = 0.1, degree 20): the onset curve in Φ̄
    (tube/onset.py, ∂R/∂Φ̄ from the tube's generated voltage_gradient) is, at five points along it, the dispersion
    relation of Φ_eff at that Φ̄ (model/tube.bulge_onset of Charged: λθ and P to 1e-8), P falling as Φ̄ rises towards the pull-in
    (no fold: exit 1, the file written); downwards it lands on Φ̄ = 0 at the field-free onset (1e-8); the voltage
    without [electric] exits 2 in one line."""
    scene = tmp_path / "charged.toml"
    scene.write_text(charged_scene().to_toml())
    material = tube_scene("SPOM1").material
    curves = {}
    for direction in ("1", "-1"):
        path = tmp_path / f"onset{direction}.h5"
        assert main(["critical", str(scene), "--parameter", "voltage", "--direction", direction, "-o", str(path),
                     "--quiet"]) == 1
        assert "no critical voltage: the onset curve does not turn back in voltage" in capsys.readouterr().err
        curves[direction] = read_tube_run(path)["onset"]
        assert curves[direction]["attrs"]["parameter"] == "voltage"
    up, down = curves["1"], curves["-1"]
    assert up["q"][0] == VOLTAGE and up["q"][-1] > 0.6 and np.all(np.diff(up["pressure"]) < 0)
    assert down["q"][-1] == 0.0
    for k in np.linspace(0, up["q"].size - 1, 5).astype(int):  # the oracle scans its path: ~1 s a voltage
        onset = tube.bulge_onset(Charged(material, up["q"][k]), 10.0, largest_hoop=3.0)
        assert abs(up["unknowns"][k][0] - onset.hoop) <= 1e-8 and abs(up["pressure"][k] - onset.pressure) <= 1e-8
    free = tube.bulge_onset(material, 10.0, largest_hoop=3.0)
    assert abs(down["pressure"][-1] - free.pressure) <= 1e-8 and abs(down["unknowns"][-1][0] - free.hoop) <= 1e-8
    plain = tmp_path / "plain.toml"
    plain.write_text(tube_scene("SPOM1", 10.0).to_toml())
    assert main(["critical", str(plain), "--parameter", "voltage", "-o", str(tmp_path / "x.h5"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "critical --parameter voltage needs an [electric] table" in err[0]
    assert not (tmp_path / "x.h5").exists()


def test_effective_derivatives_are_those_of_the_energy_written_here():
    """model/membrane.Charged: Φ_eff and its first and second derivatives against SymPy's of the effective energy
    (SPOM1, Φ̄ = 0.3, at three stretch pairs; 1e-12 relative)."""
    energy = effective_energy("SPOM1", 0.3)
    pairs = np.array([[1.1, 1.7], [2.3, 0.9], [1.0, 1.0]])
    found = stretch_derivatives(Charged(tube_scene("SPOM1").material, 0.3), pairs[:, 0], pairs[:, 1])
    names = {"phi": energy, "phi_1": sp.diff(energy, z), "phi_2": sp.diff(energy, theta),
             "phi_11": sp.diff(energy, z, 2), "phi_12": sp.diff(energy, z, theta), "phi_22": sp.diff(energy, theta, 2)}
    for name, expression in names.items():
        expected = np.array([float(expression.subs({z: a, theta: b})) for a, b in pairs])
        assert np.abs(found[name] - expected).max() <= 1e-12 * max(1.0, np.abs(expected).max()), name


def test_a_tube_past_its_pull_in_voltage_has_no_start():
    """At P = 0 the free charged tube is equibiaxial with Φ̄² = Φ_1(λ, λ)/(2λ³) (∂Φ_eff/∂λ1 = 0), whose maximum over λ
    is the pull-in voltage (SPOM1: derived here, 0.70115 at λ = 1.2604); under Φ̄ = 1.5 the start stops there, within
    1e-5 (the natural continuation's last converged voltage, as the one-line error prints it: measured 4e-8)."""
    lam = sp.Symbol("lam", positive=True)
    squared = sp.diff(symbolic_energy(tube_scene("SPOM1").material), z).subs({z: lam, theta: lam}) / (2 * lam**3)
    with mpmath.workdps(30):
        peak = sp.nsolve(sp.diff(squared, lam), lam, 1.3, prec=30)
    pull_in = float(sp.sqrt(squared.subs(lam, peak)))
    with pytest.raises(ContinuationError, match="past the tube's pull-in voltage") as error:
        primary_branch(charged_scene(voltage=1.5))
    assert "\n" not in str(error.value)
    reached = float(re.search(r"beyond (\S+) of electric.voltage = 1.5", str(error.value)).group(1))
    assert abs(reached - pull_in) <= 1e-5  # printed to 6 digits
