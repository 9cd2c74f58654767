"""Post-processing (MODEL.md §6): exact sphere values incl. the poles, curvature of a general shape, field
components on the surface, the paper's magnetic stress additions, wrinkling states, stored runs."""
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.model.field import field_components
from balloon_cg.post.quantities import (
    paper_magnetic_stresses, postprocess, quantities, surface, wrinkling,
)
from balloon_cg.galerkin.profiles import profiles
from balloon_cg.scene import load_scene
from balloon_cg.model.sphere import sphere_stress
from balloon_cg.io.run_file import read_run, write_run

SCENES = Path(__file__).resolve().parents[1] / "scenes"
THETA = np.linspace(0.0, np.pi, 37)  # both poles exactly


@pytest.fixture(scope="module")
def spom1():
    return load_scene(SCENES / "spom1.toml")


@pytest.fixture(scope="module")
def two_coils():
    return load_scene(SCENES / "spom1_two_coils_M0.002.toml")


def shape(disc, a_coefficients, b_coefficients, pressure=1.0):
    """The row X = (u, P) of λ2 = Σ a_k P_k, η = Σ b_k P_k."""
    a, b = np.zeros(disc.degree + 1), np.zeros(disc.degree + 1)
    a[: len(a_coefficients)] = a_coefficients
    b[: len(b_coefficients)] = b_coefficients
    return np.append(disc.join(a, b), pressure)


# A smooth non-spherical, non-symmetric shape (λ2 > 0, η decreasing in θ).
GENERAL = ([1.3, 0.08, -0.1, 0.03], [0.05, 1.2, 0.07, -0.04, 0.02])


@pytest.mark.parametrize("symmetric", [True, False])
@pytest.mark.parametrize("lam", [1.01, 1.7, 4.0])
def test_sphere_exact_everywhere_including_poles(spom1, symmetric, lam):
    disc = Discretisation(12, symmetric, pin_translation=True)
    q = quantities(spom1, disc, shape(disc, [lam], [0.0, lam]), THETA)
    for key in ("gaussian_curvature",):
        np.testing.assert_allclose(q[key], 1 / lam**2, rtol=0, atol=1e-10)
    for key in ("k_meridian", "k_parallel"):
        np.testing.assert_allclose(q[key], 1 / lam, rtol=0, atol=1e-10)
    np.testing.assert_allclose(q["lam1"], lam, atol=1e-12)
    stress = sphere_stress(spom1.material, lam)
    np.testing.assert_allclose(q["sigma_theta"], stress, rtol=0, atol=1e-10)
    np.testing.assert_allclose(q["sigma_phi"], stress, rtol=0, atol=1e-10)
    assert (q["wrinkling"] == "taut").all() and not q["lam1_below_one"].any()
    for key in ("H2", "H_theta", "H_zeta", "sigma_theta_paper", "sigma_phi_paper"):
        assert not q[key].any()  # no coils: no field


def test_sphere_translated_keeps_its_curvature(spom1):
    disc = Discretisation(10, symmetric=False, pin_translation=False)
    q = quantities(spom1, disc, shape(disc, [2.0], [0.3, 2.0]), THETA)
    np.testing.assert_allclose(q["gaussian_curvature"], 0.25, atol=1e-12)


def finite_difference_curvature(disc, X, theta, h=1e-4):
    """κ = η'(ρ'η'' − ρ''η')/(ρ(ρ'² + η'²)²) with ρ'', η'' by central differences of the exact ρ', η'."""
    def first(t):
        lam2, dlam2, _, deta = disc.evaluate(X[:-1], t)
        return dlam2 * np.sin(t) + lam2 * np.cos(t), deta

    drho, deta = first(theta)
    d2rho, d2eta = ((p - m) / (2 * h) for p, m in zip(first(theta + h), first(theta - h)))
    rho = disc.evaluate(X[:-1], theta)[0] * np.sin(theta)
    return deta * (drho * d2eta - d2rho * deta) / (rho * (drho**2 + deta**2) ** 2)


def test_curvature_of_a_general_shape(spom1):
    disc = Discretisation(10, symmetric=False, pin_translation=False)
    X = shape(disc, *GENERAL)
    interior = np.linspace(0.05, np.pi - 0.05, 40)
    q = quantities(spom1, disc, X, interior)
    np.testing.assert_allclose(q["gaussian_curvature"][0], finite_difference_curvature(disc, X, interior), rtol=1e-6)
    # the pole values are the limits of the general formula
    near = np.array([1e-4, np.pi - 1e-4])
    at_poles = quantities(spom1, disc, X, np.array([0.0, np.pi]))["gaussian_curvature"][0]
    np.testing.assert_allclose(at_poles, quantities(spom1, disc, X, near)["gaussian_curvature"][0], rtol=1e-6)
    # at a pole κ is the square of the meridian curvature, and both principal curvatures agree
    g = surface(disc, X, np.array([0.0, np.pi]))
    np.testing.assert_allclose(g["k_meridian"], g["k_parallel"], rtol=1e-12)
    np.testing.assert_allclose(at_poles, g["k_meridian"][0] ** 2, rtol=1e-12)


