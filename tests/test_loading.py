"""Loading control (scene/loading.py): gas and volume control against the sphere's closed forms.

On the M = 0 sphere of radius λ (MODEL.md §4) P(λ) is known in closed form (model/sphere.py); with V = 4πλ³/3
and n = P V, the second variation of E/2π along the uniform inflation δ = d(u)/dλ (a_0 = b_1 = 1) is
2λ² P'(λ) under pressure control and 2 (Pλ³)'/λ under gas control (d²/dλ² of E − n ln V at fixed n), so the
gas reading is stable to uniform inflation iff (Pλ³)' > 0, and the folds in n are the extrema of Pλ³.
"""
import h5py
import numpy as np
import pytest
from scipy.optimize import brentq

from balloon_cg.analysis.branches.control import control_value
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.results import Kind, Status, StopCode
from balloon_cg.analysis.stability.axisymmetric import FLAGS, SecondVariation, assess_branch
from balloon_cg.app.cli import main
from balloon_cg.model.sphere import sphere_pressure
from balloon_cg.post.plotting import Reading, load_branches
from balloon_cg.scene import Control, SceneError, load_scene, parse_scene

# SPOM1's exponents (its committed kernels) with a stronger α = −2 term: μ3 α3 < 0 softens Pλ³ at large λ,
# which then has a maximum (every preset has Σ-terms μ_i α_i > 0 and a monotone Pλ³: no folds in n)
SOFT = """
[material]
mu = [3.0, 0.0145, 0.06]
alpha = [1.3, 4.0, -2.0]
[continuation]
stop_stretch = 4.0
[stability]
m_max = 0
[loading]
control = "gas"
"""


def closed_pressure(material, lam):
    """P(λ) of the sphere (MODEL.md §4), written out here."""
    return 2 * sum(mu * (lam ** (a - 3) - lam ** (-2 * a - 3)) for mu, a in zip(material.mu, material.alpha))


def closed_dP(material, lam):
    return 2 * sum(mu * ((a - 3) * lam ** (a - 4) + (2 * a + 3) * lam ** (-2 * a - 4))
                   for mu, a in zip(material.mu, material.alpha))


def closed_dPlam3(material, lam):
    """d(P λ³)/dλ = 2 Σ μ_i α_i (λ^(α_i − 1) + 2 λ^(−2α_i − 1))."""
    return 2 * sum(mu * a * (lam ** (a - 1) + 2 * lam ** (-2 * a - 1)) for mu, a in zip(material.mu, material.alpha))


def test_closed_forms_are_those_of_the_package():
    material = load_scene("spom1").material
    lam, h = np.linspace(1.05, 4.0, 7), 1e-3
    assert np.allclose(closed_pressure(material, lam), sphere_pressure(material, lam), rtol=1e-13)
    derivative = (sphere_pressure(material, lam - 2 * h) - 8 * sphere_pressure(material, lam - h)
                  + 8 * sphere_pressure(material, lam + h) - sphere_pressure(material, lam + 2 * h)) / (12 * h)
    assert np.allclose(closed_dP(material, lam), derivative, rtol=1e-8)
    assert np.allclose(closed_dPlam3(material, lam), closed_dP(material, lam) * lam**3
                       + 3 * lam**2 * closed_pressure(material, lam), rtol=1e-12)


@pytest.fixture(scope="module")
def spom1_gas():
    scene = load_scene("spom1").with_overrides({"loading.control": "gas", "continuation.stop_stretch": 3.0,
                                                 "stability.m_max": 0})
    branch = trace_primary(scene)
    return branch, assess_branch(branch, scene.stability.degree)[0]


@pytest.fixture(scope="module")
def soft_gas():
    scene = parse_scene(SOFT, "soft")
    branch = trace_primary(scene)
    return branch, assess_branch(branch, scene.stability.degree)[0]


def uniform_second_variations(branch):
    """δᵀHδ and δᵀH_gas δ along the uniform inflation at every point of an M = 0 sphere branch, and λ."""
    variation = SecondVariation(equilibrium_of(branch), branch.scene.stability.degree)
    delta = np.zeros(2 * (variation.basis.degree + 1))
    delta[0] = delta[variation.translation + 1] = 1.0  # a_0 = b_1 = 1
    rows = []
    for X in branch.X:
        params = branch.params.with_value("P", X[-1])
        H, g = variation.matrices(X[:-1], params)
        pressure = delta @ H @ delta
        rows.append((pressure, pressure + X[-1] / variation.eq.volume(X[:-1]) * (g @ delta) ** 2))
    return np.array(rows), branch.pole_values()["lam2_top"]


