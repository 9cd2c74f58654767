"""Two-parameter continuation in any runtime parameter (analysis.critical.second_parameter): a strain energy's parameter
against the sphere's closed-form pear condition, a runtime scalar without a derivative kernel (χ, central
differences) against the same curve in M (exact), the Jacobians against differences of the residual, and the
one-line error for a name the scene does not have."""
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.points import branch_points as bifurcation
from balloon_cg.analysis.critical.pitchfork_curve import CurveEnd, continue_branch_point
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.results import Status, StopCode
from balloon_cg.analysis.critical.second_parameter import Derivative, UnknownParameter, parameter_keys, resolve
from balloon_cg.app.cli import main
from balloon_cg.io.curve_file import read_curve, write_curve
from balloon_cg.scene import load_scene, parse_scene
from pitchforks import isola, jacobian_error, pear_events

SCENES = Path(__file__).resolve().parent.parent / "scenes"
YEOH = ('[material]\nfamily = "rivlin"\n[material.parameters]\nC10 = 1.0\nC01 = 0.0\nC20 = -0.01\nC11 = 0.0\n'
        'C02 = 0.0\nC30 = 3e-4\n[continuation]\nstop_stretch = 3.0\n')


def yeoh_sphere(lam, C20, C10=1.0, C30=3e-4):
    """(P, λ(Φ11 + Φ12) − Φ1, its scale) of the sphere of radius λ for Φ = W(I1) = C10 x + C20 x² + C30 x³,
    x = I1 − 3, I1 = λ1² + λ2² + 1/(λ1λ2)², written out: Φ1 = W' ∂1I1, Φ11 = W'' (∂1I1)² + W' ∂11I1,
    Φ12 = W'' ∂1I1 ∂2I1 + W' ∂12I1 at λ1 = λ2 = λ, where ∂1I1 = 2λ − 2λ⁻⁵, ∂11I1 = 2 + 6λ⁻⁶, ∂12I1 = 4λ⁻⁶."""
    x = 2 * lam**2 + lam**-4 - 3
    w1, w2 = C10 + 2 * C20 * x + 3 * C30 * x**2, 2 * C20 + 6 * C30 * x
    d1 = 2 * lam - 2 * lam**-5
    phi1, phi11, phi12 = w1 * d1, w2 * d1**2 + w1 * (2 + 6 * lam**-6), w2 * d1**2 + w1 * 4 * lam**-6
    return 2 * phi1 / lam**2, lam * (phi11 + phi12) - phi1, abs(lam * (phi11 + phi12)) + abs(phi1)


@pytest.fixture(scope="module")
def yeoh():
    return isola(parse_scene(YEOH, name="yeoh"))  # Yeoh's softening then stiffening: an isola at M = 0


@pytest.fixture(scope="module")
def c20_curve(yeoh):
    _, branch, bps = yeoh
    return continue_branch_point(branch, bps[0], "material.parameters.C20")


def test_curve_in_C20_satisfies_the_sphere_pear_condition(c20_curve):
    """At M = 0 every point of the curve is a sphere whose radius λ is a pear point, λ(Φ11 + Φ12) = Φ1, at the
    point's own C20 (closed form above), and its pressure is 2Φ1/λ²; the curve runs from the lower pitchfork over
    the merge to the upper one."""
    curve = c20_curve
    assert curve.end == CurveEnd.ISOLA_MERGE and curve.stop.code == StopCode.PARTNER
    assert curve.second.derivative == Derivative.CENTRAL and curve.parameter == "C20"
    assert len(curve.q) >= 8 and curve.q.max() > -0.01 + 1e-3
    for q, lam, P in zip(curve.q, curve.pole_stretch, curve.pressure):
        pressure, condition, scale = yeoh_sphere(lam, q)
        assert abs(condition) < 1e-8 * scale
        assert P == pytest.approx(pressure, rel=1e-8)
    assert np.allclose(curve.pole_values()["lam2_bottom"], curve.pole_stretch, rtol=1e-10)


def test_critical_C20_is_where_the_condition_touches_zero(c20_curve):
    """The merge: the closed-form condition and its λ-derivative vanish together at (C20*, λ*)."""
    merge = c20_curve.merges[0]
    assert merge.status == Status.LOCATED
    qc, _, lam = c20_curve.critical
    h = 1e-5
    slope = (yeoh_sphere(lam + h, qc)[1] - yeoh_sphere(lam - h, qc)[1]) / (2 * h)
    _, condition, scale = yeoh_sphere(lam, qc)
    assert abs(condition) < 1e-8 * scale and abs(slope) < 1e-4 * scale


def test_curve_file_records_the_parameter(c20_curve, yeoh, tmp_path):
    data = read_curve(write_curve(tmp_path / "c20.h5", yeoh[0], c20_curve))
    assert data["attrs"]["parameter"] == "C20"
    assert data["attrs"]["parameter_key"] == "material.parameters.C20"
    assert data["attrs"]["parameter_derivative"] == "central"
    assert data["attrs"]["critical_q"] == c20_curve.critical[0]


def test_jacobian_in_an_energy_parameter_matches_differences(yeoh):
    _, branch, bps = yeoh
    for key in ("material.parameters.C20", "material.parameters.C10"):
        assert jacobian_error(branch, bps[0], key, seed=2) < 1e-8


SINGLE_COIL = SCENES / "spom1_single_coil.toml"


