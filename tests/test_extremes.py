"""Stiff and extreme cases (fast versions; benchmarks/extremes.py has the slow ones and prints the report).

Each case either converges, with a verified residual and a refinement check (the same point solved again at a
higher Legendre degree), or stops with a clear diagnostic; no stored solution holds a NaN and every loop is
bounded (max_points, max_degree, Newton iterations).
"""
import numpy as np
import pytest

from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.results import StopCode, TraceStop

from balloon_cg.analysis.branches.wires import wire_gap
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Parameters
from balloon_cg.galerkin.point_solve import constrained_newton
from balloon_cg.scene import load_scene, parse_scene
from balloon_cg.model.sphere import sphere_pressure

from pathlib import Path

SCENES = Path(__file__).resolve().parents[1] / "scenes"


def spom1(extra=""):
    return parse_scene(f'[material]\npreset = "SPOM1"\n{extra}', name="spom1")


def two_coils(**overrides):
    return load_scene(SCENES / "spom1_two_coils_M0.002.toml").with_overrides(overrides)


def assert_clean(branch):
    """Every stored point finite and converged (residual at the Newton tolerance's level)."""
    assert np.all(np.isfinite(branch.X))
    assert np.all(branch.residual < 1e-9)
    assert branch.legs and all(leg.stop is not None for leg in branch.legs)


def refinement_check(branch, factor=1.5, rel=1e-10):
    """The last point solved again at a higher degree gives the same P."""
    X = branch.X[-1]
    stretch = branch.pole_values()["lam2_top"][-1]
    degree = int(branch.disc.degree * factor)
    scene = branch.scene
    result, _ = constrained_newton(scene, degree, X, branch.disc, stretch, branch.params)
    assert result.converged, result.message
    assert result.x[-1] == pytest.approx(X[-1], rel=rel)
    return result


def test_pole_stretch_10_is_the_exact_sphere():
    branch = trace_primary(spom1("[continuation]\nstop_stretch = 10.0\n"), down=False)
    assert_clean(branch)
    lam = branch.pole_values()["lam2_top"]
    assert lam[-1] == pytest.approx(10.0, abs=1e-12)
    assert branch.legs[0].label == "up" and branch.stopped(StopCode.STOP_STRETCH)
    exact = sphere_pressure(branch.scene.material, lam)
    assert np.abs(branch.pressure / exact - 1).max() < 1e-10
    refinement_check(branch)


@pytest.mark.parametrize("mu, alpha", [(0.5, 8.0), (-1.0, -4.0)])
def test_one_term_ogden_with_extreme_exponents(mu, alpha):
    """μ α = 4. At M = 0 the branch is the sphere: P = 2μ(λ^(α−3) − λ^(−2α−3)) to 1e-10, refined × 1.5."""
    scene = parse_scene(f"[material]\nmu = [{mu}]\nalpha = [{alpha}]\n[continuation]\nstop_stretch = 2.0\n",
                        name=f"alpha{alpha}")
    branch = trace_primary(scene, down=False)
    assert_clean(branch)
    assert branch.legs[0].label == "up" and branch.stopped(StopCode.STOP_STRETCH)
    lam = branch.pole_values()["lam2_top"]
    assert np.abs(branch.pressure / sphere_pressure(scene.material, lam) - 1).max() < 1e-10
    refinement_check(branch)


def test_stiff_material_runs_out_of_points_with_a_clear_stop():
    """α = 8: P grows like λ^5, so arclength steps (dominated by P) are short in λ; a small max_points budget
    ends the trace with the budget named, never a hang."""
    scene = parse_scene("[material]\nmu = [0.5]\nalpha = [8.0]\n[continuation]\nstop_stretch = 10.0\nmax_points = 60\n")
    branch = trace_primary(scene, down=False)
    assert_clean(branch)
    assert branch.stopped(TraceStop.MAX_POINTS) and len(branch.X) <= 60
    assert len(branch.X) <= 61


def test_tiny_field_is_continuous_with_zero_field():
    """M = 1e-9: P − P(M = 0) = O(M), with the slope of M = 1e-6 (linear response)."""
    P0 = sphere_pressure(spom1().material, 1.5)
    slopes = []
    for M in (1e-9, 1e-6):
        branch = trace_primary(two_coils(**{"field.M": M}), stop_stretch=1.5, down=False)
        assert_clean(branch)
        slopes.append((branch.pressure[-1] - P0) / M)
    assert abs(branch.pressure[-1] - P0) < 1e-4 * P0
    assert slopes[0] == pytest.approx(slopes[1], rel=1e-2)


