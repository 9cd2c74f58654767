"""The dielectric elastomer balloon: Φ = Φ_elastic − Φ̄² λ1² λ2² (docs/scenes.md, [electric]).

Units. The classic statement of the pull-in uses σ = μ(λ² − λ⁻⁴) for the equibiaxial neo-Hookean membrane, i.e.
W = (μ/2)(I1 − 3) − (ε/2)(Φ/H)² λ1² λ2² and Φ̄ = (Φ/H)√(ε/μ). This project's energy is Φ = W/(μ/2), so the
elastic part is I1 − 3 (the neo-Hookean preset) and the dielectric part (2/μ)(ε/2)(Φ/H)² λ1²λ2² = Φ̄² λ1²λ2²:
the same Φ̄, and stresses scaled by 2/μ, so that at P = 0 (zero stress in any units) the numbers are unchanged:
σ = 0 ⇔ Φ̄² = λ⁻² − λ⁻⁸, largest at λ⁶ = 4: λ = 2^(1/3), Φ̄² = 2^(−2/3) − 2^(−8/3).

Every closed form below is written out here, independently of model/sphere.py.
"""
import h5py
import numpy as np
import pytest
from scipy.optimize import brentq

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.results import Block, Kind, Status, StopCode
from balloon_cg.analysis.stability.axisymmetric import assess_branch
from balloon_cg.app.api import Result
from balloon_cg.galerkin.equilibrium import Parameters
from balloon_cg.model.kernels import PLAIN, KernelSet
from balloon_cg.model.shooting import shoot_symmetric
from balloon_cg.scene import parse_scene
from balloon_cg.scene.validation import SceneError

NEO = '[material]\npreset = "neo-Hookean"\n'
PULL_IN_STRETCH = 2 ** (1 / 3)
DIELECTRIC = (*PLAIN, "dielectric")  # the terms of a dielectric class without coils
PULL_IN_VOLTAGE_SQ = 2 ** (-2 / 3) - 2 ** (-8 / 3)


def neo_hookean_derivatives(lam, voltage):
    """Φ_1, Φ_11, Φ_12 of Φ = λ1² + λ2² + λ1⁻²λ2⁻² − 3 − Φ̄² λ1²λ2² at λ1 = λ2 = λ."""
    phi1 = 2 * lam - 2 * lam**-5 - 2 * voltage**2 * lam**3
    phi11 = 2 + 6 * lam**-6 - 2 * voltage**2 * lam**2
    phi12 = 4 * lam**-6 - 4 * voltage**2 * lam**2
    return phi1, phi11, phi12


def neo_hookean_pressure(lam, voltage):
    """P = 2 Φ_1(λ, λ)/λ² = 4(λ⁻¹ − λ⁻⁷) − 4 Φ̄² λ."""
    return 2 * neo_hookean_derivatives(lam, voltage)[0] / lam**2


def sphere_mode_condition(lam, voltage, n):
    """The sphere's axisymmetric mode-n bifurcation condition (docs/sphere_bifurcation.md) with the dielectric
    term in Φ: n = 1: S = t; n ≥ 2: Δ_n = Φ11² − Φ12² + t((N − 1)Φ11 + 3Φ12) − 2t² (N = n(n+1), t = Φ1/λ)."""
    phi1, phi11, phi12 = neo_hookean_derivatives(lam, voltage)
    t, N = phi1 / lam, n * (n + 1)
    if n == 1:
        return phi11 + phi12 - t
    return phi11**2 - phi12**2 + t * ((N - 1) * phi11 + 3 * phi12) - 2 * t**2


@pytest.fixture(scope="module")
def pull_in_branch():
    scene = parse_scene(NEO + '[electric]\n[continuation]\nparameter = "voltage"\nstop_stretch = 2.0\n',
                        name="pull_in")
    branch = trace_primary(scene)
    branch.stability, _ = assess_branch(branch, scene.stability.degree)
    return branch


def test_pull_in_is_located_at_the_closed_form(pull_in_branch):
    """Voltage control at P = 0: the fold in Φ̄ at λ = 2^(1/3), Φ̄² = 2^(−2/3) − 2^(−8/3) (module docstring)."""
    folds = [s for s in pull_in_branch.special if s.kind == Kind.LP]
    assert len(folds) == 1
    fold = folds[0]
    stretch = pull_in_branch.pole_values(fold.X)["lam2_top"][0]
    assert abs(stretch - PULL_IN_STRETCH) < 1e-10
    assert abs(fold.X[-1] ** 2 - PULL_IN_VOLTAGE_SQ) < 1e-10


