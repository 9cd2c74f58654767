"""Tuning curves: ``continue RUN LABEL --parameter M`` follows a point in the field M at its fixed P (app/restart.py
``restart_in``), with the natural frequencies along it (docs/dynamics.md), against independent checks.

The two-coil scene (SPOM1 between the paper's opposed coils) at M = 0.002 has a user point at P = 2.5 on the rising
primary branch (below its fold at P = 2.555). Followed in M at P = 2.5 the state goes up to the M where the
branch's fold in P reaches 2.5 (there a fold in M, LP: the breathing mode's Ω² vanishes) and back down on the
falling side of the branch to M = 0, where both ends are the field-free SPOM1 spheres of P = 2.5: their Ω² are
the closed forms of tests/test_dynamics.py (the breathing mode Ω² = (φ''(λ) − 2Pλ)/2 and the degree-n spheroidal
modes of the linearised membrane equations), at the two roots λ of P(λ) = 2.5 either side of the pressure maximum,
and the toroidal modes, which the m ≥ 1 blocks hold (their δφ):

Toroidal modes of degree n (derived here). u = V(θ) e_φ, V = dP_n(cos θ)/dθ, on the sphere of radius λ:
x = λ e_r + εV e_φ, x_θ = λ e_θ + εV' e_φ, x_φ/sin θ = λ e_φ − εV (e_r + cot θ e_θ), so the Cauchy–Green tensor in
(e_θ, e_φ) is C = λ² I + ελ s [[0, 1], [1, 0]] + ε² diag(V'², V²/sin²θ), s = V' − V cot θ. Its eigenvalues are
λ² ± ελs + ε² d + O(ε³), d = (V'² + V²/sin²θ)/2, so λ1,2 = λ ± εs/2 + ε² (d − s²/4)/(2λ) and the ε² part of Φ is
Φ1 (d − s²/4)/λ + (Φ11 − Φ12) s²/4. The volume per 2π, (1/3)∫ x·(x_θ × x_φ) dθ, has the ε² part
(λ/3)∫(V V' cos θ + V² sin θ) dθ = (λ/2)∫ V² sin θ dθ (by parts). K = 2 × the ε² part of ∫Φ sin θ dθ − P V/2π,
M = ∫ V² sin θ dθ, Ω² = K/(2M); in x = cos θ: V = −sin θ P_n'(x), s = sin²θ P_n''(x), V' = −x P_n' + sin²θ P_n'',
polynomials integrated exactly by Gauss–Legendre. n = 1 is the rigid rotation (Ω² = 0, removed by the blocks).
"""
from pathlib import Path

import numpy as np
import pytest
from numpy.polynomial import legendre
from scipy import optimize

import balloon_cg as bc
from balloon_cg.app.cli import main
from test_dynamics import breathing, phi_derivatives, pressure, pressure_maximum, spheroidal

ROOT = Path(__file__).resolve().parent.parent
P0 = 2.5
EXTRA = f"""
[dynamics]
frequencies = true
count = 2
m_max = 2

[[events]]
quantity = "pressure"
value = {P0}
"""
STEPS = ["--set", "continuation.step=0.005", "--set", "continuation.step_max=0.01"]
HELD = ("even", "odd_held", "m1_held", "m2_held")


def scene_file(folder: Path, M: float | None = None) -> Path:
    """The shipped two-coil scene to a pole stretch of 1.55 with [dynamics] and a user point at P = P0 (and M)."""
    text = (ROOT / "scenes" / "spom1_two_coils_M0.002.toml").read_text().replace("stop_stretch = 5.0",
                                                                                  "stop_stretch = 1.55")
    if M is not None:
        text = text.replace("M = 0.002", f"M = {M!r}")
    path = folder / ("two_coils.toml" if M is None else "two_coils_M.toml")
    path.write_text(text + EXTRA)
    return path


def rising_user_point(run) -> dict:
    """The user point (UZ) at P0 on the rising side of a run's primary branch (the first)."""
    return next(s for s in run.special_points if s["kind"] == "UZ")


