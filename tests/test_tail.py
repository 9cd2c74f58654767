"""The spectral error estimate (Discretisation.tail) against the true error of P, measured with an independent
method (shooting, DOP853 at rtol 1e-13) on the two-coil scene near its turning point, where the Legendre
coefficients decay slowly (r ≈ 0.85 per degree) and the last coefficients alone under-read the error ~10×."""
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.branches.problem import ParameterSystem

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import load_scene
from balloon_cg.model.shooting import shoot_symmetric

SCENE = Path(__file__).resolve().parent.parent / "scenes" / "spom1_two_coils_M0.002.toml"
STRETCH = 1.7


@pytest.fixture(scope="module")
def landed():
    scene = load_scene(SCENE).with_overrides({"continuation.stop_stretch": STRETCH})
    branch = trace_primary(scene, down=False)
    X = branch.X[-1]
    eta0 = float(branch.disc.pole_rows()["eta_top"] @ X[:-1])
    shot = shoot_symmetric(scene, STRETCH, X[-1], eta0, tol=1e-13)
    assert shot.converged
    return scene, branch, X, shot.P


@pytest.mark.parametrize("degree", [32, 48, 64, 96])
def test_tail_estimate_tracks_the_true_error(landed, degree):
    scene, branch, X, P_ref = landed
    fine = branch.disc
    disc = Discretisation(degree, fine.symmetric, fine.pin_translation)  # Legendre in x, no map
    X0 = fine.transfer(X, disc)
    eq = Equilibrium(scene, disc)
    system = ParameterSystem(eq, branch.params, "P")
    row = np.append(disc.pole_rows()["lam2_top"], 0.0)
    result = newton(system.residual, system.jacobian, X0, row, STRETCH, 1e-13, 30)
    assert result.converged
    error = abs(result.x[-1] / P_ref - 1)
    estimate = disc.tail(result.x[:-1])
    assert error > 1e-10  # resolution-limited, above the rounding floor
    assert 0.3 * error < estimate < 30 * error