def test_the_pull_in_fold_reports_the_bracket_its_search_narrowed(pull_in_branch):
    """At the zero-tension pull-in every sphere mode is singular at once: the corrector fails ~1e-13 from the
    fold, so the fold may be stored approximate; then its uncertainty is the narrowest sign change the root
    search evaluated (~2e-8), not the whole continuation step (it was 3.4e-3), and it covers the closed form."""
    fold = next(s for s in pull_in_branch.special if s.kind == Kind.LP)
    assert fold.status == Status.LOCATED or fold.uncertainty < 1e-6
    stretch = pull_in_branch.pole_values(fold.X)["lam2_top"][0]
    assert abs(stretch - PULL_IN_STRETCH) <= max(fold.uncertainty, 1e-10)


def test_voltage_branch_is_the_zero_pressure_sphere(pull_in_branch):
    lam = pull_in_branch.pole_values()["lam2_top"]
    assert np.all(pull_in_branch.pressure == 0.0)
    assert np.abs(pull_in_branch.voltage**2 - (lam**-2 - lam**-8)).max() < 1e-10
    assert pull_in_branch.stopped(StopCode.STOP_STRETCH)


def test_voltage_control_loses_stability_at_the_pull_in(pull_in_branch):
    """Stable (fixed P = 0 and Φ̄) below the pull-in stretch, unstable above it."""
    lam = pull_in_branch.pole_values()["lam2_top"]
    stable = np.array([a.stable_pressure for a in pull_in_branch.stability])
    assert np.all(stable[lam < PULL_IN_STRETCH - 1e-6]) and not np.any(stable[lam > PULL_IN_STRETCH + 1e-6])


@pytest.fixture(scope="module")
def fixed_voltage():
    """Pressure continuation at Φ̄ = 0.3 with the branch points and the m ≤ 2 stability."""
    scene = parse_scene(NEO + "[electric]\nvoltage = 0.3\n[continuation]\nstart_stretch = 1.1\nstop_stretch = 2.45\n"
                        "[stability]\nm_max = 2\n", name="fixed_voltage")
    return analyse(scene, pear=False)


def test_fixed_voltage_pressure_is_the_sphere_closed_form(fixed_voltage):
    branch = fixed_voltage.primary
    lam = branch.pole_values()["lam2_top"]
    assert np.abs(branch.pressure - neo_hookean_pressure(lam, 0.3)).max() < 1e-10
    assert np.all(branch.voltage == 0.3)


def test_compressed_membrane_stops_the_branch(fixed_voltage):
    """Below the stretch where the tension Φ_1 vanishes (2λ − 2λ⁻⁵ = 2Φ̄²λ³) the dielectric stress would compress
    the membrane: the down leg stops there, its last point taut."""
    branch = fixed_voltage.primary
    slack = brentq(lambda lam: neo_hookean_derivatives(lam, 0.3)[0], 1.0001, 1.1)
    assert branch.stopped(StopCode.COMPRESSED)
    lam = branch.pole_values()["lam2_top"]
    assert slack < lam.min() < slack + 0.05


def test_branch_points_satisfy_the_sphere_conditions_with_the_dielectric_term(fixed_voltage):
    """Pear (n = 1, λ⁸ = 3/Φ̄²), n = 2 (even block) and n = 3 (odd) points on the sphere: to 1e-9 in λ."""
    branch = fixed_voltage.primary
    found = {(bp.block, round(float(branch.pole_values(bp.X)["lam2_top"][0]), 3)):
             float(branch.pole_values(bp.X)["lam2_top"][0]) for bp in fixed_voltage.branch_points}
    pear = (3 / 0.3**2) ** (1 / 8)
    assert sphere_mode_condition(pear, 0.3, 1) == pytest.approx(0.0, abs=1e-12)
    expected = {Block.ODD_HELD: [pear, brentq(sphere_mode_condition, 2.2, 2.45, args=(0.3, 3))],
                Block.EVEN: [brentq(sphere_mode_condition, 1.9, 2.2, args=(0.3, 2))]}
    assert len(found) == 3
    for block, stretches in expected.items():
        for lam in stretches:
            assert abs(found[block, round(lam, 3)] - lam) < 1e-9


