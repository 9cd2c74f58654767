"""Fold curves (analysis/critical/fold_curve.py, ``critical --of LP|LV|LN``) against closed forms of the inflated sphere.

At M = 0 the primary branch is the sphere λ1 = λ2 = λ with P = 2Φ1/λ² (Φ1 = ∂Φ/∂λ1 at (λ, λ)). Its pressure folds
satisfy g(λ) = λ(Φ11 + Φ12) − 2Φ1 = 0 (dP/dλ = 0), and the cusp where the maximum and the minimum of P merge
satisfies g = 0 and dg/dλ = 0 as well. Both are derived here by SymPy from Gent's energy typed again below and
solved by mpmath to 30 digits: nothing is taken from the package's closed forms. The gas-control fold (LN) of an
Ogden sphere is the extremum of n ∝ Pλ³: d(Pλ³)/dλ = 2 Σ μ_i α_i (λ^(α_i − 1) + 2λ^(−2α_i − 1)) = 0. No sphere has
a fold in V (LV): its curve is checked against the folds located on plain branches traced at the curve's values.
"""
import json

import mpmath
import numpy as np
import pytest
import sympy as sp

from balloon_cg.app.cli import main
from balloon_cg.analysis.critical.pitchfork_curve import CurveEnd
from balloon_cg.analysis.critical.fold_curve import FoldSystem, continue_fold
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.results import Block, Kind, Status
from balloon_cg.analysis.critical.second_parameter import second_parameter
from balloon_cg.io.curve_file import read_curve
from balloon_cg.scene import Control, load_scene, parse_scene

GENT = '[material]\npreset = "Gent"\n[continuation]\nstart_stretch = 1.01\nmin_stretch = 1.005\nstop_stretch = 5.0\n'
SOFT = ('[material]\nmu = [3.0, 0.0145, 0.06]\nalpha = [1.3, 4.0, -2.0]\n[continuation]\nstop_stretch = 4.0\n'
        '[stability]\nm_max = 0\n[loading]\ncontrol = "gas"\n')

lam, Jm, l1, l2 = sp.symbols("lam Jm l1 l2", positive=True)


def gent_closed_forms():
    """(P(λ, Jm), g(λ, Jm)) of Gent's Φ = −Jm ln(1 − (I1 − 3)/Jm) (μ = 2) on the sphere, as SymPy expressions."""
    phi = -Jm * sp.log(1 - (l1**2 + l2**2 + (l1 * l2) ** -2 - 3) / Jm)
    d1 = sp.diff(phi, l1)
    at = {l1: lam, l2: lam}
    phi1, S = d1.subs(at), (sp.diff(d1, l1) + sp.diff(d1, l2)).subs(at)
    return 2 * phi1 / lam**2, lam * S - 2 * phi1


@pytest.fixture(scope="module")
def gent_curve():
    scene = parse_scene(GENT, "gent")
    branch = trace_primary(scene)
    maximum = next(s for s in branch.special if s.kind == Kind.LP)
    return continue_fold(branch, maximum, "material.parameters.Jm", direction=-1.0)


def test_gent_cusp_against_the_closed_form(gent_curve):
    """The LP curve from Jm = 97.2 down: it turns back at the cusp (g = dg/dλ = 0), located to 1e-8 in Jm and in
    λ, and comes back along the minimum of P to Jm = 97.2 (the partner fold)."""
    pressure, g = gent_closed_forms()
    mpmath.mp.dps = 30
    lam_c, Jm_c = sp.nsolve([g, sp.diff(g, lam)], [lam, Jm], [1.6, 18.0], prec=30)
    curve = gent_curve
    assert curve.end == CurveEnd.CUSP and curve.stop.code.value == "partner"
    assert curve.merge.status == Status.LOCATED and len(curve.merges) == 1
    q, P, stretch = curve.critical
    assert abs(q - float(Jm_c)) < 1e-8 and abs(stretch - float(lam_c)) < 1e-8
    assert abs(P - float(pressure.subs({lam: lam_c, Jm: Jm_c}))) < 1e-8
    lam_top = curve.pole_stretch
    assert lam_top[0] < float(lam_c) < lam_top[-1]  # from the maximum of P, back along the minimum