@pytest.fixture(scope="module")
def tuning(tmp_path_factory):
    """The primary branch at M = 0.002 (primary only), and the branch through its rising user point in M."""
    folder = tmp_path_factory.mktemp("tuning")
    run = folder / "run.h5"
    assert main(["run", str(scene_file(folder)), "--primary-only", "--quiet", "-o", str(run)]) == 0
    label = rising_user_point(bc.load(run))["label"]
    curve = folder / "curve.h5"
    assert main(["continue", str(run), str(label), "--parameter", "M", "--quiet", "-o", str(curve), *STEPS]) == 0
    return folder, bc.load(curve)


def toroidal(name, lam, P, n) -> float:
    """Ω² of the degree-n toroidal mode of the sphere of radius λ at pressure P (module docstring)."""
    phi1, phi11, phi12 = (float(d[0]) for d in phi_derivatives(name, lam)[:3])
    x, weights = legendre.leggauss(2 * n + 8)
    c = np.zeros(n + 1)
    c[n] = 1.0
    dp, ddp = (legendre.legval(x, legendre.legder(c, k)) for k in (1, 2))
    sin2 = 1 - x * x
    V2, s = sin2 * dp * dp, sin2 * ddp
    d = ((-x * dp + sin2 * ddp) ** 2 + dp * dp) / 2
    stiffness = 2 * weights @ (phi1 / lam * (d - s * s / 4) - P * lam / 2 * V2 + (phi11 - phi12) * s * s / 4)
    return stiffness / (2 * weights @ V2)


def sphere_stretches() -> list:
    """The two SPOM1 spheres of pressure P0: the roots of P(λ) = P0 below and above the pressure maximum."""
    top = pressure_maximum("SPOM1")
    return [optimize.brentq(lambda lam: float(pressure("SPOM1", lam)[0]) - P0, a, b, xtol=1e-15, rtol=1e-15)
            for a, b in ((1.01, top), (top, 6.0))]


def test_the_curve_in_M_turns_at_a_fold_and_ends_at_the_field_free_spheres(tuning):
    """Both ends land on M = 0 (the stop ``zero_field``), between them one fold in M (LP, located), P = P0
    throughout; the ends are the two spheres of P0 (their pole stretch λ to 1e-9: the sphere's closed form
    P(λ) = φ'(λ)/λ²)."""
    _, curve = tuning
    data = curve.branches["primary"].data
    assert data["attrs"]["parameter"] == "M"
    assert list(curve.branches["primary"].data["attrs"]["leg_stop_codes"]) == ["zero_field", "zero_field"]
    assert data["M"][0] == pytest.approx(0.0, abs=1e-12) and data["M"][-1] == pytest.approx(0.0, abs=1e-12)
    assert np.all(data["pressure"] == data["pressure"][0]) and abs(data["pressure"][0] - P0) < 1e-9
    folds = [s for s in data["special_points"] if s["kind"] == "LP"]
    assert len(folds) == 1 and folds[0]["status"] == "located" and folds[0]["M"] > 0.005
    np.testing.assert_allclose(sorted(data["lam2_top"][[0, -1]]), sphere_stretches(), rtol=0, atol=1e-9)


def test_at_M_zero_the_frequencies_are_the_field_free_spheres(tuning):
    """At each M = 0 end the breathing mode (the even block's lowest) is (φ''(λ) − 2Pλ)/2 at that sphere, and every
    stored Ω² of the held blocks is one of the sphere's closed forms (breathing, spheroidal and toroidal n ≤ 8), to
    1e-9: the sphere's modes are Legendre polynomials of degree ≤ 8, exact at the branch's degree (observed
    1.3e-10: the state is the sphere to the solver's tolerance); the toroidal n = 2 value is among them (the
    m1_held and m2_held blocks' second)."""
    _, curve = tuning
    data = curve.branches["primary"].data
    for end in (0, -1):
        lam = float(data["lam2_top"][end])
        forms = np.concatenate([[float(breathing("SPOM1", lam, P0)[0])]]
                               + [spheroidal("SPOM1", lam, P0, n) for n in range(1, 9)]
                               + [[toroidal("SPOM1", lam, P0, n) for n in range(2, 9)]])
        assert abs(data["frequencies"]["even"][end, 0] - forms[0]) <= 1e-9
        stored = np.concatenate([data["frequencies"][block][end] for block in HELD])
        assert np.abs(stored[:, None] - forms[None, :]).min(axis=1).max() <= 1e-9, (end, stored)
        assert np.abs(stored - toroidal("SPOM1", lam, P0, 2)).min() <= 1e-9