def test_azimuthal_blocks_cross_at_the_sphere_modes(fixed_voltage):
    """cos mφ blocks (m ≥ 1) against the sphere's modes (spherical symmetry: mode n has copies m = 0..n): the lowest
    eigenvalue of the held block m changes sign once, between the two points that bracket the stretch of the
    first mode with n ≥ m, i.e. n = m (n = 1: λ⁸ = 3/Φ̄²; n = 2: Δ_2 = 0)."""
    branch = fixed_voltage.primary
    lam = branch.pole_values()["lam2_top"]
    modes = {1: (3 / 0.3**2) ** (1 / 8), 2: brentq(sphere_mode_condition, 1.9, 2.2, args=(0.3, 2))}
    for m, stretch in modes.items():
        lowest = np.array([a.blocks[Block.azimuthal(m, True).value][0] for a in branch.stability])
        changes = np.flatnonzero(np.diff(np.sign(lowest)))
        assert len(changes) == 1
        assert lam[changes[0]] < stretch < lam[changes[0] + 1]


def test_gent_with_voltage_follows_its_sphere_closed_form():
    """Gent (μ = 2, Jm = 97.2): Φ = −Jm ln(1 − (I1 − 3)/Jm), Φ_1 = Jm/(Jm − I1 + 3) (2λ − 2λ⁻⁵) on the sphere."""
    scene = parse_scene('[material]\npreset = "Gent"\n[electric]\nvoltage = 0.2\n[continuation]\n'
                        "start_stretch = 1.1\nstop_stretch = 3.0\n", name="gent_voltage")
    branch = trace_primary(scene)
    lam = branch.pole_values()["lam2_top"]
    jm, i1 = 97.2, 2 * lam**2 + lam**-4
    exact = 2 * (jm / (jm - i1 + 3) * (2 * lam - 2 * lam**-5) - 2 * 0.2**2 * lam**3) / lam**2
    assert np.abs(branch.pressure - exact).max() < 1e-10
    assert any(s.kind == Kind.LP for s in branch.special)  # the pressure maximum