def test_every_gent_fold_point_satisfies_the_closed_form(gent_curve):
    """At every point of the curve, at its own Jm: the state is the sphere (both poles at λ), g(λ) = 0 to 1e-9 of
    its terms' scale and P is the sphere's pressure to 1e-10."""
    pressure, g = gent_closed_forms()
    P_of, g_of = sp.lambdify((lam, Jm), pressure), sp.lambdify((lam, Jm), g)
    scale = sp.lambdify((lam, Jm), 2 * lam**2 * pressure / 2)  # 2Φ1: the size of the terms of g
    curve = gent_curve
    poles = curve.pole_values()
    assert np.abs(poles["lam2_bottom"] - poles["lam2_top"]).max() < 1e-12
    lams, q = poles["lam2_top"], curve.q
    assert len(q) > 50 and q.min() < 17.65 and q.max() <= 97.2
    assert np.abs(g_of(lams, q) / scale(lams, q)).max() < 1e-9
    assert np.abs(curve.pressure / P_of(lams, q) - 1).max() < 1e-10


@pytest.fixture(scope="module")
def soft_ln_curve():
    """(scene, the LN fold curve of the soft Ogden sphere followed in μ3 downward, 30 points at most)."""
    scene = parse_scene(SOFT, "soft")
    branch = trace_primary(scene)
    fold = next(s for s in branch.special if s.kind == Kind.LN)
    return scene, continue_fold(branch, fold, "material.mu[2]", direction=-1.0, max_points=30)


def soft_mu3_on_the_ln_curve(stretch):
    """μ3 of the soft material's LN fold at the sphere's stretch λ: Σ μ_i α_i (λ^(α_i − 1) + 2λ^(−2α_i − 1)) = 0."""
    mu, alpha = [mpmath.mpf(3.0), mpmath.mpf(0.0145)], [mpmath.mpf(1.3), mpmath.mpf(4), mpmath.mpf(-2)]
    terms = [a * (stretch ** (a - 1) + 2 * stretch ** (-2 * a - 1)) for a in alpha]
    return -(mu[0] * terms[0] + mu[1] * terms[1]) / terms[2]


def test_gas_fold_curve_against_the_extremum_of_P_lambda3(soft_ln_curve):
    """The LN fold (gas control) of a soft Ogden sphere followed in μ3: d(Pλ³)/dλ = 0 at every point, at its own
    μ3, to 1e-9 relative; the tangent's pressure part μ is not zero (this is not a fold in P)."""
    scene, curve = soft_ln_curve
    mu, alpha = np.array(scene.material.mu), np.array(scene.material.alpha)
    lams = curve.pole_stretch
    assert len(lams) >= 20
    for lam_i, mu3 in zip(lams, curve.q):
        mu_i = np.append(mu[:2], mu3)
        terms = 2 * mu_i * alpha * (lam_i ** (alpha - 1) + 2 * lam_i ** (-2 * alpha - 1))
        assert abs(terms.sum()) < 1e-9 * np.abs(terms).max()
    assert np.abs(curve.mode[:, curve.n]).min() > 1e-3


def n4_bifurcation_on_the_ln_curve(stretch):
    """The sphere's n = 4 bifurcation condition Δ_4 = Φ11² − Φ12² + t(19 Φ11 + 3 Φ12) − 2t² (t = Φ1/λ,
    docs/sphere_bifurcation.md §7, written out here for Ogden) at the soft material's LN fold of stretch λ."""
    mu12, alpha = [mpmath.mpf(3.0), mpmath.mpf(0.0145)], [mpmath.mpf(1.3), mpmath.mpf(4), mpmath.mpf(-2)]
    mu = mu12 + [soft_mu3_on_the_ln_curve(stretch)]
    phi1 = sum(m * (stretch ** (a - 1) - stretch ** (-2 * a - 1)) for m, a in zip(mu, alpha))
    phi11 = sum(m * ((a - 1) * stretch ** (a - 2) + (a + 1) * stretch ** (-2 * a - 2)) for m, a in zip(mu, alpha))
    phi12 = sum(m * a * stretch ** (-2 * a - 2) for m, a in zip(mu, alpha))
    t = phi1 / stretch
    return phi11**2 - phi12**2 + t * (19 * phi11 + 3 * phi12) - 2 * t**2


