"""The tube over (S, φ) (tube/surface/): Legendre(S) × Fourier(φ), its energy, residual and exact Jacobian.

Checked against the interval discretisation (its m = 0 restriction), against the existing m ≥ 1 blocks
(tube/azimuthal.py) and their located zeros, and against an energy written here from the strain energy alone: the
deformed point from the coefficients by numpy's Legendre series, in Cartesian components, the principal stretches
from the metric's eigenvalues, Ogden's Φ, the pressure's work over the volume between the end planes
½ x_h · (x_S × x_φ), Gauss–Legendre in S and the trapezoid in φ."""
import numpy as np
import pytest

from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.galerkin.interval import IntervalDiscretisation
from balloon_cg.numerics.eigen import GramFactor, restricted
from balloon_cg.scene import parse_scene
from balloon_cg.tube import azimuthal
from balloon_cg.tube.surface.basis import TubeSurfaceBasis
from balloon_cg.tube.surface.equilibrium import MeridianSurfaceEquilibrium

ENDS = ("sliding", "plugged", "held")


def tube_scene(preset="SPOM1", length=10.0, extra=""):
    return parse_scene(f'[material]\npreset = "{preset}"\n[geometry]\nshape = "tube"\nlength = {length}\n{extra}')


def scene_and_disc(ends, degree=16, length=10.0, preset="SPOM1"):
    extra = 'ends = "sliding"\naxial_stretch = 1.3\n' if ends == "held" else f'ends = "{ends}"\n'
    scene = tube_scene(preset, length, extra)
    disc = IntervalDiscretisation(degree, length, ends=scene.geometry.ends, axial_stretch=scene.geometry.axial_stretch)
    return scene, disc


def random_state(disc, seed=3, size=0.05):
    return disc.reference() + size * np.random.default_rng(seed).standard_normal(disc.size)


@pytest.mark.parametrize("ends", ENDS)
def test_restricted_to_m0_it_is_the_interval_discretisation(ends):
    """At a random axisymmetric state (orders 0, 1, 2): E/(2π), V/(2π), the residual, ∂R/∂P and the Jacobian on the
    m = 0 unknowns are the interval discretisation's (1e-12 relative); the m ≥ 1 residual vanishes (∫ cos mφ = 0)
    and the Hessian couples no two orders (the trapezoid exact for cos mφ cos m'φ, n_phi > m + m')."""
    scene, disc = scene_and_disc(ends)
    eq, params = Equilibrium(scene, disc), Parameters(0.9)
    basis = TubeSurfaceBasis(disc, (0, 1, 2))
    surface = MeridianSurfaceEquilibrium(scene, basis)
    u = random_state(disc)
    c = basis.axisymmetric(u)
    axis = basis.block(0)

    def close(a, b):
        return np.max(np.abs(np.asarray(a) - b)) <= 1e-12 * max(np.max(np.abs(b)), 1.0)

    assert close(surface.energy(c, params), eq.energy(u, params))
    assert close(surface.volume(c), eq.volume(u))
    R = surface.residual(c, params)
    assert close(R[axis], eq.residual(u, params))
    assert np.max(np.abs(R[axis.stop:])) <= 1e-12 * np.max(np.abs(R))
    assert close(surface.parameter_derivative(c, params)[axis], eq.parameter_derivative(u, params, "P"))
    H = surface.hessian(c, params)
    assert close(H[axis, axis], eq.jacobian(u, params))
    for m in (1, 2):
        assert np.max(np.abs(H[axis, basis.block(m)])) <= 1e-12 * np.max(np.abs(H))
    assert np.max(np.abs(H[basis.block(1), basis.block(2)])) <= 1e-12 * np.max(np.abs(H))


