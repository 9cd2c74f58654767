"""Strain-energy families and user formulas (scene/energies.py, codegen/energies.py) against closed forms.

At M = 0 the primary branch is the sphere, P = 2Φ_1(λ, λ)/λ²; its pressure extrema satisfy λ(Φ_11 + Φ_12) = 2Φ_1
and its pear (n = 1) points λ(Φ_11 + Φ_12) = Φ_1 (model/sphere_modes.py). Φ_1, Φ_11, Φ_12 are derived here by
SymPy from the formulas typed again below (not from the scene layer's text), so the generated kernels, the
Galerkin discretisation and the branch-point location are checked against an independent derivation.
"""
import numpy as np
import pytest
import sympy as sp
from scipy.optimize import brentq

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Block, Kind, Status
from balloon_cg.model.sphere_modes import bifurcation_stretches
from balloon_cg.scene import parse_scene

l1, l2 = sp.symbols("l1 l2", positive=True)
_I1 = l1**2 + l2**2 + (l1 * l2) ** -2
_I2 = l1**-2 + l2**-2 + (l1 * l2) ** 2
N_AB, JM = 26.5, 97.2
MU_AB = 2 * (3 * N_AB - 3) / (3 * N_AB - 1)
INDEPENDENT = {
    "Mooney-Rivlin-I": (_I1 - 3) / 1.1 + 0.1 * (_I2 - 3) / 1.1,
    "Yeoh": (_I1 - 3) - 0.01 * (_I1 - 3) ** 2 + 3e-4 * (_I1 - 3) ** 3,
    "Gent": -JM * sp.log(1 - (_I1 - 3) / JM),
    "Gent-Gent": -(2 / 1.1) * JM / 2 * sp.log(1 - (_I1 - 3) / JM) + (0.3 / 1.1) * sp.log(_I2 / 3),
    "Arruda-Boyce": MU_AB * (_I1 - 3) / 6 - MU_AB * N_AB * sp.log((3 * N_AB - _I1) / (3 * N_AB - 3)),
}
STOP = 5.0


def sphere_functions(phi):
    """(P(λ), pear condition λ(Φ11 + Φ12) − Φ1, extremum condition λ(Φ11 + Φ12) − 2Φ1) as numpy functions."""
    lam = sp.Symbol("lam", positive=True)
    at = {l1: lam, l2: lam}
    d1 = sp.diff(phi, l1)
    phi1, S = d1.subs(at), (sp.diff(d1, l1) + sp.diff(d1, l2)).subs(at)
    f = lambda e: sp.lambdify(lam, e, "numpy")  # noqa: E731
    return f(2 * phi1 / lam**2), f(lam * S - phi1), f(lam * S - 2 * phi1)


def roots(f, upper):
    grid = np.geomspace(1.001, upper, 4000)
    values = f(grid)
    return [brentq(f, a, b, xtol=1e-15) for a, b, fa, fb in zip(grid, grid[1:], values, values[1:]) if fa * fb < 0]


def sphere_scene(material: str, name: str):
    return parse_scene(f"[material]\n{material}\n[continuation]\nstart_stretch = 1.01\nmin_stretch = 1.005\n"
                       f"stop_stretch = {STOP}\n", name=name)


@pytest.fixture(scope="module", params=list(INDEPENDENT))
def family(request):
    scene = sphere_scene(f'preset = "{request.param}"', request.param)
    return request.param, analyse(scene, pear=False).primary


def test_primary_branch_is_the_sphere_closed_form(family):
    name, primary = family
    pressure, _, _ = sphere_functions(INDEPENDENT[name])
    lam = primary.pole_values()["lam2_top"]
    assert lam.max() == pytest.approx(STOP, abs=1e-12)
    assert np.abs(primary.pressure / pressure(lam) - 1).max() < 1e-10


def test_pear_points_and_pressure_extrema_match_the_closed_conditions(family):
    """Every root of λ(Φ11 + Φ12) = Φ1 is a located odd-block branch point and every root of
    λ(Φ11 + Φ12) = 2Φ1 a located fold in P, to 1e-10 in λ; sphere_modes finds the same roots."""
    name, primary = family
    _, pear, extremum = sphere_functions(INDEPENDENT[name])
    north = lambda X: primary.pole_values(X)["lam2_top"][0]  # noqa: E731
    pears = [north(bp.X) for bp in primary.branch_points(Block.ODD_HELD)]
    folds = [north(p.X) for p in primary.special if p.kind == Kind.LP and p.status == Status.LOCATED]
    for expected, located, n in ((roots(pear, STOP), pears, 1), (roots(extremum, STOP), folds, 0)):
        assert len(located) == len(expected), (n, expected, located)
        assert np.abs(np.sort(located) - expected).max(initial=0) < 1e-10
        assert np.abs(bifurcation_stretches(primary.scene.material, n, lam_max=STOP) - expected).max(
            initial=0) < 1e-10