def test_the_soft_ln_curve_meets_the_sphere_s_n4_bifurcation():
    """Why the LN curve below stopped near μ3 = 0.0467 (session 24): along it (μ3(λ) from d(Pλ³)/dλ = 0,
    ``soft_mu3_on_the_ln_curve``) the sphere's n = 4 bifurcation condition Δ_4 (``n4_bifurcation_on_the_ln_curve``)
    changes sign at λ* = 3.56181, μ3* = 0.046520. There J_u has the n = 4 mode as a null vector orthogonal to R_P
    (an n = 0 field), so F_x = [J_u  R_P] loses rank and the fold system is singular: its condition grows on
    approach (5e4 at μ3 = 0.06, 5e7 at 0.04674), and its Newton corrections stagnate above solver.tol."""
    mpmath.mp.dps = 30
    assert n4_bifurcation_on_the_ln_curve(mpmath.mpf(3.13)) < 0 < n4_bifurcation_on_the_ln_curve(mpmath.mpf(4.5))
    crossing = mpmath.findroot(n4_bifurcation_on_the_ln_curve, mpmath.mpf(3.56))
    assert abs(crossing - mpmath.mpf("3.5618137193")) < 1e-9
    assert abs(soft_mu3_on_the_ln_curve(crossing) - mpmath.mpf("0.0465201119")) < 1e-9


def test_gas_fold_curve_reaches_below_mu3_0_03(soft_ln_curve):
    """The same LN fold curve followed in μ3 goes on down to μ3 < 0.03 in 30 points (the closed form μ3(λ) falls
    smoothly, 0.0468 at λ = 3.55, 0.0314 at λ = 4.5) past the singular point of the fold system above: its
    corrector is ILL_CONDITIONED there and the trace steps across it (numerics/continuation.py; opted in by
    analysis/critical's curve_settings) instead of halving its step to the minimum (session 24's defect: the
    curve stopped at μ3 ≈ 0.0467 after ~25 points). Every point, on both sides, is on the closed form
    (test_gas_fold_curve_against_the_extremum_of_P_lambda3)."""
    _, curve = soft_ln_curve
    lams = curve.pole_stretch
    assert len(lams) == 30 and curve.q.min() < 0.03
    assert lams.min() < 3.5618137193 - 0.01 and lams.max() > 3.5618137193 + 0.3


def test_the_ln_curve_s_crossing_of_the_n4_bifurcation_is_a_special_point(soft_ln_curve, tmp_path, capsys):
    """The crossing above is the curve's one meeting: LN-BP, block even, between the two curve points that bracket
    λ* (fold_crossing.py). It is APPROXIMATE (the fold system's corrector fails within ~1e-3 of it): the closed
    form's λ* lies within its bracket, |λ − λ*| ≤ 2·uncertainty (the half-width in λ2(0) and P; measured: 1.3e-3
    from λ*, ±1.3e-3; the bound 5e-3 leaves the corrector's failure zone room to double on another BLAS build,
    under an eighth of the bracketing curve points' 0.038), and the stored point is on the LN curve's closed form
    μ3(λ) to 1e-9. Stored in the curve
    file as a special point of kind LN-BP, shown by ``inspect`` and in the curve's description."""
    from balloon_cg.io.curve_file import curve_meetings, write_curve

    mpmath.mp.dps = 30
    scene, curve = soft_ln_curve
    lam_star = float(mpmath.findroot(n4_bifurcation_on_the_ln_curve, mpmath.mpf(3.56)))
    [crossing] = curve.meetings
    assert (crossing.kind, crossing.block, crossing.status) == (Kind.LN_BP, Block.EVEN, Status.APPROXIMATE)
    lams = curve.pole_stretch
    assert lams[crossing.index] < lam_star < lams[crossing.index + 1]
    lam_c, mu3_c = float(curve.pole_values(crossing.X)["lam2_top"][0]), float(crossing.X[-1])
    assert abs(lam_c - lam_star) <= 2 * crossing.uncertainty and crossing.uncertainty < 5e-3
    assert abs(mu3_c - float(soft_mu3_on_the_ln_curve(mpmath.mpf(lam_c)))) < 1e-9
    assert f"the LN fold meets a branch point at mu[2] = {mu3_c:.10g}" in curve.describe()
    out = write_curve(tmp_path / "ln.h5", scene, curve, name="LN")
    [stored] = curve_meetings(read_curve(out, "LN"))
    assert stored["kind"] == "LN-BP" and stored["q"] == mu3_c and stored["status"] == "approximate"
    assert main(["inspect", str(out)]) == 0
    assert f"LN-BP meeting        mu[2] = {mu3_c:.12g}" in capsys.readouterr().out