def test_the_fold_in_M_is_a_zero_of_the_breathing_frequency(tuning):
    """At the located fold in M (LP) the even block's lowest Ω² is zero to the solver tolerance 1e-11, and it
    changes sign between the points around it (stable below the fold on the rising side, unstable past it)."""
    _, curve = tuning
    data = curve.branches["primary"].data
    n, fold = next((n, s) for n, s in enumerate(data["special_points"]) if s["kind"] == "LP")
    assert abs(data["special_frequencies"]["even"][n, 0]) <= 1e-11
    around = data["frequencies"]["even"][fold["index"]:fold["index"] + 2, 0]
    assert around[0] > 0 > around[1]


def test_a_point_of_the_curve_is_the_scenes_state_at_that_M(tuning):
    """A point of the curve on its rising side, at M = M_k, against a run of the scene at field.M = M_k: its user
    point at P0 on the rising primary branch has the same frequencies in every block, to 1e-9 (two Newton
    solutions of the same equations to 1e-11 on bases of different degree and map, each resolving its
    frequencies to ~1e-11: docs/dynamics.md's convergence table; observed 2e-12)."""
    folder, curve = tuning
    data = curve.branches["primary"].data
    k = int(np.flatnonzero(data["M"] > 0.005)[0])
    assert data["frequencies"]["even"][k, 0] > 0  # before the fold
    other = folder / "at_M.h5"
    assert main(["run", str(scene_file(folder, float(data["M"][k]))), "--primary-only", "--quiet", "-o",
                 str(other)]) == 0
    run = bc.load(other)
    n = next(n for n, s in enumerate(run.special_points) if s["kind"] == "UZ")
    stored = run.branches["primary"].data["special_frequencies"]
    for block, values in data["frequencies"].items():
        np.testing.assert_allclose(stored[block][n], values[k], rtol=0, atol=1e-9, err_msg=block)


def test_plot_draws_the_frequencies_against_M(tuning, tmp_path):
    """``plot --what frequencies`` on the curve's file: Ω² against M, the fold marked at Ω² = 0."""
    from balloon_cg.post.plotting import plot

    folder, curve = tuning
    fig = plot([folder / "curve.h5"], "frequencies")
    ax = fig.axes[0]
    assert "M" in ax.get_xlabel()
    lines = [line for line in ax.get_lines() if len(line.get_xdata()) == len(curve.branches["primary"].data["M"])]
    np.testing.assert_array_equal(lines[0].get_xdata(), curve.branches["primary"].data["M"])
    marked = [line for line in ax.get_lines() if len(line.get_xdata()) == 1 and line.get_ydata()[0] == 0.0]
    fold = next(s for s in curve.branches["primary"].data["special_points"] if s["kind"] == "LP")
    assert [line.get_xdata()[0] for line in marked] == [fold["M"]]


def test_a_curve_in_M_restarts_in_M(tuning):
    """``continue`` from the curve's fold in its own parameter traces the branch in M again (not in P): the same
    fold, at the same M to 1e-9, and the same ends at M = 0."""
    folder, curve = tuning
    data = curve.branches["primary"].data
    fold = next(s for s in data["special_points"] if s["kind"] == "LP")
    again = folder / "again.h5"
    assert main(["continue", str(folder / "curve.h5"), str(fold["label"]), "--quiet", "-o", str(again), *STEPS]) == 0
    restarted = bc.load(again).branches["primary"].data
    assert restarted["attrs"]["parameter"] == "M"
    assert list(restarted["attrs"]["leg_stop_codes"]) == ["zero_field", "zero_field"]
    assert [abs(s["M"] - fold["M"]) <= 1e-9 for s in restarted["special_points"] if s["kind"] == "LP"] == [True]