def test_voltage_derivative_is_exact_with_a_coil_field():
    """∂R/∂Φ̄ (generated) against a central difference of R, on a field-deformed (non-spherical) state."""
    scene = parse_scene(NEO + "[electric]\nvoltage = 0.25\n[field]\nM = 0.002\n[[field.coils]]\nradius = 1.7321\n"
                        "height = 1.0\ncurrent = 1.0\n[continuation]\nstart_stretch = 1.2\nstop_stretch = 1.5\n",
                        name="coil_voltage")
    branch = trace_primary(scene, down=False)
    eq = equilibrium_of(branch)
    X = branch.X[len(branch.X) // 2]
    params = branch.params_at(X)
    assert eq.kernels.electric and eq.kernels.field_class
    exact = eq.parameter_derivative(X[:-1], params, "voltage")
    h = 1e-5
    difference = (eq.residual(X[:-1], params.with_value("voltage", 0.25 + h))
                  - eq.residual(X[:-1], params.with_value("voltage", 0.25 - h))) / (2 * h)
    assert np.abs(exact - difference).max() < 1e-8 * np.abs(exact).max()
    assert np.abs(exact).max() > 0.1


def test_voltage_is_a_runtime_parameter_of_one_module():
    """Scenes that differ only in Φ̄ use one kernel module; its kernels take Φ̄ as the named argument 'voltage'."""
    first = parse_scene(NEO + "[electric]\nvoltage = 0.1\n")
    second = first.with_overrides({"electric.voltage": 0.4})
    a = KernelSet(first.material, DIELECTRIC)
    b = KernelSet(second.material, DIELECTRIC)
    assert a.module is b.module and a.name == b.name
    assert ("voltage", "param", ()) in a.module.KERNELS["energy_gradient"]["args"]
    plain = KernelSet(first.material)
    assert "voltage_gradient" not in plain.module.KERNELS and plain.name == "ogden_neo_hookean"
    values = {"cos_theta": np.array([0.3]), "sin_theta": np.array([0.95]), "lam2": np.array([1.3]),
              "v": np.array([0.0]), "eta": np.array([0.4]), "w": np.array([-1.2])}
    # π̂ difference between two voltages: −(Φ̄1² − Φ̄0²) λ1² λ2², λ1 = |(λ2 cos θ + v, w)|
    lam1_sq = (1.3 * 0.3) ** 2 + 1.2**2
    energy = [a.nodes("energy_density", values, Parameters(0.5, voltage=V))[0, 0] for V in (0.1, 0.4)]
    assert energy[1] - energy[0] == pytest.approx(-(0.4**2 - 0.1**2) * lam1_sq * 1.3**2, rel=1e-13)


def test_shear_coefficient_gains_the_voltage_squared():
    """K = (φ̂_1 − φ̂_2)/(e1 − e2) of −Φ̄² e1 e2 is Φ̄²: the dielectric class's K minus the plain class's."""
    scene = parse_scene(NEO + "[electric]\n")
    electric, plain = KernelSet(scene.material, DIELECTRIC), KernelSet(scene.material)
    for l1, l2 in ((1.3, 1.3), (1.2, 1.5)):
        K = electric.call("shear_coefficient", {"lam1": l1, "lam2": l2, "voltage": 0.35})[0]
        assert K - plain.call("shear_coefficient", {"lam1": l1, "lam2": l2})[0] == pytest.approx(0.35**2, rel=1e-12)


def test_run_file_records_the_voltage_and_the_term(tmp_path, pull_in_branch):
    result = Result.of(pull_in_branch.scene, [pull_in_branch])
    path = result.save(tmp_path / "pull_in.h5")
    with h5py.File(path) as f:
        group = f["branches/primary"]
        assert group.attrs["electric"] and group.attrs["parameter"] == "voltage"
        assert np.array_equal(group["voltage"][:], pull_in_branch.voltage)
        assert np.all(group["pressure"][:] == 0.0)
        lp = list(group["special_points/kind"].asstr()[:]).index("LP")
        assert group["special_points/voltage"][lp] ** 2 == pytest.approx(PULL_IN_VOLTAGE_SQ, abs=1e-10)
        assert "[electric]" in f.attrs["scene_toml"]
    plain = trace_primary(parse_scene(NEO + "[continuation]\nstop_stretch = 1.2\n"))
    with h5py.File(Result.of(plain.scene, [plain]).save(tmp_path / "plain.h5")) as f:
        assert not f["branches/primary"].attrs["electric"] and "voltage" not in f["branches/primary"]


@pytest.mark.parametrize("text, message", [
    ("[electric]\nvoltage = -0.1\n", "electric.voltage = -0.1: must be in [0, 10]"),
    ("[electric]\nvoltage = inf\n", "electric.voltage = inf: must be finite"),
    ('[electric]\nvoltage = "high"\n', 'electric.voltage = "high": must be a number'),
    ("[electric]\ncharge = 1\n", "electric.charge = 1: unknown key; allowed keys: voltage"),
    ("[electric]\nvoltage = [0.3]\n", "electric.voltage = [0.3]: must be a number"),
    ('[continuation]\nparameter = "voltage"\n', 'continuation.parameter = "voltage": needs an [electric] table'),
    ('[electric]\n[continuation]\nparameter = "charge"\n',
     'continuation.parameter = "charge": must be one of "pressure", "voltage"'),
    ("[electric]\n[continuation]\nstop_voltage = 0.5\n",
     'continuation.stop_voltage = 0.5: only for continuation.parameter = "voltage"'),
    ('[electric]\nvoltage = 0.2\n[continuation]\nparameter = "voltage"\n', "electric.voltage = 0.2: a voltage "
     "continuation starts at the sphere's voltage"),
    ('[electric]\n[continuation]\nparameter = "voltage"\nstop_voltage = 0\n', "continuation.stop_voltage = 0: "
     "must be in (0, 10]"),
    ('[electric]\n[continuation]\nparameter = "voltage"\npressure = -1\n', "continuation.pressure = -1: must be "
     ">= 0"),
])
def test_bad_electric_input_is_one_line_naming_key_and_value(text, message):
    with pytest.raises(SceneError) as error:
        parse_scene(NEO + text)
    assert message in str(error.value) and "\n" not in str(error.value)


def test_electric_must_be_a_table():
    with pytest.raises(SceneError, match=r"electric = 0.3: must be a table$"):
        parse_scene("electric = 0.3\n" + NEO)


def test_a_start_the_voltage_compresses_is_refused():
    scene = parse_scene(NEO + "[electric]\nvoltage = 0.3\n")  # start_stretch 1.01: below the zero-tension stretch
    with pytest.raises(RuntimeError, match="compressed at the voltage 0.3"):
        trace_primary(scene)


def test_galerkin_matches_shooting_with_voltage_and_two_coils():
    """Φ̄ = 0.25 between the paper's two coils (M = 0.003, neo-Hookean): the Galerkin point at north pole stretch
    1.5 against the independent shooting solution (first-order kernels and pole series of the same class), 1e-10;
    the field moves P away from the sphere's by more than 1 %."""
    scene = parse_scene(NEO + "[electric]\nvoltage = 0.25\n[field]\nM = 0.003\n[[field.coils]]\nradius = 1.7321\n"
                        "height = 1.0\ncurrent = 1.0\n[[field.coils]]\nradius = 1.7321\nheight = -1.0\n"
                        "current = -1.0\n[continuation]\nstart_stretch = 1.2\n[solver]\ndegree = 80\n"
                        "max_degree = 80\nmax_error = 1e-2\n", name="two_coils_voltage")
    branch = trace_primary(scene, stop_stretch=1.5, down=False)
    P, eta = branch.pressure[-1], branch.pole_values()["eta_top"][-1]
    shot = shoot_symmetric(scene, 1.5, P_guess=1.01 * P, eta0_guess=eta)
    assert shot.converged
    assert abs(shot.P / P - 1) < 1e-10 and abs(shot.eta_top / eta - 1) < 1e-10
    assert abs(P / neo_hookean_pressure(1.5, 0.25) - 1) > 0.01


def test_voltage_fold_at_a_positive_pressure_and_the_zero_voltage_end():
    """At P = 0.5 the sphere is held by Φ̄² = (4(λ⁻¹ − λ⁻⁷) − P)/(4λ) = λ⁻² − λ⁻⁸ − P/(4λ): its maximum,
    −2λ⁻³ + 8λ⁻⁹ + P/(4λ²) = 0 (solved by brentq), is the located fold; the lower leg ends where Φ̄ reaches 0 (the
    voltage-free sphere)."""
    scene = parse_scene(NEO + '[electric]\n[continuation]\nparameter = "voltage"\npressure = 0.5\n'
                        "start_stretch = 1.2\nstop_stretch = 2.0\n", name="voltage_P0.5")
    branch = trace_primary(scene)
    square = lambda lam: (neo_hookean_pressure(lam, 0.0) - 0.5) / (4 * lam)  # noqa: E731
    peak = brentq(lambda lam: -2 * lam**-3 + 8 * lam**-9 + 0.5 / (4 * lam**2), 1.1, 1.6, xtol=1e-14)
    fold = next(s for s in branch.special if s.kind == Kind.LP)
    assert abs(branch.pole_values(fold.X)["lam2_top"][0] - peak) < 1e-10
    assert abs(fold.X[-1] ** 2 - square(peak)) < 1e-12
    assert np.all(branch.pressure == 0.5) and branch.voltage.min() > 0
    assert branch.stopped(StopCode.ZERO_VOLTAGE) and branch.stopped(StopCode.STOP_STRETCH)


def test_a_compressed_point_is_never_landed_on():
    """Φ̄ = 0.085: the tension vanishes at λ = 1.0012, just above min_stretch = 1.001, and the step that passes it
    also passes min_stretch: the leg stops as compressed instead of landing on min_stretch (a compressed sphere,
    P < 0), and every stored point is taut (P > 0)."""
    scene = parse_scene(NEO + "[electric]\nvoltage = 0.085\n[continuation]\nstart_stretch = 1.1\nstop_stretch = 1.2\n")
    branch = trace_primary(scene)
    slack = brentq(lambda lam: neo_hookean_derivatives(lam, 0.085)[0], 1.0001, 1.1)
    assert 1.001 < slack < 1.002
    assert branch.stopped(StopCode.COMPRESSED) and not branch.stopped(StopCode.MIN_STRETCH)
    assert branch.pressure.min() > 0 and branch.pole_values()["lam2_top"].min() > slack


def test_voltage_is_a_second_parameter():
    """critical --parameter voltage: the dielectric class's runtime voltage is found (KernelSet.of_scene)."""
    from balloon_cg.analysis.critical.second_parameter import resolve
    scene = parse_scene('[material]\npreset = "SPOM1"\n[electric]\nvoltage = 0.05\n', "d")
    assert resolve(scene, "voltage") == "electric.voltage"
    with pytest.raises(ValueError, match="not a runtime parameter"):
        resolve(parse_scene('[material]\npreset = "SPOM1"\n', "plain"), "voltage")