def test_gent_pressure_has_a_maximum_and_a_minimum_then_stiffens():
    """Gent, Jm = 97.2, μ0 as neo-Hookean: two closed-form extrema (the located folds are compared with them
    above), P rising after the minimum up to Gent's limit and past the maximum."""
    pressure, _, extremum = sphere_functions(INDEPENDENT["Gent"])
    maximum, minimum = roots(extremum, STOP)
    assert 1.39 < maximum < 1.41 and 4.0 < minimum < 4.1
    after = np.linspace(minimum, 7.0, 50)  # Gent's limit: I1 − 3 = Jm at λ ≈ 7.07 on the sphere
    assert pressure(maximum) > pressure(minimum) and np.all(np.diff(pressure(after)) > 0)
    assert pressure(7.0) > pressure(maximum)



def test_leaving_gent_domain_is_an_error_naming_the_point_and_stretch():
    """A sphere beyond Gent's limit (I1 − 3 ≥ Jm, where the kernels would stay finite): NonFiniteState naming
    the node, the failing log argument and the stretches; Newton reports it as the state leaving the domain."""
    from balloon_cg.analysis.branches.problem import equilibrium_of
    from balloon_cg.galerkin.equilibrium import NonFiniteState, Parameters

    scene = parse_scene('[material]\nfamily = "gent"\n[material.parameters]\nmu = 2.0\nJm = 10.0\n'
                        "[continuation]\nstop_stretch = 2.0\n")
    primary = analyse(scene, pear=False).primary
    X = primary.X[-1]
    beyond = X[:-1] * 3.0 / primary.pole_values(X)["lam2_top"][0]  # the sphere λ = 3: I1 − 3 = 15 > Jm
    equilibrium = equilibrium_of(primary)
    with pytest.raises(NonFiniteState, match=r"left the domain of gent at the node cos θ = -?[0-9.]+: log argument "
                                             r"1 - \(I1 - 3\) / Jm = -0\.501235 \(λ1 = 3, λ2 = 3\)"):
        equilibrium.residual(beyond, Parameters(X[-1]))
    equilibrium.residual(X[:-1], Parameters(X[-1]))  # inside: no error


def test_a_family_parameter_is_an_override_and_a_sweep_key():
    from balloon_cg.app.sweep import expand
    from balloon_cg.scene.validation import SceneError

    scene = parse_scene('[material]\npreset = "Gent"\n')
    assert scene.with_overrides({"material.parameters.Jm": 20.0}).material.parameters == {"mu": 2.0, "Jm": 20.0}
    members = expand(scene, ["material.parameters.Jm=20:60:3"])
    assert [m.scene.material.parameters["Jm"] for m in members] == [20.0, 40.0, 60.0]
    with pytest.raises(SceneError, match="no parameter 'N'"):
        scene.with_overrides({"material.parameters.N": 3.0})
    with pytest.raises(SceneError, match=r"parameters.Jm = -1.0: must be > 0"):
        scene.with_overrides({"material.parameters.Jm": -1.0})


def test_gent_pressure_extrema_merge_at_the_critical_jm():
    """The two extrema of the Gent sphere's P(λ) merge at Jm* (a double root of dP/dλ, solved by SymPy from the
    closed form); the kernels' sphere_modes find none just below Jm* and two about λ* just above."""
    from balloon_cg.scene.energies import family_energy

    lam, J = sp.symbols("lam J", positive=True)
    i1 = 2 * lam**2 + lam**-4
    slope = sp.numer(sp.together(sp.diff(sp.diff(-J * sp.log(1 - (i1 - 3) / J), lam) / lam**2, lam)))
    lam_c, jm_c = (float(x) for x in sp.nsolve([slope, sp.diff(slope, lam)], [lam, J], [1.6, 18]))
    assert jm_c == pytest.approx(17.638, abs=1e-3) and lam_c == pytest.approx(1.6426, abs=1e-4)
    gent = lambda jm: family_energy("gent", {"mu": 2.0, "Jm": jm}, "gent")  # noqa: E731
    assert bifurcation_stretches(gent(jm_c * (1 - 1e-4)), 0, lam_max=2.5).size == 0
    below, above = bifurcation_stretches(gent(jm_c * (1 + 1e-4)), 0, lam_max=2.5)
    assert below < lam_c < above and above - below < 0.02
