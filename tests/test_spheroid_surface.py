"""The whole-sphere engine on a reference spheroid (surface/, SphericalBasis.aspect): the non-axisymmetric branch born
at a spheroid's m = 1 branch point.

The energy is written here from its definition, independently of the kernels and of the basis' reference rows: the
reference X = (sin θ cos φ, sin θ sin φ, c cos θ) and its tangents written here, the deformed point X + u with u the
basis' harmonics (the definition of the coefficients), its θ- and φ-derivatives by fourth-order central differences,
the principal stretches from the two metrics (det(g − λ² G) = 0), Ogden's Φ of MODEL.md §2 and −½ χ M H² (H² by the
Biot–Savart integral of MODEL.md §3, tests/test_tube_field.py) per reference area |A_θ × A_φ| dθ dφ, and the pressure's
−P V with V = ⅓ ∫∫ x · (x_θ × x_φ) dθ dφ, over its own Gauss–Legendre × uniform nodes. The scene is SPOM1 in the
field of one coil of radius 4 in the equatorial plane (scenes/spom1_single_coil.toml), M = 0.002."""
import numpy as np
import pytest

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.surface.branches import (SurfaceTrace, axisymmetric_solve, critical_mode, initial_basis,
                                                  located_degree, mode_symmetry, switch, trace_surface)
from balloon_cg.dynamics.frequencies import attach
from balloon_cg.galerkin.equilibrium import Parameters
from balloon_cg.scene import load_scene
from balloon_cg.surface.basis import MIRROR_Y, SphericalBasis
from balloon_cg.surface.embedding import axisymmetric_coefficients, displacement_coefficients, mode_coefficients
from balloon_cg.surface.equilibrium import SurfaceEquilibrium
from balloon_cg.surface.gauge import FieldSymmetry, Gauge

from test_tube_field import biot_savart_squared

STEP = 1e-3  # of the central differences of u in θ and φ (fourth order: error ~ STEP⁴ |u⁽⁵⁾|)


def coil_scene(aspect: float, stop: float = 3.0):
    """The single-coil scene on a spheroid of ``aspect`` (1.0: still a spheroid), traced to the pole stretch ``stop``
    (past its first m = 1 branch points)."""
    return load_scene("spom1_single_coil").with_overrides(
        {"geometry.shape": "spheroid", "geometry.aspect": aspect, "continuation.stop_stretch": stop,
         "surface.branches": "none"})


def written_energy(scene, basis: SphericalBasis, c: np.ndarray, params: Parameters, n_theta: int = 48,
                   n_phi: int = 40) -> float:
    """E/(2π) of the state c written here (module docstring)."""
    aspect = scene.geometry.aspect
    t, w = np.polynomial.legendre.leggauss(n_theta)
    theta, phi = np.arccos(t), 2 * np.pi * np.arange(n_phi) / n_phi
    T, F = np.meshgrid(theta, phi, indexing="ij")

    def reference(T, F):
        return np.array([np.sin(T) * np.cos(F), np.sin(T) * np.sin(F), aspect * np.cos(T)])

    def point(T, F):
        u = basis.grid_values(c, np.cos(T[:, 0]), F[0]) - basis.grid_values(np.zeros(basis.size), np.cos(T[:, 0]),
                                                                             F[0])
        return reference(T, F) + u

    def derivative(f, dT, dF):
        return (-f(T + 2 * dT, F + 2 * dF) + 8 * f(T + dT, F + dF) - 8 * f(T - dT, F - dF)
                + f(T - 2 * dT, F - 2 * dF)) / (12 * STEP)

    x = point(T, F)
    x_t, x_p = derivative(point, STEP, 0.0), derivative(point, 0.0, STEP)
    X_t = np.array([np.cos(T) * np.cos(F), np.cos(T) * np.sin(F), -aspect * np.sin(T)])
    X_p = np.array([-np.sin(T) * np.sin(F), np.sin(T) * np.cos(F), np.zeros_like(T)])
    G = [[np.einsum("i...,i...->...", a, b) for b in (X_t, X_p)] for a in (X_t, X_p)]
    g = [[np.einsum("i...,i...->...", a, b) for b in (x_t, x_p)] for a in (x_t, x_p)]
    # λ² the roots of det(g − λ² G) = 0: a q² − b q + d = 0
    a = G[0][0] * G[1][1] - G[0][1] ** 2
    b = g[0][0] * G[1][1] + g[1][1] * G[0][0] - 2 * g[0][1] * G[0][1]
    d = g[0][0] * g[1][1] - g[0][1] ** 2
    root = np.sqrt(b * b - 4 * a * d)
    lam1, lam2 = np.sqrt((b + root) / (2 * a)), np.sqrt((b - root) / (2 * a))
    phi_ogden = sum(mu / alpha * (lam1**alpha + lam2**alpha + (lam1 * lam2) ** -alpha - 3)
                    for mu, alpha in zip(scene.material.mu, scene.material.alpha))
    coils = [(coil.radius, coil.height, coil.current) for coil in scene.field.coils]
    h2 = biot_savart_squared(np.hypot(x[0], x[1]).ravel(), x[2].ravel(), coils).reshape(T.shape)
    area = np.linalg.norm(np.cross(X_t, X_p, axis=0), axis=0)  # |A_θ × A_φ| = S' sin θ
    flux = np.einsum("i...,i...->...", x, np.cross(x_t, x_p, axis=0))
    density = (phi_ogden - 0.5 * params.chi * params.M * h2) * area - params.P * flux / 3
    # dθ = d(cos θ)/sin θ; the φ-sum times 2π/n_phi, the whole divided by 2π
    return float((w / np.sin(theta)) @ density.sum(axis=1) / n_phi)