def test_field_components_on_the_surface(two_coils):
    disc = Discretisation(10, symmetric=False, pin_translation=False)
    q = quantities(two_coils, disc, shape(disc, *GENERAL), THETA)
    np.testing.assert_allclose(q["H_theta"] ** 2 + q["H_zeta"] ** 2, q["H2"], rtol=1e-12)
    assert q["H2"].max() > 1.0
    # t and n: unit, orthogonal, n points away from the centre on a sphere: n = (sin θ, cos θ)
    lam = 1.5
    sphere = quantities(two_coils, disc, shape(disc, [lam], [0.0, lam]), THETA)
    h_rho, h_z = field_components(lam * np.sin(THETA), lam * np.cos(THETA), [[1.7321, 1.0, 1.0], [1.7321, -1.0, -1.0]])
    np.testing.assert_allclose(sphere["H_zeta"][0], h_rho * np.sin(THETA) + h_z * np.cos(THETA), atol=1e-12)
    np.testing.assert_allclose(sphere["H_theta"][0], h_rho * np.cos(THETA) - h_z * np.sin(THETA), atol=1e-12)


def test_paper_magnetic_additions(two_coils):
    """Δσ_θ = (1+χ) M H_θ² − ½ M H², Δσ_φ = ½ λ2 χ M ∂(H²)/∂λ2 − ½ M H², ∂/∂λ2 by differences at fixed θ."""
    disc = Discretisation(10, symmetric=False, pin_translation=False)
    X = shape(disc, *GENERAL)
    M, chi = 0.002, 0.7
    q = quantities(two_coils, disc, X, THETA, M=M, chi=chi)
    lam2, eta = q["lam2"][0], q["eta"][0]

    def H2(stretch):
        h_rho, h_z = field_components(stretch * np.sin(THETA), eta, [[1.7321, 1.0, 1.0], [1.7321, -1.0, -1.0]])
        return h_rho**2 + h_z**2

    dH2 = (H2(lam2 + 1e-6) - H2(lam2 - 1e-6)) / 2e-6
    np.testing.assert_allclose(q["sigma_phi_paper"][0], 0.5 * lam2 * chi * M * dH2 - 0.5 * M * q["H2"][0],
                               rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(q["sigma_theta_paper"][0],
                               (1 + chi) * M * q["H_theta"][0] ** 2 - 0.5 * M * q["H2"][0], rtol=1e-14)
    # reported separately: the elastic stresses do not depend on M
    elastic = quantities(two_coils, disc, X, THETA, M=0.0)
    np.testing.assert_array_equal(q["sigma_theta"], elastic["sigma_theta"])
    assert not elastic["sigma_phi_paper"].any()
    zero = paper_magnetic_stresses(0.0, chi, np.sin(THETA), lam2, q)
    assert not np.any(zero[0]) and not np.any(zero[1])


def test_wrinkling_states(spom1):
    states = wrinkling([1.0, -1.0, 1.0, 0.0, -2.0], [1.0, 1.0, 0.0, -1.0, -1.0])
    assert states.tolist() == ["taut", "wrinkled", "wrinkled", "slack", "slack"]
    disc = Discretisation(8, True, True)
    undeformed = quantities(spom1, disc, shape(disc, [1.0], [0.0, 1.0]), THETA)
    assert (undeformed["wrinkling"] == "slack").all()  # nothing stretched: no tension


def test_postprocess_of_a_stored_run(tmp_path, spom1):
    scene = spom1.with_overrides({"continuation.stop_stretch": 1.5})
    branch = trace_primary(scene, down=False)
    run = read_run(write_run(tmp_path / "run.h5", scene, [branch]))
    stored = run["branches"]["primary"]
    q = postprocess(run, points=[0, -1])
    assert q["points"].tolist() == [0, -1] and q["lam1"].shape == (2, len(stored["theta"]))
    for key in ("lam1", "lam2", "rho", "eta"):
        np.testing.assert_allclose(q[key], stored["profiles"][key][[0, -1]], atol=1e-12)
    np.testing.assert_allclose(q["pressure"], stored["pressure"][[0, -1]])
    reference = profiles(branch.disc, branch.X, stored["theta"])
    np.testing.assert_allclose(postprocess(run)["lam1"], reference["lam1"], atol=1e-12)
    # M = 0 branch of spheres: κ = 1/λ2² everywhere, poles included
    np.testing.assert_allclose(q["gaussian_curvature"], 1 / q["lam2"] ** 2, rtol=1e-9)