def test_a_scalar_without_derivative_kernel_follows_the_same_curve_as_M():
    """The field term is −½ χ M H² sin θ: with χ = 0.002 and M = 1 the scene is the single-coil scene at
    χM = 0.002, and the curve in χ (a runtime scalar with no derivative kernel: central differences, as a new
    kernel parameter gets) must merge at χ* = M*(χ = 1) = 4.1876946802 (tests/test_two_parameter.py, exact ∂R/∂M)."""
    scene = load_scene(SINGLE_COIL).with_overrides({"continuation.stop_stretch": 2.0, "solver.degree": 60,
                                                    "field.M": 1.0, "field.chi": 0.002})
    branch = trace_primary(scene, down=False)
    bp = bifurcation.locate(branch, *pear_events(branch)[0])
    assert jacobian_error(branch, bp, "chi", seed=2) < 1e-8
    curve = continue_branch_point(branch, bp, "field.chi")
    assert curve.second.derivative == Derivative.CENTRAL and curve.second.key == "field.chi"
    assert curve.end == CurveEnd.ISOLA_MERGE
    assert curve.critical[0] == pytest.approx(4.1876946802, abs=1e-9)


def test_parameter_keys_of_each_kind():
    gent = parse_scene('[material]\npreset = "Gent"\n')
    assert list(parameter_keys(gent)) == ["field.M", "material.parameters.mu", "material.parameters.Jm", "M"]
    keys = parameter_keys(load_scene(SINGLE_COIL))
    assert keys["M"] == "field.M" and keys["chi"] == "field.chi" and "material.mu[2]" in keys and "alpha1" in keys
    assert resolve(gent, "material.parameters.Jm") == "material.parameters.Jm"


def test_unknown_parameter_is_one_line_listing_the_scene_parameters(tmp_path, capsys):
    scene = tmp_path / "gent.toml"
    scene.write_text('[material]\npreset = "Gent"\n[field]\nM = 0.002\n[[field.coils]]\nradius = 4.0\nheight = 0.0\n'
                     'current = 1.0\n')
    with pytest.raises(UnknownParameter, match="material.parameters.Jm"):
        resolve(load_scene(scene), "Jm")
    out = tmp_path / "curve.h5"
    assert main(["critical", str(scene), "--parameter", "Jm", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("balloon-cg: error: ")
    for word in ("'Jm'", "field.M", "field.chi", "material.parameters.mu", "material.parameters.Jm"):
        assert word in err
    assert not out.exists()


def test_an_exponent_on_a_shape_other_than_the_sphere_is_refused_before_any_work(tmp_path, capsys):
    """An Ogden exponent (alpha1, material.alpha[i]) is followed on the general kernel class, committed for the sphere
    only: on a capsule ``critical`` refuses it in one line naming the key, the shape and what is allowed, before
    tracing anything (it traced the primary branch and then failed on the kernel class, before); a modulus resolves."""
    scene = tmp_path / "capsule.toml"
    scene.write_text('[material]\npreset = "SPOM1"\n[geometry]\nshape = "capsule"\nlength = 2.0\n')
    capsule = load_scene(scene)
    for key in ("alpha1", "material.alpha[1]"):
        with pytest.raises(UnknownParameter, match=r"committed for the sphere only: scene capsule is a capsule"):
            resolve(capsule, key)
    assert resolve(capsule, "material.mu[1]") == "material.mu[1]"
    assert resolve(parse_scene('[material]\npreset = "SPOM1"\n'), "alpha1") == "alpha1"
    out = tmp_path / "curve.h5"
    assert main(["critical", str(scene), "--of", "LP", "--parameter", "alpha1", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "'alpha1'" in err and "(allowed: " in err and not out.exists()


def test_critical_C20_from_the_command_line(c20_curve, tmp_path, capsys):
    """`critical` with --set on a shipped scene (the Yeoh preset is the fixture's material) and a strain-energy
    parameter: the same merge as the library call, recorded in the curve file."""
    out = tmp_path / "c20.h5"
    assert main(["critical", "spom1", "--set", "material.preset=Yeoh", "--stop-stretch", "3",
                 "--parameter", "material.parameters.C20", "-o", str(out), "--quiet"]) == 0
    assert capsys.readouterr().out.startswith(f"critical C20 = {c20_curve.critical[0]:.12g} ")
    attrs = read_curve(out)["attrs"]
    assert attrs["parameter_key"] == "material.parameters.C20" and attrs["end"] == "isola_merge"


def test_domain_check_uses_the_parameters_of_the_call():
    """A Gent state with I1 − 3 ≈ 15 (sphere λ = 3) is inside the domain at the scene's Jm = 97.2 and outside it
    at Jm = 10 given through Parameters.material, also right after a call at the scene's Jm at the same u (the
    state cache must not keep the old check)."""
    from dataclasses import replace

    from balloon_cg.galerkin.equilibrium import NonFiniteState

    scene = parse_scene('[material]\npreset = "Gent"\n[continuation]\nstop_stretch = 3.0\n', name="gent")
    branch = trace_primary(scene, down=False)
    eq = equilibrium_of(branch)
    u, P = branch.X[-1, :-1], branch.X[-1, -1]
    params = branch.params.with_value("P", P)
    assert np.abs(eq.residual(u, params)).max() < 1e-8
    with pytest.raises(NonFiniteState, match="left the domain"):
        eq.residual(u, replace(params, material=(2.0, 10.0)))
