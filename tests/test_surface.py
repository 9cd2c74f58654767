"""The whole-sphere engine (surface/, MODEL.md §8) against the axisymmetric solver and the azimuthal second variation:
its Hessian against finite differences, axisymmetric states as its equilibria, the sphere's spectrum as the union
of the m-blocks, the exact zero modes, and the gauge."""
from pathlib import Path

import numpy as np
import pytest
from scipy import linalg

from balloon_cg.analysis import azimuthal as az
from balloon_cg.analysis.primary import trace_primary
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.model.sphere import sphere_pressure
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import load_scene, parse_scene
from balloon_cg.surface import stability
from balloon_cg.surface.basis import EQUATOR, INVERSION, MIRROR_Y, SphericalBasis
from balloon_cg.surface.embedding import axisymmetric_coefficients, displacement_coefficients
from balloon_cg.surface.equilibrium import SurfaceEquilibrium
from balloon_cg.surface.gauge import Gauge, UnsupportedGauge
from balloon_cg.surface.measures import axial_stretch_row, measures
from balloon_cg.surface.system import SurfaceSystem

ROOT = Path(__file__).resolve().parent.parent


def sphere(scene, stretch, degree):
    """The axisymmetric problem on the full (m = 0) basis and the exact sphere of radius ``stretch``."""
    disc = Discretisation(degree, symmetric=False, pin_translation=False)
    a, b = np.zeros(degree + 1), np.zeros(degree + 1)
    a[0], b[1] = stretch, stretch
    return Equilibrium(scene, disc), disc.join(a, b), Parameters(sphere_pressure(scene.material, stretch))


@pytest.fixture(scope="module")
def spom1():
    return load_scene(ROOT / "scenes" / "spom1.toml")


@pytest.mark.parametrize("symmetry", [(), (MIRROR_Y,), (MIRROR_Y, EQUATOR), (MIRROR_Y, INVERSION)])
def test_hessian_is_the_derivative_of_the_residual_and_the_residual_of_the_energy(spom1, symmetry):
    """The sum-factorised Hessian (FFT in φ, product-to-sum) and the projected residual against central differences,
    at a random non-symmetric... state of the subspace (every block and sector present)."""
    basis = SphericalBasis(5, symmetry)
    eq = SurfaceEquilibrium(spom1, basis)
    rng = np.random.default_rng(7)
    c = displacement_coefficients(basis, 0.4 * basis.nodes["reference"][:3]) + 0.03 * rng.standard_normal(basis.size)
    params = Parameters(1.7)
    H, R = eq.hessian(c, params), eq.residual(c, params)
    h = 1e-6
    for k in range(basis.size):
        e = np.zeros(basis.size)
        e[k] = h
        column = (eq.residual(c + e, params) - eq.residual(c - e, params)) / (2 * h)
        assert np.abs(column - H[:, k]).max() <= 2e-7 * max(1.0, np.abs(H).max())
        slope = (eq.energy(c + e, params) - eq.energy(c - e, params)) / (2 * h)
        assert abs(slope - R[k]) <= 2e-8 * max(1.0, np.abs(R).max())
    assert np.abs(H - H.T).max() <= 1e-12 * np.abs(H).max()


def test_sphere_spectrum_is_the_union_of_the_azimuthal_blocks(spom1):
    """MODEL.md §8 check: at a sphere state (M = 0) the 2D Hessian in the mirror sector y → −y (the cos mφ family of
    every m: no torsion) has the eigenvalues of the axisymmetric m = 0 Hessian and of the m = 1..L blocks of
    analysis/azimuthal.py, in the same displacement norm; the lowest 40 (every sphere mode of degree n well below L,
    exact in both bases) to 1e-9. The other sector holds the sin mφ copies."""
    L = 10
    eq1, u, params = sphere(spom1, 1.5, L + 4)
    basis = SphericalBasis(L, (MIRROR_Y,))
    eq = SurfaceEquilibrium(spom1, basis)
    c = axisymmetric_coefficients(basis, eq1.disc, u)
    ours = np.sort(linalg.eigvalsh(2 * np.pi * eq.hessian(c, params)))
    ops, w, s = eq1.disc.ops, eq1.disc.weights, eq1.disc.sin_theta
    gram = (ops[0].T * (w * s * s)) @ ops[0] + (ops[2].T * w) @ ops[2]
    union = list(linalg.eigh(eq1.jacobian(u, params), gram, eigvals_only=True))
    copies = []
    for m in range(1, L + 1):
        values = linalg.eigh(*az.azimuthal_hessian(eq1, u, params, m, L), eigvals_only=True)
        union += list(values)
        copies += list(values)
    union = np.sort(union)
    assert np.abs(ours[:40] - union[:40]).max() <= 1e-9 * np.abs(union[:40]).max()
    odd = SphericalBasis(L, (MIRROR_Y,), (-1,))
    theirs = np.sort(linalg.eigvalsh(2 * np.pi * eq.hessian(c, params, odd)))
    for value in np.sort(copies)[:20]:
        assert np.abs(theirs - value).min() <= 1e-9 * max(1.0, abs(value))