@pytest.mark.parametrize("ends", ENDS)
def test_order_m_blocks_are_the_azimuthal_blocks(ends):
    """At a random axisymmetric state the Hessian's order-m block (m = 1, 2, 3) is tube/azimuthal.hessian (1e-12
    relative) and its eigenvalues on the Gram matrix, the zero modes removed as there, are the block's (1e-10)."""
    scene, disc = scene_and_disc(ends)
    eq, params = Equilibrium(scene, disc), Parameters(0.9)
    basis = TubeSurfaceBasis(disc, (0, 1, 2, 3))
    surface = MeridianSurfaceEquilibrium(scene, basis)
    u = random_state(disc, seed=5)
    H = surface.hessian(basis.axisymmetric(u), params)
    factor = GramFactor(azimuthal.operators(disc)[1])
    for m in (1, 2, 3):
        block = H[basis.block(m), basis.block(m)]
        expected = azimuthal.hessian(eq, u, params, m)
        assert np.max(np.abs(block - expected)) <= 1e-12 * np.max(np.abs(expected)), m
        ours = np.linalg.eigvalsh(restricted(block, factor, azimuthal.zero_modes(eq, params, m)))
        theirs = np.linalg.eigvalsh(azimuthal.block(eq, u, params, m))
        assert np.max(np.abs(ours - theirs)) <= 1e-10 * max(1.0, np.max(np.abs(theirs))), m


def located_zeros(case):
    """(scene, branch, its located m = 1 zeros (tube/azimuthal_crossings.py)) of a held neo-Hookean tube's uniform
    branch (λz = 1.5, degree 16: its sideways buckle), of SPOM1's bulge branch (L = 10, degree 20, to V/V0 = 5: the
    lateral buckle of the bulge, a non-uniform state) or of a plugged neo-Hookean tube held at λz = 1.2 (L = 10,
    degree 16: one m = 1 zero at P = 1.18399, the plugs holding the rims: no translation to gauge)."""
    from balloon_cg.galerkin.interval import Mirror
    from balloon_cg.tube.azimuthal_crossings import crossings
    from balloon_cg.tube.bulge import bulge_branch
    from balloon_cg.tube.primary import primary_branch

    if case == "held":
        scene = tube_scene("neo-Hookean", 10.0, "axial_stretch = 1.5\n").with_overrides(
            {"solver.degree": 16, "continuation.stop_stretch": 2.3})
        branch = primary_branch(scene)
    elif case == "plugged":
        scene = tube_scene("neo-Hookean", 10.0, 'ends = "plugged"\naxial_stretch = 1.2\n').with_overrides(
            {"solver.degree": 16, "continuation.stop_stretch": 3.5})
        branch = primary_branch(scene)
    else:
        scene = tube_scene("SPOM1", 10.0).with_overrides({"solver.degree": 20, "continuation.stop_stretch": 5.0})
        primary = primary_branch(scene)
        branch = bulge_branch(scene, primary, primary.branch_points(Mirror.ODD)[0], stop_volume=5.0 * np.pi * scene.geometry.length)
    eq = Equilibrium(scene, branch.disc)
    modes = azimuthal.branch_modes(eq, np.column_stack([branch.states, branch.pressure]), branch.params, 1)
    return scene, branch, [c for c in crossings(scene, branch, modes) if c.pressure > 0.5]


@pytest.fixture(scope="module", params=["held", "bulge", "plugged"])
def zeros(request):
    return located_zeros(request.param)


def test_lowest_m1_eigenvalue_vanishes_at_the_located_branch_point(zeros):
    """At each located m = 1 zero the lowest eigenvalue of the surface Hessian's m = 1 block (orders 0, 1, 2; the
    translation removed on the Gram matrix as tube/azimuthal.py does) is zero (1e-9 of the block's scale: the
    location's own tolerance), and it has opposite signs at the branch's points on either side."""
    scene, branch, found = zeros
    assert found, "no located m = 1 zero"
    disc = branch.disc
    eq = Equilibrium(scene, disc)
    basis = TubeSurfaceBasis(disc, (0, 1, 2))
    surface = MeridianSurfaceEquilibrium(scene, basis)
    factor = GramFactor(azimuthal.operators(disc)[1])

    def lowest(u, P):
        params = branch.params.with_value("P", P)
        block = surface.hessian(basis.axisymmetric(u), params)[basis.block(1), basis.block(1)]
        A = restricted(block, factor, azimuthal.zero_modes(eq, params, 1))
        return np.linalg.eigvalsh(A)[0], np.max(np.abs(A))

    for zero in found:
        value, scale = lowest(zero.u, zero.pressure)
        assert abs(value) <= 1e-9 * scale, (zero.pressure, value, scale)
        before = lowest(branch.states[zero.index], branch.pressure[zero.index])[0]
        after = lowest(branch.states[zero.index + 1], branch.pressure[zero.index + 1])[0]
        assert before * after < 0, (before, after)


