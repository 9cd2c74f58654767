"""One name per parameter (issue 40): ``alpha1`` (α1 with μ1 keeping Σ μ_i α_i = 4) means the same family in
``--set``, ``sweep --vary`` and ``critical --parameter``; grids are the decimals written; a curve file's coordinate
is named after its parameter."""
from fractions import Fraction

import numpy as np
import pytest

from balloon_cg.analysis.points import branch_points as bifurcation
from balloon_cg.analysis.critical.pitchfork_curve import continue_branch_point, land_on_q
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.app.cli import main
from balloon_cg.app.sweep import grid, parse_vary, run_sweep
from balloon_cg.scene import SceneError, load_scene
from pitchforks import pear_events


@pytest.fixture(scope="module")
def scene():
    return load_scene("spom1").with_overrides({"continuation.stop_stretch": 3.0, "surface.branches": "none"})


def ogden_sphere_pressure(mu, alpha, lam):
    """P = 2Φ1/λ² of the inflated sphere λ1 = λ2 = λ, λ3 = λ⁻²: Φ1 = Σ μ_i (λ^(α_i−1) − λ^(−2α_i−1))."""
    return 2 * sum(m * (lam ** (a - 1) - lam ** (-2 * a - 1)) for m, a in zip(mu, alpha)) / lam**2


def test_set_alpha1_is_the_family_of_critical(scene, capsys):
    """``--set alpha1=1.4``: α1 = 1.4 with μ1 = (4 − Σ_{i≥2} μ_i α_i)/1.4; the sphere's pressure at λ = 2 (solve)
    is the closed form's for those terms, not the one with μ1 kept (``material.alpha[0]``)."""
    member = scene.with_overrides({"alpha1": 1.4})
    rest = sum(m * a for m, a in zip(scene.material.mu[1:], scene.material.alpha[1:]))
    assert member.material.alpha == (1.4,) + scene.material.alpha[1:]
    assert member.material.mu[0] == pytest.approx((4 - rest) / 1.4, rel=1e-15)
    assert member.material.shear_modulus_sum == pytest.approx(4.0, rel=1e-15)
    assert main(["solve", "spom1", "--set", "alpha1=1.4", "--pole-stretch", "2", "--json"]) == 0
    import json
    P = json.loads(capsys.readouterr().out)["pressure"]
    assert P == pytest.approx(ogden_sphere_pressure(member.material.mu, member.material.alpha, 2.0), rel=1e-10)
    kept = scene.with_overrides({"material.alpha": [1.4, 4.0, -2.0]})  # sweep's material.alpha[0] = 1.4
    assert abs(P - ogden_sphere_pressure(kept.material.mu, kept.material.alpha, 2.0)) > 1e-2


def test_alpha1_errors_name_the_key(scene, capsys):
    """A strain energy has no α1; a mistyped bare name gets the nearest key, not the advice to add a table."""
    gent = scene.with_overrides({"material.preset": "Gent"})
    with pytest.raises(SceneError, match="alpha1 = 1.4: the first Ogden exponent .* not an Ogden material"):
        gent.with_overrides({"alpha1": 1.4})
    with pytest.raises(SceneError, match="alpha1 = 0: exponents must be nonzero"):
        scene.with_overrides({"alpha1": 0})
    assert main(["solve", "spom1", "--set", "alpa1=1.4", "--pole-stretch", "2"]) == 2
    err = capsys.readouterr().err
    assert "--set alpa1: not a scene key (did you mean alpha1?)" in err and "TABLE" not in err


def test_grid_values_are_the_decimals_written(scene):
    """1.2:1.4:3 is 1.2, 1.3, 1.4 (numpy's linspace gives 1.2999999999999998), and every grid value is the float
    nearest the exact rational start + (stop − start)·i/(n − 1)."""
    assert parse_vary("alpha1=1.2:1.4:3", scene) == ("alpha1", [1.2, 1.3, 1.4])
    assert np.linspace(1.2, 1.4, 3)[1] != 1.3  # what the old grid stored
    values = grid(Fraction("0.1"), Fraction("0.7"), 7)
    assert values == [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]
    assert grid(Fraction(0), Fraction(1), 3) == [0.0, 0.5, 1.0] and grid(Fraction(2), Fraction(2), 1) == [2.0]
    for k, v in enumerate(grid(Fraction(0), Fraction(1), 4)):  # no neighbouring float is nearer k/3
        error = abs(Fraction(v) - Fraction(k, 3))
        assert all(error <= abs(Fraction(float(np.nextafter(v, side))) - Fraction(k, 3)) for side in (-1, 2))


@pytest.fixture(scope="module")
def alpha1_files(scene, tmp_path_factory):
    """A sweep of alpha1 over 1.2:1.4:3 (no pear branches) and the α1 curve of pear pitchforks traced from the
    scene's first pitchfork (α1 = 1.3): (sweep path, curve file path, curve, branch)."""
    from balloon_cg.io.curve_file import write_curve

    folder = tmp_path_factory.mktemp("alpha1")
    run_sweep(scene, ["alpha1=1.2:1.4:3"], folder / "sweep.h5", mode="no-pear", workers=1)
    branch = trace_primary(scene, down=False)
    bp = bifurcation.locate(branch, *pear_events(branch)[0])
    curve = continue_branch_point(branch, bp, "alpha1")
    return folder / "sweep.h5", write_curve(folder / "curve.h5", scene, curve), curve, branch


def test_sweep_in_alpha1_meets_the_critical_curve(alpha1_files):
    """The acceptance test: the pear pitchfork of the sweep member α1 = 1.4 and the point of the α1 curve of
    pitchforks (``critical --parameter alpha1``, traced from the scene's α1 = 1.3) landed on α1 = 1.4 have the same
    P to 1e-8; the sweep's grid value prints as written."""
    import balloon_cg as bc

    sweep, _, curve, branch = alpha1_files
    table = bc.load(sweep).to_dataframe()
    assert list(table["alpha1"]) == [1.2, 1.3, 1.4] and str(table.loc[1, "alpha1"]) == "1.3"
    near = int(np.argmax(curve.q >= 1.4))
    X = land_on_q(curve, 1.4, near)
    assert X is not None and X[-1] == 1.4
    assert abs(X[branch.disc.size] - table.loc[2, "P_cr1"]) < 1e-8
    assert abs(table.loc[2, "P_cr1"] - 2.2224) < 1e-4  # not the μ1-kept family's ≈ 2.39 (issue 40)


def test_loaded_sweeps_and_curves_plot_on_one_parameter_axis(alpha1_files):
    """``bc.plot(bc.load(sweep))`` and a CurveResult draw (their kind: phase), together on the one α1 axis: the
    sweep's three pitchfork pressures and the curve; anything else is one PlotError line, not a TypeError."""
    import balloon_cg as bc
    from balloon_cg.post.plotting import PlotError

    sweep, path, curve, _ = alpha1_files
    for source in (bc.load(sweep), bc.load(path), sweep):
        assert "alpha_1" in bc.plot(source).axes[0].get_xlabel()
    ax = bc.plot([bc.load(sweep), bc.load(path)]).axes[0]
    drawn = [line for line in ax.get_lines() if "pear pitchfork" in line.get_label()]
    assert len(drawn) == 1 and list(drawn[0].get_xdata()) == [1.2, 1.3, 1.4]
    assert any(len(line.get_xdata()) == len(curve.q) for line in ax.get_lines())
    with pytest.raises(PlotError, match="plot draws a Result, a loaded sweep or curve .* got int"):
        bc.plot(42)