@pytest.mark.parametrize("text, stretch", [
    ('[material]\npreset = "SPOM1"\n', 2.1),
    ('[material]\nfamily = "gent"\n[material.parameters]\nmu = 2.0\nJm = 30.0\n', 1.8),
])
def test_sphere_states_are_equilibria_and_the_solver_returns_them(text, stretch):
    """An exact sphere embedded: residual ≤ 1e-10; Newton at the prescribed north pole stretch (a bordering row)
    returns its pressure to 1e-10 from a perturbed start."""
    scene = parse_scene(text)
    eq1, u, params = sphere(scene, stretch, 8)
    basis = SphericalBasis(10, (MIRROR_Y, EQUATOR))
    eq = SurfaceEquilibrium(scene, basis)
    c = axisymmetric_coefficients(basis, eq1.disc, u)
    assert np.abs(eq.residual(c, params)).max() <= 1e-10
    system = SurfaceSystem(eq, Gauge(basis, held=True, in_field=False), params)
    row, offset = axial_stretch_row(basis)
    X0 = system.point(c + 0.01 * np.random.default_rng(3).standard_normal(basis.size), params.P * 1.05)
    X0[:-1] = system.gauge.reduce(system.gauge.expand(X0[:-1]))
    reduced_row = np.append(system.gauge.reduce(row), 0.0)
    result = newton(system.residual, system.jacobian, X0, reduced_row, stretch - offset, 1e-13, 30)
    assert result.converged
    assert abs(result.x[-1] - params.P) <= 1e-10 * params.P


def test_primary_branch_states_are_equilibria_with_a_field():
    """Points of the two-coil M = 0.002 primary branch (wire-mapped Legendre basis, field on) embedded at L = 40 (the
    shape is steep near the wire heights: its tail decays ~10× per 4 degrees, docs/numerics.md):
    residual ≤ 1e-10 (relative to the pressure), and Newton at the prescribed pole stretch returns P to 1e-10."""
    scene = load_scene(ROOT / "scenes" / "spom1_two_coils_M0.002.toml").with_overrides(
        {"continuation.stop_stretch": 2.2})
    branch = trace_primary(scene)
    basis = SphericalBasis(40, (MIRROR_Y, EQUATOR))
    eq = SurfaceEquilibrium(scene, basis)
    for index in (len(branch.X) // 3, 2 * len(branch.X) // 3):
        X = branch.X[index]
        params = branch.params_at(X)
        c = axisymmetric_coefficients(basis, branch.disc, X[:-1])
        assert np.abs(eq.residual(c, params)).max() <= 1e-10 * max(1.0, params.P)
        system = SurfaceSystem(eq, Gauge(basis, held=True, in_field=True), params)
        row, offset = axial_stretch_row(basis)
        stretch = branch.pole_values(X)["lam2_north"][0]
        X0 = system.point(c, params.P * 1.01)
        result = newton(system.residual, system.jacobian, X0, np.append(system.gauge.reduce(row), 0.0),
                        stretch - offset, 1e-13, 30)
        assert result.converged
        assert abs(result.x[-1] - params.P) <= 1e-10 * params.P


def test_relabelling_and_rigid_modes_are_exact_null_vectors(spom1):
    """At an equilibrium that is not a sphere (an ellipsoid-like state solved at M = 0 in the full mirror space would
    rotate; use a sphere state and the full space): every zero mode of ``stability.zero_mode_fields`` is a null
    vector of the 2D Hessian (to rounding), and removing them leaves the held spectrum positive below the pear
    point."""
    eq1, u, params = sphere(spom1, 1.3, 8)
    basis = SphericalBasis(10)
    eq = SurfaceEquilibrium(spom1, basis)
    c = axisymmetric_coefficients(basis, eq1.disc, u)
    H = eq.hessian(c, params)
    fields = stability.zero_mode_fields(eq.node_values(c)["state"], basis.nodes["reference"], False, True)
    rows = stability.mode_rows(basis, fields)
    assert len(rows) == 9
    for v in rows:
        assert np.abs(H @ v).max() <= 1e-10 * np.abs(H).max() * np.linalg.norm(v)
    values = stability.spectrum(eq, c, params, held=True)
    assert min(v.min() for v in values.values()) > 0


def test_gauge_removes_the_subspace_zero_modes(spom1):
    """The relabelling about y lives in the mirror subspace and is removed; a subspace that keeps a rigid rotation
    the field leaves free is refused."""
    basis = SphericalBasis(8, (MIRROR_Y,))
    gauge = Gauge(basis, held=True, in_field=True)
    assert gauge.size == basis.size - 2  # the x translation held (z is free in a field), the relabelling about y
    a = np.random.default_rng(1).standard_normal(gauge.size)
    c = gauge.expand(a)
    assert np.abs(gauge.constraints @ c).max() <= 1e-14
    assert np.allclose(gauge.reduce(c), a)
    with pytest.raises(UnsupportedGauge, match="rotation about the y axis"):
        Gauge(basis, held=True, in_field=False)


def test_measures_of_a_shifted_ellipsoid():
    """Volume, centroid, tilt and pole stretches of x = (1.5 X + 0.1, 1.2 Y, Z) against the closed forms."""
    basis = SphericalBasis(6, (MIRROR_Y,))
    X = basis.nodes["reference"][:3]
    c = displacement_coefficients(basis, np.array([1.5 * X[0] + 0.1, 1.2 * X[1], X[2]]) - X)
    m = measures(basis, c)
    assert m["volume"] == pytest.approx(4 / 3 * np.pi * 1.5 * 1.2 / (2 * np.pi), rel=1e-13)
    assert np.allclose(m["centroid"], [0.1, 0, 0], atol=1e-13)
    assert m["tilt"] == pytest.approx(90.0, abs=1e-9)
    assert m["lam_north"] == pytest.approx(np.sqrt(1.5 * 1.2), rel=1e-13)