def legendre_values(coefficients, x, length):
    """(f, df/dS) of Σ c_k P_k at x = 2S/L − 1."""
    L = np.polynomial.legendre
    return L.legval(x, coefficients), 2 / length * L.legval(x, L.legder(coefficients))


def bubbles(b):
    """The Legendre coefficients of Σ b_k (P_{k+2} − P_k)."""
    c = np.zeros(b.size + 2)
    c[2:] += b
    c[:-2] -= b
    return c


def written_point(disc, orders, c, s, phi):
    """(x, x_S, x_φ), each (3, s.size, phi.size), of the coefficients c at x = 2S/L − 1 = s and the azimuths φ,
    written from their definition (tube/surface/basis.py): λ2 = Σ a_k P_k (plugged: 1 + bubbles), η = −λ̄(L/2)x +
    bubbles, R, T on P_k (plugged: bubbles), Z on bubbles; the Cartesian x = (r cos φ − t sin φ, r sin φ + t cos φ, z)
    and its derivatives."""
    n, L = disc.degree, disc.length
    sliding = disc.ends.value == "sliding"
    k = disc.hoops
    hoop = c[:k] if sliding else bubbles(c[:k]) + np.eye(1, n + 1)[0]
    rho, rho_s = legendre_values(hoop, s, L)
    eta, eta_s = legendre_values(bubbles(c[k + 1: disc.size]), s, L)
    eta, eta_s = eta - c[k] * L / 2 * s, eta_s - c[k]
    r, r_s, r_p = rho[:, None] + 0 * phi, rho_s[:, None] + 0 * phi, 0 * rho[:, None] + 0 * phi
    t, t_s, t_p = 0 * r, 0 * r, 0 * r
    z, z_s, z_p = eta[:, None] + 0 * phi, eta_s[:, None] + 0 * phi, 0 * r
    size = 2 * k + n - 1
    for i, m in enumerate(orders[1:]):
        block = c[disc.size + i * size: disc.size + (i + 1) * size]
        a, b = (block[:k], block[k: 2 * k]) if sliding else (bubbles(block[:k]), bubbles(block[k: 2 * k]))
        (R, R_s), (T, T_s) = legendre_values(a, s, L), legendre_values(b, s, L)
        Z, Z_s = legendre_values(bubbles(block[2 * k:]), s, L)
        cos, sin = np.cos(m * phi), np.sin(m * phi)
        r, r_s, r_p = r + np.outer(R, cos), r_s + np.outer(R_s, cos), r_p - m * np.outer(R, sin)
        t, t_s, t_p = t + np.outer(T, sin), t_s + np.outer(T_s, sin), t_p + m * np.outer(T, cos)
        z, z_s, z_p = z + np.outer(Z, cos), z_s + np.outer(Z_s, cos), z_p - m * np.outer(Z, sin)
    cos, sin = np.cos(phi), np.sin(phi)
    x = np.array([r * cos - t * sin, r * sin + t * cos, z])
    x_s = np.array([r_s * cos - t_s * sin, r_s * sin + t_s * cos, z_s])
    x_p = np.array([r_p * cos - r * sin - t_p * sin - t * cos, r_p * sin + r * cos + t_p * cos - t * sin, z_p])
    return x, x_s, x_p