def test_only_two_parameter_curves_accept_the_rounding_floor():
    """The rounding rule and the step across (numerics/continuation.py) are opted in by analysis/critical's curves
    alone (rounding_limit = solver.max_error); every one-parameter trace keeps 0 (the rule off: main's code path)."""
    from balloon_cg.analysis.branches.problem import continuation_settings
    from balloon_cg.analysis.critical.pitchfork_curve import curve_settings

    scene = parse_scene(SOFT, "soft")
    assert continuation_settings(scene).rounding_limit == 0.0
    assert curve_settings(scene, 30).rounding_limit == scene.solver.max_error > 0
    assert curve_settings(scene, 30).max_points == 30


def test_pressure_fold_in_alpha1_uses_runtime_exponents():
    """SPOM1's maximum of P followed in α1 (μ1 = (4 − Σ_{i≥2} μ_i α_i)/α1: kernels with the exponents as runtime
    arguments): at every point dP/dλ = Σ μ_i ((α_i − 3)λ^(α_i − 4) + (2α_i + 3)λ^(−2α_i − 4)) = 0 at its own α1
    (written out here), to 1e-9 of its terms."""
    scene = parse_scene('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 2.0\n', "spom1")
    branch = trace_primary(scene, down=False)
    fold = next(s for s in branch.special if s.kind == Kind.LP)
    curve = continue_fold(branch, fold, "alpha1", max_points=12)
    mu, alpha = np.array(scene.material.mu), np.array(scene.material.alpha)
    assert curve.q.max() > alpha[0] + 0.05
    for lam_i, a1 in zip(curve.pole_stretch, curve.q):
        a = np.append(a1, alpha[1:])
        m = np.append((4 - mu[1:] @ alpha[1:]) / a1, mu[1:])
        terms = m * ((a - 3) * lam_i ** (a - 4) + (2 * a + 3) * lam_i ** (-2 * a - 4))
        assert abs(terms.sum()) < 1e-9 * np.abs(terms).max()


def test_volume_fold_curve_in_M_against_plain_branches():
    """The paper's single coil under volume control has a fold in V (LV, after the TP of λ2(0)); followed in M, the
    curve's pressure at two of its M values equals the LV fold located on the primary branch traced at that M
    (a plain continuation and Brent on dV/ds: another method) to 1e-10."""
    scene = load_scene("spom1_paper_coil").with_overrides({"loading.control": "volume"}, name="paper_coil")
    branch = trace_primary(scene)
    fold = next(s for s in branch.special if s.kind == Kind.LV)
    curve = continue_fold(branch, fold, "M", max_points=7)
    assert curve.q[-1] > 2 * curve.q[0]
    for i in (3, 6):
        again = trace_primary(scene.with_overrides({"field.M": float(curve.q[i])}, name="paper_coil"))
        [located] = [s for s in again.special if s.kind == Kind.LV]
        assert located.status == Status.LOCATED and abs(located.X[-1] - curve.pressure[i]) < 1e-10


