"""The primary branch at M = 0 against the exact sphere (MODEL.md §4), for every preset."""
import numpy as np
import pytest
from scipy.optimize import brentq

from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.galerkin.equilibrium import Parameters
from balloon_cg.scene import parse_scene
from balloon_cg.model.sphere import sphere_pressure

PRESET_NAMES = ["SPOM1", "SPOM2", "FPOM1", "FPOM2", "TPOM1", "TPOM2", "neo-Hookean", "Mooney-Rivlin"]


def sphere_scene(preset, stop=6.0, extra=""):
    return parse_scene(
        f'[material]\npreset = "{preset}"\n[continuation]\nstart_stretch = 1.01\nmin_stretch = 1.005\n'
        f"stop_stretch = {stop}\n{extra}",
        name=preset,
    )


@pytest.fixture(scope="module", params=PRESET_NAMES)
def branch(request):
    return trace_primary(sphere_scene(request.param))


def test_pressure_is_the_exact_sphere_pressure(branch):
    """Relative 1e-10, except next to a branch point of the sphere, where the error in the nearly singular mode
    is rounding (~1e-13 in the residual) divided by the smallest Hessian eigenvalue, and is bounded by that."""
    stretch = branch.pole_values()["lam2_top"]
    assert stretch[0] == pytest.approx(1.005, abs=1e-12) and stretch[-1] == pytest.approx(6.0, abs=1e-12)
    assert stretch.min() == pytest.approx(1.005, abs=1e-12)  # landed on min_stretch, not past it
    exact = sphere_pressure(branch.scene.material, stretch)
    error = np.abs(branch.pressure / exact - 1)
    for X, e in zip(branch.X, error):
        if e > 1e-10:
            smallest = np.abs(np.linalg.eigvalsh(equilibrium_of(branch).jacobian(X[:-1], Parameters(X[-1])))).min()
            assert e < 1e-12 / smallest and smallest < 1e-3


def test_profile_is_a_sphere(branch):
    theta = np.linspace(0, np.pi, 181)
    for X in branch.X[:: max(1, len(branch.X) // 15)]:
        lam2, _, eta, _ = branch.disc.evaluate(X[:-1], theta)
        radius = lam2[0]
        rho = lam2 * np.sin(theta)
        assert np.abs(rho**2 + eta**2 - radius**2).max() < 1e-10 * radius**2
        assert np.abs(lam2 - radius).max() < 1e-10


def test_points_are_converged_equilibria(branch):
    assert np.all(branch.residual < 1e-9)
    assert np.all(branch.error_estimate < 1e-10)


def test_limit_point_is_the_maximum_of_the_exact_pressure(branch):
    """The located fold in P sits where dP/dλ = 0 for the sphere (when the material has one in range)."""
    material = branch.scene.material
    h = 1e-6
    slope = lambda lam: (sphere_pressure(material, lam + h) - sphere_pressure(material, lam - h)) / (2 * h)  # noqa: E731
    folds = [s for s in branch.special if s.kind == "LP"]
    grid = np.linspace(1.02, 5.99, 500)
    changes = np.nonzero(np.diff(np.sign(slope(grid))))[0]
    assert len(folds) == len(changes)
    for fold, i in zip(folds, changes):
        exact = brentq(slope, grid[i], grid[i + 1], xtol=1e-13)
        assert branch.pole_values(fold.X)["lam2_top"][0] == pytest.approx(exact, rel=1e-7)
        assert fold.X[-1] == pytest.approx(sphere_pressure(material, exact), rel=1e-12)


def test_general_mode_matches_the_symmetric_one():
    """Tracing without the equator-symmetry reduction (north and south pole stretches free) gives the same P."""
    scene = sphere_scene("SPOM1", stop=3.0, extra='symmetry = "none"\n')
    branch = trace_primary(scene)
    values = branch.pole_values()
    assert not branch.disc.symmetric
    assert np.abs(values["lam2_top"] - values["lam2_bottom"]).max() < 1e-10
    exact = sphere_pressure(scene.material, values["lam2_top"])
    assert np.abs(branch.pressure / exact - 1).max() < 1e-10