@pytest.mark.parametrize("aspect", [0.7, 1.6])
def test_spheroid_energy_and_residual_are_those_written_here(aspect):
    """At a random non-axisymmetric state (degree 8, the mirror y → −y, 64 × 64 nodes; written on 80 × 72): E/(2π)
    is the energy written here to 1e-10 relative (measured 1e-11), and the residual along random unit directions
    its fourth-order central differences (1e-8 of the residual's norm); the same state read on the sphere's
    reference is another energy (the reference is not the sphere's)."""
    scene = coil_scene(aspect)
    basis = SphericalBasis(8, (MIRROR_Y,), n_theta=64, n_phi=64, aspect=aspect)
    eq = SurfaceEquilibrium(scene, basis)
    rng = np.random.default_rng(3)
    c = 0.03 * rng.standard_normal(basis.size) / (1 + np.arange(basis.size) / 10)
    params = Parameters(P=1.2, M=scene.field.M, chi=scene.field.chi)

    def written(state):
        return written_energy(scene, basis, state, params, 80, 72)

    energy = written(c)
    assert abs(eq.energy(c, params) - energy) <= 1e-10 * abs(energy)
    residual = eq.residual(c, params)
    for _ in range(3):
        d = rng.standard_normal(basis.size)
        d /= np.linalg.norm(d)
        h = 1e-3  # fourth order
        differences = (8 * (written(c + h * d) - written(c - h * d))
                       - (written(c + 2 * h * d) - written(c - 2 * h * d))) / (12 * h)
        assert abs(residual @ d - differences) <= 1e-8 * np.linalg.norm(residual)
    sphere = SurfaceEquilibrium(scene.with_overrides({"geometry.shape": "sphere", "geometry.aspect": 1.0}),
                                SphericalBasis(8, (MIRROR_Y,), n_theta=64, n_phi=64))
    assert abs(sphere.energy(c, params) - energy) > 1e-2 * abs(energy)


def test_gauge_of_a_spheroid_removes_only_its_relabelling_about_the_axis():
    """A spheroid's reference is invariant only under rotations about its axis: no phase condition about x or y
    (on the sphere, with every reflection off, there are three)."""
    for aspect, count in ((1.0, 3), (1.4, 1)):
        basis = SphericalBasis(4, aspect=aspect)
        assert basis.relabellings == ((0, 1, 2) if aspect == 1.0 else (2,))
        gauge = Gauge(basis, held=True, field_symmetry=FieldSymmetry.GENERAL)
        assert gauge.constraints.shape[0] == 3 + count  # three translations held


def smooth_direction(trace: SurfaceTrace, rng) -> np.ndarray:
    """A unit direction of the gauge's free space (G d = 0) from a random quadratic displacement field with the
    branch's reflections (y → −y, z → −z): smooth, so that the written energy's plain Gauss nodes integrate it (a
    random coefficient vector of a wire-mapped basis has features of the map's width)."""
    x, y, z = trace.basis.nodes["reference"][:3]
    a, b, e = rng.standard_normal(5), rng.standard_normal(2), rng.standard_normal(2)
    field = np.array([a[0] + a[1] * x + a[2] * x * x + a[3] * z * z + a[4] * y * y, y * (b[0] + b[1] * x),
                      z * (e[0] + e[1] * x)])
    d = displacement_coefficients(trace.basis, field)
    G = trace.gauge.constraints
    d -= G.T @ np.linalg.solve(G @ G.T, G @ d)
    return d / np.linalg.norm(d)


@pytest.fixture(scope="module")
def spheroid_primary():
    return analyse(coil_scene(1.3), pear=False).primary