def written_energy(material, disc, orders, n_phi, c, P):
    """E/(2π) of the coefficients c: the point of ``written_point``, the metric's eigenvalues λ1², λ2²,
    Φ = Σ μ/α (λ1^α + λ2^α + (λ1λ2)^−α − 3) and −P ½ (x, y, 0)·(x_S × x_φ); Gauss–Legendre in S with as many
    nodes as the basis, n_phi points of the trapezoid in φ."""
    s, w = np.polynomial.legendre.leggauss(disc.x.size)
    x, x_s, x_p = written_point(disc, orders, c, s, 2 * np.pi * np.arange(n_phi) / n_phi)
    g11, g12, g22 = (x_s * x_s).sum(0), (x_s * x_p).sum(0), (x_p * x_p).sum(0)
    root = np.sqrt((g11 - g22) ** 2 / 4 + g12**2)
    l1, l2 = np.sqrt((g11 + g22) / 2 + root), np.sqrt((g11 + g22) / 2 - root)
    phi_density = sum(mu / al * (l1**al + l2**al + (l1 * l2) ** -al - 3) for mu, al in zip(material.mu, material.alpha))
    normal = np.cross(x_s, x_p, axis=0)
    density = phi_density - P * 0.5 * (x[0] * normal[0] + x[1] * normal[1])
    return (disc.length / 2 * w) @ density.sum(axis=1) / n_phi


@pytest.mark.parametrize("ends", ENDS)
def test_energy_and_its_derivatives_are_those_written_here(ends):
    """At a random non-axisymmetric state (orders 0, 1, 2, every coefficient perturbed): E/(2π) is the energy written
    here (1e-12 relative) and ``profile`` its Cartesian point (1e-13), the residual its central differences (1e-7
    relative), the Jacobian the residual's (1e-7) and symmetric (1e-12); ∂R/∂P the derivative of the residual in P
    (1e-7)."""
    scene, disc = scene_and_disc(ends, degree=10)
    basis = TubeSurfaceBasis(disc, (0, 1, 2))
    surface = MeridianSurfaceEquilibrium(scene, basis)
    rng = np.random.default_rng(11)
    c = basis.axisymmetric(random_state(disc, seed=7)) + 0.02 * rng.standard_normal(basis.size) * (
        np.arange(basis.size) >= disc.size)
    P, h = 0.9, 1e-6
    params = Parameters(P)

    def energy(c):
        return written_energy(scene.material, disc, basis.orders, basis.n_phi, c, P)

    E = energy(c)
    assert abs(surface.energy(c, params) - E) <= 1e-12 * abs(E)
    S, phi = np.linspace(0, disc.length, 7), np.linspace(0, 2 * np.pi, 5)
    written = written_point(disc, basis.orders, c, 2 * S / disc.length - 1, phi)[0]
    assert np.max(np.abs(basis.profile(c, S, phi) - written)) <= 1e-13 * np.max(np.abs(written))
    R = surface.residual(c, params)
    free = basis.free
    steps = np.eye(basis.size)[free] * h
    differences = np.array([(energy(c + e) - energy(c - e)) / (2 * h) for e in steps])
    assert np.max(np.abs(R[free] - differences)) <= 1e-7 * np.max(np.abs(R)), np.max(np.abs(R[free] - differences))
    H = surface.hessian(c, params)
    assert np.max(np.abs(H - H.T)) <= 1e-12 * np.max(np.abs(H))
    columns = np.array([(surface.residual(c + e, params) - surface.residual(c - e, params)) / (2 * h) for e in steps])
    assert np.max(np.abs(H[:, free] - columns.T)) <= 1e-7 * np.max(np.abs(H))
    dP = (surface.residual(c, Parameters(P + h)) - surface.residual(c, Parameters(P - h))) / (2 * h)
    assert np.max(np.abs(surface.parameter_derivative(c, params) - dP)) <= 1e-7 * np.max(np.abs(dP))