def test_continuing_a_user_point_in_another_parameter_is_one_line(tuning, capsys):
    """A key a point is not followed in at fixed P (a material parameter; the branch's own P is the usual
    restart): one line naming it, exit 2."""
    folder, _ = tuning
    run = folder / "run.h5"
    label = rising_user_point(bc.load(run))["label"]
    assert main(["continue", str(run), str(label), "--parameter", "material.mu[0]", "-o",
                 str(folder / "no.h5")]) == 2
    err = capsys.readouterr().err
    assert "--parameter material.mu[0]" in err and "M or voltage" in err and not (folder / "no.h5").exists()


DIELECTRIC = """[material]
preset = "neo-Hookean"
[electric]
voltage = 0.3
[continuation]
start_stretch = 1.1
stop_stretch = 2.5
[dynamics]
frequencies = true
count = 4
m_max = 1
[[events]]
quantity = "pressure"
value = 1.0
"""


def test_a_curve_in_the_voltage_holds_the_breathing_mode_of_each_sphere(tmp_path):
    """``--parameter voltage`` from the user point at P = 1 of a neo-Hookean dielectric balloon at Φ̄ = 0.3: the
    branch in Φ̄ at P = 1 down to Φ̄ = 0 and up through the pull-in (a fold in Φ̄, LP) to the stop stretch. Without a
    field every point is the sphere P = 4(λ⁻¹ − λ⁻⁷) − 4Φ̄²λ (docs/scenes.md; 1e-10), and its breathing mode at fixed P
    and Φ̄ is the radial equation of motion's (tests/test_dynamics.py, the dielectric energy at fixed Φ̄ a function
    of λ on a sphere): Ω² = λ² (∂P/∂λ)_Φ̄ / 2 = λ² (−4λ⁻² + 28λ⁻⁸ − 4Φ̄²)/2, one of the even block's four stored Ω²
    at every point to 1e-9 (observed ~1e-12); at the pull-in it vanishes (1e-11)."""
    scene = tmp_path / "dielectric.toml"
    scene.write_text(DIELECTRIC)
    run, curve = tmp_path / "run.h5", tmp_path / "curve.h5"
    assert main(["run", str(scene), "--primary-only", "--quiet", "-o", str(run)]) == 0
    label = rising_user_point(bc.load(run))["label"]
    assert main(["continue", str(run), str(label), "--parameter", "voltage", "--quiet", "-o", str(curve),
                 "--set", "continuation.step_max=0.05"]) == 0
    data = bc.load(curve).branches["primary"].data
    assert data["attrs"]["parameter"] == "voltage"
    assert sorted(data["attrs"]["leg_stop_codes"]) == ["stop_stretch", "zero_voltage"]
    lam, voltage = data["lam2_top"], data["voltage"]
    assert np.abs(4 * (1 / lam - lam ** -7) - 4 * voltage ** 2 * lam - 1.0).max() <= 1e-10
    breathing_mode = lam ** 2 * (-4 * lam ** -2 + 28 * lam ** -8 - 4 * voltage ** 2) / 2
    assert np.abs(data["frequencies"]["even"] - breathing_mode[:, None]).min(axis=1).max() <= 1e-9
    n = next(n for n, s in enumerate(data["special_points"]) if s["kind"] == "LP")
    assert abs(data["special_frequencies"]["even"][n, 0]) <= 1e-11


def test_inspect_gives_each_special_point_its_M(tuning, capsys):
    """A branch continued in M at fixed P: `inspect` lists each special point with its M (the coordinate it was
    located in; P is the branch's fixed one), read back as stored."""
    folder, curve = tuning
    assert main(["inspect", str(folder / "curve.h5")]) == 0
    out = capsys.readouterr().out
    special = curve.special_points
    assert {s["kind"] for s in special} >= {"LP", "EP"}
    for s in special:
        line = next(line for line in out.splitlines() if line.lstrip().startswith(f"{s['label']} {s['kind']}"))
        assert f"M = {s['M']:.10g}  " in line and f"P = {s['pressure']:.10g}  " in line