@pytest.mark.parametrize("control", list(Control))
def test_fold_system_jacobian_is_the_derivative_of_its_residual(control):
    """The extended system's Jacobian (second derivatives by central differences of F_x) against central
    differences of its residual, for every control, at a point of the Gent branch with an arbitrary w."""
    scene = parse_scene(GENT, "gent")
    branch = trace_primary(scene, stop_stretch=2.0, down=False)
    eq = equilibrium_of(branch)
    parameter = second_parameter(scene, eq, branch.params, "material.parameters.Jm")
    rng = np.random.default_rng(0)
    n = branch.disc.size
    w = rng.standard_normal(n + 1)
    system = FoldSystem(eq, branch.params, parameter, control, w / np.linalg.norm(w))
    X = np.concatenate([branch.X[len(branch.X) // 2], w, [80.0]])
    J = system.jacobian(X)
    numeric = np.empty_like(J)
    for k in range(X.size):
        h = 1e-6 * max(1.0, abs(X[k]))
        e = np.zeros(X.size)
        e[k] = h
        numeric[:, k] = (system.residual(X + e) - system.residual(X - e)) / (2 * h)
    assert np.abs(J - numeric).max() < 1e-6 * max(1.0, np.abs(J).max())


def test_critical_of_LP_from_the_command_line(tmp_path, capsys):
    """`critical --of LP`: the cusp printed (exit 0), `inspect --json` shows of, end = cusp and critical_q;
    `plot --what phase` draws it; an --of outside the allowed set is one error line naming them (exit 2)."""
    scene = tmp_path / "gent.toml"
    scene.write_text(GENT)
    out = tmp_path / "lp.h5"
    assert main(["critical", str(scene), "--of", "LP", "--parameter", "material.parameters.Jm", "--direction", "-1",
                 "-o", str(out), "--quiet"]) == 0
    assert capsys.readouterr().out.startswith("critical Jm = 17.63808007")
    assert main(["inspect", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)["curves"]["LP"]
    assert summary["of"] == "LP" and summary["end"] == "cusp"
    assert summary["critical_q"] == pytest.approx(17.6380800759137, abs=1e-9)
    assert read_curve(out, "LP")["special_points"][0]["status"] == "located"
    assert main(["plot", str(out), "--what", "phase", "-o", str(tmp_path / "phase.png")]) == 0
    capsys.readouterr()
    with pytest.raises(SystemExit) as error:
        main(["critical", str(scene), "--of", "LX", "--parameter", "Jm", "-o", str(tmp_path / "x.h5")])
    assert error.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "--of" in err and "'LX'" in err and "LP" in err and "LN" in err
    assert not (tmp_path / "x.h5").exists()


def test_phase_diagram_shades_between_the_upper_and_the_lower_fold(tmp_path, capsys):
    """Gent's two pressure folds (the maximum and the minimum of P) each continued in Jm upward from its label: two
    curves that never meet (the cusp is below, Jm = 17.6). `plot --what phase` of both shades the bistable region
    between them over the Jm both span, bounded by the two curves (through every stored point); one curve alone is
    drawn without shading."""
    from balloon_cg.io.run_file import read_run
    from balloon_cg.post.plotting import plot

    scene = tmp_path / "gent.toml"
    scene.write_text(GENT + "max_points = 80\n")
    run = tmp_path / "gent.h5"
    assert main(["run", str(scene), "--primary-only", "-o", str(run), "--quiet"]) == 0
    labels = [s["label"] for s in read_run(run)["branches"]["primary"]["special_points"] if s["kind"] == "LP"]
    assert len(labels) == 2
    curves = [tmp_path / f"fold{label}.h5" for label in labels]
    for label, out in zip(labels, curves):
        assert main(["continue", str(run), str(label), "--parameter", "material.parameters.Jm", "-o", str(out),
                     "--quiet"]) == 0
    capsys.readouterr()
    (q1, P1), (q2, P2) = [(read_curve(out, "LP")["q"], read_curve(out, "LP")["pressure"]) for out in curves]
    assert np.all(np.diff(q1) > 0) and np.all(np.diff(q2) > 0) and P2[0] < P1[0]
    [shaded] = plot(curves, "phase").axes[0].collections
    assert shaded.get_label() == "bistable: snap-through between the two LP curves"
    q, P = shaded.get_paths()[0].vertices.T
    high = min(q1[-1], q2[-1])
    assert q.min() == pytest.approx(97.2, abs=1e-9) and q.max() == pytest.approx(high, rel=1e-12)
    for qs, Ps in ((q1, P1), (q2, P2)):  # every stored point of either curve in the overlap is on the boundary
        inside = qs <= high
        distance = np.hypot((q[:, None] - qs[inside]) / np.ptp(q), (P[:, None] - Ps[inside]) / np.ptp(P)).min(axis=0)
        assert distance.max() < 1e-12
    assert not plot(curves[:1], "phase").axes[0].collections


def test_phase_diagram_refuses_curves_of_two_parameters(gent_curve, tmp_path):
    """Curves in two second parameters (Gent's fold in Jm, SPOM1's in α1) have no common q axis: `plot --what
    phase` of both is one line naming each parameter and its curves (they were drawn on one axis labelled q);
    each alone draws."""
    from balloon_cg.io.curve_file import write_curve
    from balloon_cg.post.plotting import PlotError, plot

    spom1 = parse_scene('[material]\npreset = "SPOM1"\n[continuation]\nstop_stretch = 2.0\n', "spom1")
    branch = trace_primary(spom1, down=False)
    alpha1 = continue_fold(branch, next(s for s in branch.special if s.kind == Kind.LP), "alpha1", max_points=5)
    jm = write_curve(tmp_path / "jm.h5", parse_scene(GENT, "gent"), gent_curve, name="LP")
    a1 = write_curve(tmp_path / "a1.h5", spom1, alpha1, name="LP")
    with pytest.raises(PlotError) as error:
        plot([jm, a1], "phase")
    message = str(error.value)
    assert "\n" not in message and "material.parameters.Jm (jm: LP)" in message and "alpha1 (a1: LP)" in message
    assert "Jm" in plot([jm], "phase").axes[0].get_xlabel()
    assert "alpha_1" in plot([a1], "phase").axes[0].get_xlabel()