def test_switched_point_is_an_equilibrium_off_the_axisymmetric_branch(zeros):
    """From each located m = 1 zero (tube/surface/switching.py, orders 0, 1, 2): Newton converges at ε = ±0.1 and
    0.05 along the critical mode (residual ≤ 1e-12 of the pressure's terms in it, P ∂Ṽ/∂c); the point is stationary
    for the energy written here (its central differences along 8 random unit directions, h = 1e-6: ≤ 1e-9 of
    P ∂Ṽ/∂c; the predictor's ≥ 1e-6 of it, measured 2.3e-6 and more: the check tells the point from its predictor);
    the amplitude is ε, the reaction of the held centroid zero; the branch is a pitchfork: P(−ε) = P(ε) (1e-12) and
    (P(ε) − P_0)/ε² converges as ε² (its change from ε = 0.1 to 0.05 a quarter of that from 0.2 to 0.1, within 5 %)."""
    from balloon_cg.tube.surface.switching import switched_point

    scene, branch, found = zeros
    disc, h = branch.disc, 1e-6
    for zero in found:
        points = {eps: switched_point(scene, disc, zero, eps, branch.params) for eps in (0.2, 0.1, -0.1, 0.05)}
        for eps, point in points.items():
            assert point.converged, (eps, point.message)
            basis = point.basis
            start = basis.with_mode(basis.axisymmetric(zero.u), 1, eps * zero.mode)
            surface = MeridianSurfaceEquilibrium(scene, basis)
            scale = zero.pressure * np.max(np.abs(surface.parameter_derivative(start, branch.params)))
            assert point.residual <= 1e-12 * scale, (eps, point.residual, scale)
            amplitude = zero.mode @ azimuthal.operators(disc)[1] @ point.c[basis.block(1)]
            assert abs(amplitude - eps) <= 1e-12 and abs(point.reaction) <= 1e-12 * scale
        point = points[0.1]
        basis = point.basis
        directions = np.zeros((8, basis.size))
        directions[:, basis.free] = np.random.default_rng(2).standard_normal((8, basis.free.size))
        steps = h * directions / np.linalg.norm(directions, axis=1)[:, None]

        def gradient(c, P):
            def energy(c):
                return written_energy(scene.material, disc, basis.orders, basis.n_phi, c, P)
            return np.array([(energy(c + e) - energy(c - e)) / (2 * h) for e in steps])

        start = basis.with_mode(basis.axisymmetric(zero.u), 1, 0.1 * zero.mode)
        derivative = MeridianSurfaceEquilibrium(scene, basis).parameter_derivative(start, branch.params)
        scale = zero.pressure * np.max(np.abs(derivative))
        stationary, predicted = (np.max(np.abs(gradient(c, P))) for c, P in ((point.c, point.pressure),
                                                                              (start, zero.pressure)))
        assert stationary <= 1e-9 * scale and predicted >= 1e-6 * scale
        assert abs(points[-0.1].pressure - points[0.1].pressure) <= 1e-12 * zero.pressure
        quotient = {eps: (points[eps].pressure - zero.pressure) / eps**2 for eps in (0.2, 0.1, 0.05)}
        ratio = (quotient[0.2] - quotient[0.1]) / (quotient[0.1] - quotient[0.05])
        assert abs(ratio - 4) <= 0.2, (quotient, ratio)


def test_what_it_does_not_take_is_refused_in_one_line():
    """A sphere, another parameter than P (SceneError: the scene's), orders not starting at 0, too few points in φ
    (ValueError: the call's): one line each, naming the key, its value and what is allowed."""
    from balloon_cg.scene import SceneError

    disc = IntervalDiscretisation(8, 10.0)
    cases = [(lambda: MeridianSurfaceEquilibrium(parse_scene('[material]\npreset = "SPOM1"\n'), TubeSurfaceBasis(disc)),
              "geometry.shape", SceneError),
             (lambda: TubeSurfaceBasis(disc, (1, 2)), "orders", ValueError),
             (lambda: TubeSurfaceBasis(disc, (0, 3), n_phi=6), "n_phi", ValueError),
             (lambda: MeridianSurfaceEquilibrium(tube_scene(), TubeSurfaceBasis(disc)).parameter_derivative(
                 np.zeros(TubeSurfaceBasis(disc).size), Parameters(1.0), "M"), "continuation.parameter", SceneError)]
    for call, key, kind in cases:
        with pytest.raises(kind) as error:
            call()
        message = str(error.value)
        assert message.startswith(key) and "allowed" in message, message
        assert "\n" not in message