@pytest.mark.parametrize("case", ["spom1_gas", "soft_gas"])
def test_uniform_second_variation_matches_the_closed_form(case, request):
    branch, _ = request.getfixturevalue(case)
    material = branch.scene.material
    rows, lam = uniform_second_variations(branch)
    pressure, gas = rows.T
    assert np.allclose(pressure, 2 * lam**2 * closed_dP(material, lam), rtol=1e-8, atol=1e-9)
    assert np.allclose(gas, 2 * closed_dPlam3(material, lam) / lam, rtol=1e-8, atol=1e-9)


def test_gas_flag_follows_the_closed_form_on_spom1(spom1_gas):
    """Along SPOM1's primary branch (M = 0) the even block (the one holding the uniform inflation) is stable
    under gas control iff (Pλ³)' > 0 (always, for SPOM1), under pressure control iff P' > 0 (up to the fold)."""
    branch, assessments = spom1_gas
    material, lam = branch.scene.material, branch.pole_values()["lam2_top"]
    assert np.allclose(branch.pressure, sphere_pressure(material, lam), rtol=1e-10)
    far = np.abs(closed_dP(material, lam)) > 1e-2  # not at the fold itself
    gas = np.array([a.blocks["even_gas"][0] > 0 for a in assessments])
    held = np.array([a.blocks["even"][0] > 0 for a in assessments])
    assert np.array_equal(gas, closed_dPlam3(material, lam) > 0) and gas.all()
    assert np.array_equal(held[far], (closed_dP(material, lam) > 0)[far]) and not held.all()
    stable_gas = np.array([a.stable_gas for a in assessments])
    assert (stable_gas <= gas).all() and stable_gas.sum() > np.array([a.stable_pressure for a in assessments]).sum()


def test_fold_in_n_matches_the_extremum_of_P_lambda3(soft_gas, spom1_gas):
    branch, assessments = soft_gas
    material = branch.scene.material
    folds = [s for s in branch.special if s.kind == Kind.LN]
    assert len(folds) == 1 and folds[0].status == Status.LOCATED
    lam_star = brentq(lambda lam: closed_dPlam3(material, lam), 2.0, 4.0, xtol=1e-15)
    n_star = 4 * np.pi / 3 * lam_star**3 * closed_pressure(material, lam_star)
    fold = folds[0]
    assert abs(branch.pole_values(fold.X)["lam2_top"][0] - lam_star) < 1e-8 * lam_star
    assert abs(control_value(branch.disc, fold.X, Control.GAS) - n_star) < 1e-8 * n_star
    # the gas reading loses the uniform mode at the fold: unstable past it
    stable = np.array([a.stable_gas for a in assessments])
    assert not stable[fold.index + 1:].any()
    assert not [s for s in spom1_gas[0].special if s.kind == Kind.LN]  # SPOM1: Pλ³ monotone, no fold in n


def test_gas_jacobian_is_singular_at_the_fold_in_n(soft_gas):
    """At a fold of n the Jacobian of the gas problem, J + (P/Ṽ) ∇Ṽ ∇Ṽᵀ (the Hessian of E/2π − (n/2π) ln V in
    the unknowns), is singular (J du = ∇Ṽ dP with dn = 0 gives it a null vector); at the neighbours it is not."""
    branch, _ = soft_gas
    fold = next(s for s in branch.special if s.kind == Kind.LN)
    eq = equilibrium_of(branch)

    def smallest_singular_value(X):
        params = branch.params.with_value("P", X[-1])
        gradient = -eq.parameter_derivative(X[:-1], params, "P")  # ∇Ṽ
        J = eq.jacobian(X[:-1], params) + X[-1] / eq.volume(X[:-1]) * np.outer(gradient, gradient)
        return np.linalg.svd(J, compute_uv=False)[-1]

    at_fold = smallest_singular_value(fold.X)
    neighbours = [smallest_singular_value(branch.X[i]) for i in (fold.index, fold.index + 1)]
    assert at_fold < 1e-8 < min(neighbours)