def test_spheroid_of_aspect_one_surface_branch_is_the_sphere_s():
    """The single-coil scene as a sphere and as a spheroid of aspect 1 (another kernel module for the axisymmetric
    branch): the first held m = 1 branch point and the branch born there, 4 points, the same to 1e-10 (points,
    pressures, the located branch point and the end point; the classification the same), and so are the branch's
    natural frequencies (dynamics.frequencies.attach, count 4: every sector and reading at every point and special
    point; measured ≤ 5.8e-13)."""
    dynamics = {"dynamics.frequencies": True, "dynamics.count": 4}
    sphere = coil_scene(1.0).with_overrides({"geometry.shape": "sphere", **dynamics})
    branches = []
    for scene in (sphere, coil_scene(1.0).with_overrides(dynamics)):
        primary = analyse(scene, pear=False).primary
        k, bp = next((k, bp) for k, bp in enumerate(primary.branch_points()) if bp.m == 1 and bp.block.held)
        branches.append(trace_surface(primary, k, bp, 1.0, "m1", 4))
        attach([branches[-1]], 4, 0)
    one, other = branches
    assert len(one.values) == len(other.values) == 4
    a, b = one.basis, other.basis
    assert (a.degree, a.order, a.symmetry, a.n_theta, a.n_phi) == (b.degree, b.order, b.symmetry, b.n_theta, b.n_phi)
    assert np.allclose(a.mapping.centres, b.mapping.centres, rtol=0, atol=1e-10)  # re-centred on the state
    assert np.allclose(a.mapping.widths, b.mapping.widths, rtol=1e-10, atol=0)
    assert np.abs(one.values - other.values).max() <= 1e-10 * np.abs(one.values).max()
    assert np.abs(one.coefficients - other.coefficients).max() <= 1e-10
    assert [(s.kind, s.index, s.classification) for s in one.special] == [
        (s.kind, s.index, s.classification) for s in other.special]
    for a, b in zip(one.special, other.special):
        assert np.abs(a.X - b.X).max() <= 1e-10
    for table in ("omega2", "special"):
        mine, theirs = getattr(one.frequencies, table), getattr(other.frequencies, table)
        assert set(mine) == set(theirs) and len(mine) == 24  # 4 sectors × held, free × 3 controls
        for key in mine:
            np.testing.assert_allclose(mine[key], theirs[key], rtol=0, atol=1e-10)


def test_spheroid_m1_branch_is_a_pitchfork_along_the_located_mode(spheroid_primary):
    """Aspect 1.3, the first held m = 1 branch point (P ≈ 2.1067): its located m = 1 null vector, embedded, is a
    null vector of the whole-sphere Jacobian at the branch point's state to 1e-8 of the Jacobian's norm; the
    points on the hyperplanes φ·(X − X*) = ±δ have the same P to 1e-10 (P(+δ) = P(−δ): a pitchfork) and
    P − P* scales as δ² (P(2δ) − P(δ) = 4 (P(δ) − P(δ/2)) to 1e-3) and, extrapolated to δ = 0 (Richardson), the
    whole-sphere branch point is the axisymmetric one to 1e-8 (measured 1.0e-10; 7.4e-7 while the held balloon's
    centroid was weighted by the sphere's area, not the spheroid's: surface/gauge.py); the branch traced there
    (4 points) is an equilibrium of the energy written here: its last point's directional derivatives along smooth
    directions of the gauge's free space vanish (1e-9 of the energy's scale; measured 2e-11), while at the same
    state off the branch (the amplitude doubled) they do not."""
    primary = spheroid_primary
    k, bp = next((k, bp) for k, bp in enumerate(primary.branch_points()) if bp.m == 1 and bp.block.held)
    assert abs(bp.X[-1] - 2.1067) < 1e-3
    scene = primary.scene
    az_basis, vector = critical_mode(primary, bp, located_degree(primary, bp))
    symmetry = mode_symmetry(primary, az_basis, vector, scene.surface.degree)
    params = primary.params_at(bp.X)
    trace = SurfaceTrace(scene, initial_basis(scene, primary.disc, bp.X[:-1], symmetry), params, True)
    c_star = axisymmetric_solve(trace, axisymmetric_coefficients(trace.basis, primary.disc, bp.X[:-1]), bp.X[-1])
    X_star = trace.system.point(c_star, bp.X[-1])
    phi = np.append(trace.gauge.reduce(mode_coefficients(trace.basis, az_basis, vector)), 0.0)
    phi /= np.linalg.norm(phi)
    J = trace.system.jacobian(X_star)[:, :-1]
    assert np.linalg.norm(J @ phi[:-1]) <= 1e-8 * np.linalg.norm(J, 2)  # measured 1.8e-10
    pressure = []
    for delta in (2e-2, 1e-2, 5e-3):
        plus, minus = (switch(trace, X_star, sign * phi, delta) for sign in (1.0, -1.0))
        assert abs(plus.X[-1] - minus.X[-1]) <= 1e-10
        pressure.append(plus.X[-1])
    assert abs((pressure[0] - pressure[1]) / (pressure[1] - pressure[2]) - 4.0) <= 4e-3  # measured 5e-4
    assert abs((4 * pressure[2] - pressure[1]) / 3 - bp.X[-1]) <= 1e-8

    branch = trace_surface(primary, k, bp, 1.0, "m1", 4)
    assert branch.basis.aspect == 1.3 and branch.residual.max() <= 1e-10
    on = SurfaceTrace(scene, branch.basis, params, True)
    c, at = branch.coefficients[-1], params.with_value("P", branch.values[-1])
    rng = np.random.default_rng(5)
    scale = max(abs(written_energy(scene, branch.basis, c, at, 64, 48)), 1.0)

    def slope(state, direction, h=1e-3):  # fourth order
        def energy(step):
            return written_energy(scene, branch.basis, state + step * direction, at, 64, 48)
        return (8 * (energy(h) - energy(-h)) - (energy(2 * h) - energy(-2 * h))) / (12 * h)

    directions = [smooth_direction(on, rng) for _ in range(2)]
    on_branch = [abs(slope(c, d)) for d in directions]
    off = 2 * c - branch.coefficients[0]  # the amplitude doubled: not an equilibrium
    off_branch = abs(slope(off, directions[0]))
    assert max(on_branch) <= 1e-9 * scale and off_branch > 1e-3 * scale  # measured 2e-11 and 7e-3