def test_far_coils_shift_the_pressure_by_their_field_gradient():
    """The paper's opposed pair scaled by L: near the centre H² ∝ r²/L⁴, so P − P0 ∝ L⁻⁴ (a uniform field
    would not act at all: −½χM H² per unit reference area is then a constant)."""
    P0 = sphere_pressure(spom1().material, 1.5)
    shifts = {}
    for L in (5.0, 20.0):
        scene = two_coils(**{"field.coils[0].radius": 1.7321 * L, "field.coils[0].height": L,
                             "field.coils[1].radius": 1.7321 * L, "field.coils[1].height": -L})
        branch = trace_primary(scene, stop_stretch=1.5, down=False)
        assert_clean(branch)
        shifts[L] = branch.pressure[-1] - P0
    assert 0 < -shifts[20.0] < 1e-7 * P0
    assert shifts[5.0] / shifts[20.0] == pytest.approx(4.0**4, rel=0.05)


@pytest.mark.parametrize("start, low", [(1 + 2e-8, 1 + 1e-8), (1 + 1e-12, 1 + 5e-13)])
def test_nearly_undeformed_start(start, low):
    """Start stretch 1 + O(1e-8..1e-12): the energy (Galerkin) formulation has no singularity there; the branch
    converges and the sphere pressure is matched in absolute terms (P itself is O(λ − 1))."""
    scene = spom1(f"[continuation]\nstart_stretch = {start!r}\nmin_stretch = {low!r}\nstop_stretch = 1.2\n")
    branch = trace_primary(scene)
    assert_clean(branch)
    lam = branch.pole_values()["lam2_top"]
    assert lam[0] == lam.min() == pytest.approx(low, abs=1e-15)  # the down leg lands on min_stretch
    assert start in lam
    assert np.abs(branch.pressure - sphere_pressure(scene.material, lam)).max() < 1e-11
    assert branch.legs[1].stop.code == StopCode.MIN_STRETCH


def test_constrained_newton_at_pole_stretch_one_plus_1e8():
    scene = spom1()
    disc = Discretisation(40, True, True)
    lam = 1 + 1e-8
    a, b = np.zeros(41), np.zeros(41)
    a[0], a[2], b[1] = lam * (1 + 1e-3), 1e-4, lam  # off the solution
    X0 = np.append(disc.join(a, b), 1.01 * sphere_pressure(scene.material, lam))
    result, eq = constrained_newton(scene, 40, X0, disc, lam, Parameters(0.0))
    assert result.converged and np.all(np.isfinite(result.x))
    assert abs(result.x[-1] - sphere_pressure(scene.material, lam)) < 1e-13


def test_field_switched_on_at_a_nearly_undeformed_sphere():
    """With the coils the start is the M = 0 sphere at 1 + 1e-8, then M is raised at that pressure: the field
    pulls the pole stretch up to ≈ 1.0002, the branch converges and stops at min_stretch."""
    branch = trace_primary(two_coils(**{"continuation.start_stretch": 1 + 2e-8,
                                         "continuation.min_stretch": 1 + 1e-8,
                                         "continuation.stop_stretch": 1.2}))
    assert_clean(branch)
    lam = branch.pole_values()["lam2_top"]
    assert 1.0 < lam.min() < 1.001 and lam.max() == pytest.approx(1.2, abs=1e-12)


def test_approaching_a_wire_stops_for_resolution():
    """wire_gap = 1e-3 with max_degree = 60: the bulge toward the wire outgrows the degree long before the gap
    is reached; the trace stops saying 'resolution' and naming max_degree, with every stored point clean."""
    scene = two_coils(**{"continuation.wire_gap": 1e-3, "solver.max_degree": 60})
    branch = trace_primary(scene, down=False)
    assert_clean(branch)
    assert branch.legs[0].stop.code == StopCode.RESOLUTION_LIMIT
    assert branch.degree.max() == 60
    gaps = [wire_gap(branch.disc, X[:-1], scene.field.coils)[0] for X in branch.X]
    assert min(gaps) > 1e-3
    assert np.all(branch.error_estimate <= scene.solver.max_error)


def test_wire_gap_stop_names_the_coil():
    scene = two_coils(**{"continuation.wire_gap": 0.3})
    branch = trace_primary(scene, down=False)
    assert_clean(branch)
    assert branch.stopped(StopCode.WIRE_GAP)
    gaps = [wire_gap(branch.disc, X[:-1], scene.field.coils)[0] for X in branch.X]
    assert min(gaps) >= 0.3


def test_stability_basis_degree_60():
    """N = 60 in the second variation: finite lowest eigenvalues, the same flags as N = 40 (skipped while
    balloon_cg.analysis.stability.axisymmetric does not exist)."""
    stability = pytest.importorskip("balloon_cg.analysis.stability.axisymmetric")
    branch = trace_primary(spom1("[continuation]\nstop_stretch = 2.0\n"), down=False)
    params = branch.params
    coarse, fine = stability.SecondVariation(equilibrium_of(branch), 40), stability.SecondVariation(equilibrium_of(branch), 60)
    for X in branch.X[:: max(1, len(branch.X) // 6)]:
        p = params.with_value("P", X[-1])
        a40, a60 = coarse.assess(X[:-1], p, True), fine.assess(X[:-1], p, True)
        for block, values in a60.blocks.items():
            assert np.all(np.isfinite(values)), block
        assert (a40.stable_pressure, a40.stable_volume) == (a60.stable_pressure, a60.stable_volume)