@pytest.mark.parametrize("control, key, target", [("gas", "stop_amount", 40.0), ("volume", "stop_volume", 20.0)])
def test_branch_lands_on_the_control_stop(control, key, target):
    scene = load_scene("spom1").with_overrides({"loading.control": control, f"loading.{key}": target})
    branch = trace_primary(scene, down=False)
    assert branch.legs[0].stop.code == (StopCode.STOP_AMOUNT if control == "gas" else StopCode.STOP_VOLUME)
    value = control_value(branch.disc, branch.X[-1], Control(control))
    assert abs(value - target) < 1e-11 * target
    lam = branch.pole_values()["lam2_top"][-1]
    volume = 4 * np.pi / 3 * lam**3
    assert abs((volume * sphere_pressure(scene.material, lam) if control == "gas" else volume) - target) < 1e-9 * target


def test_flags_nest_between_pressure_and_volume_control_with_a_field():
    """Stable under pressure ⇒ stable under gas ⇒ stable under volume control, held and free, on the two-coil
    primary branch; and gas control is stable past the loss of pressure stability (on this branch the gas and
    volume readings coincide: both lose stability to the same pear mode, which keeps the volume)."""
    scene = load_scene("spom1_two_coils_M0.002").with_overrides(
        {"loading.control": "gas", "continuation.stop_stretch": 2.6, "stability.m_max": 1, "stability.degree": 12})
    branch = trace_primary(scene)
    flags = np.array([list(a.flags().values()) for a in assess_branch(branch, scene.stability.degree)[0]])
    names = list(FLAGS)
    column = {name: flags[:, names.index(name)] for name in names}
    for suffix in ("", "_free"):
        pressure, gas, volume = (column[f"stable_{c}{suffix}"] for c in ("pressure", "gas", "volume"))
        assert (pressure <= gas).all() and (gas <= volume).all()
    assert (column["stable_gas"] & ~column["stable_pressure"]).any()


def test_bad_control_is_one_line():
    with pytest.raises(SceneError) as error:
        parse_scene('[material]\npreset = "SPOM1"\n[loading]\ncontrol = "mass"\n', "bad")
    assert str(error.value) == 'bad: loading.control = "mass": must be one of "pressure", "volume", "gas"'
    with pytest.raises(SceneError, match=r'loading.stop_amount = 3.0: only with loading.control = "gas"'):
        parse_scene('[material]\npreset = "SPOM1"\n[loading]\nstop_amount = 3.0\n', "bad")
    voltage = '[material]\npreset = "neo-Hookean"\n[electric]\n[continuation]\nparameter = "voltage"\n'
    assert parse_scene(voltage, "ok").loading.control == Control.PRESSURE
    with pytest.raises(SceneError, match=r'loading.control = "gas": a voltage continuation .* allowed: "pressure"'):
        parse_scene(voltage + '[loading]\ncontrol = "gas"\n', "bad")


def test_default_scene_text_is_unchanged():
    scene = load_scene("spom1")
    assert scene.loading.control == Control.PRESSURE and "[loading]" not in scene.to_toml()
    gas = scene.with_overrides({"loading.control": "gas"})
    assert gas.name == "spom1_gas" and parse_scene(gas.to_toml()).loading.control == Control.GAS


@pytest.mark.parametrize("control", list(Control))
def test_run_and_inspect_each_control(control, tmp_path, capsys):
    out = tmp_path / f"{control}.h5"
    assert main(["run", "spom1", "--primary-only", "--quiet", "--set", f"loading.control={control.value}",
                 "--set", "continuation.stop_stretch=1.8", "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["inspect", str(out)]) == 0
    assert f"control        {control.value} (loading.control)" in capsys.readouterr().out
    assert load_branches(str(out))[0].reading == Reading(control.value)  # plot's default reading
    with h5py.File(out) as f:
        assert f.attrs["control"] == control.value
        b = f["branches/primary"]
        assert b["amount"].attrs["units"] == "1" and b["amount"].attrs["long_name"] == "gas amount n"
        assert np.allclose(b["amount"][:], b["pressure"][:] * b["volume"][:], rtol=1e-14)