def test_a_spheroid_surface_branch_is_stored_inspected_and_drawn(tmp_path, capsys):
    """The aspect-1.3 scene to the pole stretch 1.45 (past the first m = 1 point, before the pear point): the branch
    born at the first held m = 1 point (3 points) and its rotated image written with the primary (io.run_file), the
    basis' aspect stored; `inspect` lists them, `plot` draws their states, and the stored point 0 (the branch
    point's state solved on the whole spheroid) read back through ``stored_basis`` has the axisymmetric branch
    point's stretches at every node in the spheroid's frame (λ2 = ρ/sin θ, λ1 = |(ρ', η')|/S', from the primary's
    state evaluated here) to 1e-8."""
    from balloon_cg.analysis.surface.branches import rotated
    from balloon_cg.app.cli import main
    from balloon_cg.io.run_file import read_run, stored_basis, write_run
    from balloon_cg.post.plotting import principal_stretches

    scene = coil_scene(1.3, 1.45)
    primary = analyse(scene, pear=False).primary
    k, bp = next((k, bp) for k, bp in enumerate(primary.branch_points()) if bp.m == 1 and bp.block.held)
    branch = trace_surface(primary, k, bp, 1.0, "m1_bp0", 3)
    path = write_run(tmp_path / "spheroid.h5", scene, [primary, branch, rotated(branch, "m1_bp0_rotated")])
    assert main(["inspect", str(path)]) == 0
    shown = capsys.readouterr().out
    assert "surface branch m1_bp0 " in shown and "surface branch m1_bp0_rotated " in shown
    stored = read_run(path)["branches"]["m1_bp0"]
    basis = stored_basis(stored["attrs"])
    assert basis.aspect == 1.3 and stored["coefficients"].shape == (3, basis.size)
    lam1, lam2 = principal_stretches(basis.framed(basis.node_state(stored["coefficients"][0])))
    theta = np.arccos(basis.nodes["cos_theta"])
    hoop, hoop_slope, _, w = primary.disc.evaluate(bp.X[:-1], theta)  # λ2, dλ2/dθ, η, dη/dθ
    rate = np.sqrt(np.cos(theta) ** 2 + (1.3 * np.sin(theta)) ** 2)
    meridional = np.hypot(hoop * np.cos(theta) + hoop_slope * np.sin(theta), w) / rate  # |(ρ', η')|/S'
    assert np.abs(lam2 - np.repeat(hoop, basis.n_phi)).max() <= 1e-8
    assert np.abs(lam1 - np.repeat(meridional, basis.n_phi)).max() <= 1e-8
    out = tmp_path / "spheroid.png"
    assert main(["plot", str(path), "--what", "surface,stretch-map", "--branch", "m1_bp0", "-o", str(out)]) == 0
    assert (tmp_path / "spheroid_surface.png").stat().st_size and (tmp_path / "spheroid_stretch-map.png").stat().st_size
