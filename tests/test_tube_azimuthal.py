"""The m ≥ 1 blocks of a tube's states (tube/azimuthal.py, codegen/second_variation.py on the tube meridian).

The uniform closed tube with sliding ends: the perturbation R = A cos kS, T = B cos kS, Z = C sin kS (k = nπ/L: Z
vanishes on the end planes, R' = T' = 0 there) times cos mφ, sin mφ, cos mφ is an exact eigenfunction of the
second variation, whose 3×3 matrix is computed here from the strain energy alone: the energy of the perturbed
cylinder written in Cartesian components (its metric's eigenvalues the squared principal stretches, the pressure's
work P times the volume between the end planes, ½ ∫∫ x_h · (x_S × x_φ) dS dφ), integrated by Gauss–Legendre in S
and the trapezoidal rule in φ, and differentiated twice in ε by an 8th-order central stencil. The Galerkin block's
lowest eigenvalues are the union of these matrices' over n."""
import numpy as np
import pytest

from balloon_cg.galerkin.discretisation import symmetric_rows
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.galerkin.interval import IntervalDiscretisation, Mirror
from balloon_cg.generated import AZIMUTHAL_PAIRS, HESSIAN_PAIRS
from balloon_cg.model import tube
from balloon_cg.scene import parse_scene
from balloon_cg.tube import azimuthal
from balloon_cg.tube.primary import primary_branch

STENCIL = (-205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560)  # f'' ≈ Σ_j c_j (f(jh) + f(−jh))/h², error O(h⁸)


def tube_scene(preset="SPOM1", length=10.0, extra=""):
    return parse_scene(f'[material]\npreset = "{preset}"\n[geometry]\nshape = "tube"\nlength = {length}\n{extra}')


def ogden(material, l1, l2):
    """Φ = Σ μ_i/α_i (λ1^α_i + λ2^α_i + (λ1λ2)^−α_i − 3)."""
    return sum(m / a * (l1**a + l2**a + (l1 * l2) ** -a - 3) for m, a in zip(material.mu, material.alpha))


def perturbed_energy(material, P, L, m, state, perturbation, eps, nodes=80):
    """E/(2π) of x = (ρ0 + εR cos mφ) e_ρ + εT sin mφ e_φ + (η0 + εZ cos mφ) e_z, ``state``(S) = (ρ0, ρ0', η0, η0'),
    ``perturbation``(S) = (R, R', T, T', Z, Z')."""
    s, w = np.polynomial.legendre.leggauss(nodes)
    S = L / 2 * (s + 1)
    rho, drho, eta, deta = (q[:, None] for q in state(S))
    R, dR, T, dT, Z, dZ = (eps * q[:, None] for q in perturbation(S))
    phi = 2 * np.pi * np.arange(nodes) / nodes
    cM, sM = np.cos(m * phi), np.sin(m * phi)
    f, g = rho + R * cM, T * sM  # the e_ρ and e_φ components of x
    # ∂x/∂S and ∂x/∂φ in (e_ρ, e_φ, e_z) (∂e_ρ/∂φ = e_φ, ∂e_φ/∂φ = −e_ρ)
    x_s = np.array([drho + dR * cM, dT * sM, deta + dZ * cM])
    x_p = np.array([-m * R * sM - g, m * T * cM + f, -m * Z * sM])
    a, b, c = (x_s * x_s).sum(0), (x_s * x_p).sum(0), (x_p * x_p).sum(0)  # the metric; the reference's is I
    root = np.sqrt((a - c) ** 2 / 4 + b * b)
    normal = np.cross(x_s, x_p, axis=0)
    density = ogden(material, np.sqrt((a + c) / 2 + root), np.sqrt((a + c) / 2 - root))
    density -= P * 0.5 * (f * normal[0] + g * normal[1])
    return (L / 2 * w) @ density.sum(1) / nodes


def second_derivative(energy, h=1e-2):
    """d²E/dε² at ε = 0 by the stencil."""
    return sum(c * (energy(j * h) + energy(-j * h)) / (2 if j == 0 else 1) for j, c in enumerate(STENCIL)) / h**2


def mode_matrix(material, state, P, L, m, n, nodes=48):
    """d²E/dε² = vᵀ K v for v = (A, B, C) (for n = 0 only A, B: sin 0 = 0), by the stencil and polarisation."""
    k = n * np.pi / L
    index = [0, 1] if n == 0 else [0, 1, 2]
    unit = np.eye(3)

    def uniform(S):
        return np.full_like(S, state.hoop), np.zeros_like(S), -state.axial * S, np.full_like(S, -state.axial)

    def quadratic(v):
        A, B, C = v

        def wave(S):
            return A * np.cos(k * S), -A * k * np.sin(k * S), B * np.cos(k * S), -B * k * np.sin(k * S), \
                C * np.sin(k * S), C * k * np.cos(k * S)
        return second_derivative(lambda e: perturbed_energy(material, P, L, m, uniform, wave, e, nodes))

    K = np.zeros((3, 3))
    for i in index:
        K[i, i] = quadratic(unit[i])
    for i in index:
        for j in index:
            if i < j:
                K[i, j] = K[j, i] = (quadratic(unit[i] + unit[j]) - K[i, i] - K[j, j]) / 2
    return K[np.ix_(index, index)]


@pytest.mark.parametrize("preset, hoop", [("SPOM1", 1.3), ("neo-Hookean", 2.0)])
def test_uniform_tube_blocks_are_the_perturbed_cylinders(preset, hoop):
    """m = 1, 2, 3 at a uniform closed state (L = 10, degree 30): the six lowest eigenvalues of the Galerkin block
    against those of the mode matrices K_n over the Gram matrix ½ ∫ (cos², cos², sin²) dS, n = 0..11 (m = 1: the
    sideways translation, n = 0 and A = −B, is the zero eigenvalue removed). Measured ≤ 1.2e-9 (the stencil's
    rounding), asserted 1e-8."""
    scene = tube_scene(preset)
    L = scene.geometry.length
    state = tube.closed_end_state(scene.material, hoop)
    disc = IntervalDiscretisation(30, L)
    eq = Equilibrium(scene, disc)
    u = disc.uniform(state.hoop, state.axial)
    for m in (1, 2, 3):
        exact = []
        for n in range(12):
            gram = 0.5 * L * (1.0 if n == 0 else 0.5)
            exact += list(np.linalg.eigvalsh(mode_matrix(scene.material, state, state.pressure, L, m, n)) / gram)
        exact = np.sort(exact)
        if m == 1:
            assert abs(exact[0]) < 1e-8
            exact = exact[1:]
        galerkin = np.linalg.eigvalsh(azimuthal.block(eq, u, Parameters(state.pressure), m))
        assert np.max(np.abs(galerkin[:6] - exact[:6])) <= 1e-8 * max(1.0, abs(exact[5])), (m, galerkin[:6], exact[:6])


@pytest.mark.parametrize("ends", ["sliding", "plugged"])
def test_block_is_the_second_variation_at_a_non_uniform_state(ends):
    """SPOM1, L = 10, degree 12, 80 Gauss nodes: at a random non-uniform state and for a random perturbation of the
    basis, m = 1, 2, cᵀ H c against d²E/dε² of the energy written here (its state and perturbation the same Legendre
    series; the stencil). Measured ≤ 4.1e-12 relative, asserted 1e-8."""
    scene = tube_scene("SPOM1", 10.0, f'ends = "{ends}"\n')
    L = 10.0
    disc = IntervalDiscretisation(12, L, quadrature=80, ends=scene.geometry.ends)
    eq = Equilibrium(scene, disc)
    rng = np.random.default_rng(7)
    u = disc.reference() + 0.05 * rng.standard_normal(disc.size) / (1 + np.arange(disc.size) % 13)
    ops, _ = azimuthal.operators(disc)
    c = 0.1 * rng.standard_normal(ops.shape[2])
    nodes_s = L / 2 * (np.polynomial.legendre.leggauss(80)[0] + 1)
    assert np.allclose(L / 2 * (disc.x + 1), nodes_s, rtol=0, atol=1e-13)  # the same nodes: the state's values there
    lam2, v, eta, w = disc.node_state(u)
    y = ops @ c  # (R, R', Z, Z', T, T') at the nodes
    for m in (1, 2):
        H = azimuthal.hessian(eq, u, Parameters(0.8), m)
        expected = second_derivative(lambda e: perturbed_energy(
            scene.material, 0.8, L, m, lambda S: (lam2, v, eta, w), lambda S: (y[0], y[1], y[4], y[5], y[2], y[3]), e))
        assert abs(c @ H @ c - expected) <= 1e-8 * abs(expected), (m, c @ H @ c, expected)


@pytest.mark.parametrize("ends", ["sliding", "plugged"])
def test_m0_kernel_is_half_the_axisymmetric_hessian_and_the_translation_a_zero_mode(ends):
    """At a random state: the azimuthal kernel at m = 0 on (R, R', Z, Z') is ½ the axisymmetric energy_hessian on
    (λ2, v, η, w) (R = 1: δρ = δλ2; the φ-mean of cos² mφ is ½ for m ≥ 1, and the kernel keeps it at m = 0), node by
    node (1e-12); with sliding ends H c = 0 for the sideways translation c (the energy is invariant under it at
    every state, the pressure's work too: 1e-12 of H)."""
    scene = tube_scene("SPOM1", 10.0, f'ends = "{ends}"\n')
    disc = IntervalDiscretisation(16, 10.0, ends=scene.geometry.ends)
    eq = Equilibrium(scene, disc)
    u = disc.reference() + 0.05 * np.random.default_rng(3).standard_normal(disc.size)
    params = Parameters(0.9)
    h = azimuthal.node_hessian(eq, u, params, 0)[symmetric_rows(AZIMUTHAL_PAIRS)][:4, :4]
    nodes = eq.at_nodes("test", (disc.cos_theta, disc.sin_theta))
    disc.node_state(u, out=nodes.state)
    nodes.hold(params)
    axisymmetric = nodes("energy_hessian", params)[symmetric_rows(HESSIAN_PAIRS)]
    assert np.max(np.abs(h - axisymmetric / 2)) <= 1e-12 * np.max(np.abs(axisymmetric))
    if ends == "sliding":
        H = azimuthal.hessian(eq, u, params, 1)
        assert np.max(np.abs(H @ azimuthal.translation(disc))) <= 1e-12 * np.max(np.abs(H))
        assert azimuthal.zero_modes(eq, params, 1).shape[0] == 1 and azimuthal.zero_modes(eq, params, 2).size == 0
    else:
        assert azimuthal.zero_modes(eq, params, 1).size == 0


def test_uniform_tube_has_no_m_ge_1_instability_before_its_bulge_onset():
    """Neo-Hookean, L = 10, degree 20: along the uniform branch to a hoop stretch of 3 the m = 1, 2, 3 blocks have no
    negative eigenvalue (before the onset of bulging, the first odd branch point of m = 0, and beyond it): the
    inflated tube's first instability is the axisymmetric bulge. The lowest m = 1 eigenvalue is that of the longest
    bending wave n = 1, small and positive (measured: the smallest over the branch 9.4e-3; m = 2: 0.119, m = 3: 0.357).
    At P = 0 the unstressed membrane has inextensional modes: the m = 2, 3 blocks' lowest eigenvalue is 0 to rounding
    (−5e-13, 6e-14), so the first point is left out."""
    scene = tube_scene("neo-Hookean", 10.0).with_overrides({"solver.degree": 20, "continuation.stop_stretch": 3.0})
    primary = primary_branch(scene)
    onset = primary.branch_points(Mirror.ODD)[0]
    eq = Equilibrium(scene, primary.disc)
    modes = azimuthal.branch_modes(eq, np.column_stack([primary.states, primary.pressure]), primary.params, 3)
    for m in (1, 2, 3):  # from the first inflated point (at P = 0 the unstressed membrane has inextensional modes)
        assert not modes.unstable[m][1:].any(), (m, modes.unstable[m])
        assert modes.lowest[m][1:, 0].min() > 0
    assert onset.index < len(primary.pressure) - 1  # the branch went beyond the onset


def test_held_tube_buckles_sideways_where_the_mode_matrix_is_singular():
    """Neo-Hookean, ends held at λz = 1.5 (sliding), L = 10, degree 16: inflated at fixed length the tube comes under
    axial compression and its first m = 1 zero (located by tube/azimuthal_crossings.py along the primary branch) is
    where the mode matrix K_n (this module's, from the energy) of the wave cos(nπS/L) first turns singular: λθ from
    Brent on the lowest eigenvalue of K_n over n = 1..3, P = Φ_2/(λθλz) there (Φ_2 written here). The first root is the
    longest wave n = 1 at λθ = 2.17430517 (n = 2: 2.36399); the located zero is within 4.9e-10 in λθ and 2.4e-11 in P
    (asserted 1e-7: the stencil's accuracy), its eigenvalue 0 to 1e-10."""
    from types import SimpleNamespace

    from scipy import optimize

    from balloon_cg.tube.azimuthal_crossings import crossings

    scene = tube_scene("neo-Hookean", 10.0, "axial_stretch = 1.5\n").with_overrides(
        {"solver.degree": 16, "continuation.stop_stretch": 2.3})
    material, axial, L = scene.material, 1.5, 10.0

    def pressure(hoop):  # Φ_2/(λθλz), Φ_2 = Σ μ (λ2^(α−1) − λ2^(−α−1) λ1^(−α))
        phi2 = sum(mu * (hoop ** (a - 1) - hoop ** (-a - 1) * axial**-a) for mu, a in zip(material.mu, material.alpha))
        return phi2 / (hoop * axial)

    def lowest(hoop, n):
        state = SimpleNamespace(hoop=hoop, axial=axial)
        return np.linalg.eigvalsh(mode_matrix(material, state, pressure(hoop), L, 1, n, nodes=24))[0]

    roots = [optimize.brentq(lambda h: lowest(h, n), 2.0, 2.6, xtol=1e-11) for n in range(1, 4)
             if lowest(2.0, n) * lowest(2.6, n) < 0]
    hoop = min(roots)
    primary = primary_branch(scene)
    eq = Equilibrium(scene, primary.disc)
    modes = azimuthal.branch_modes(eq, np.column_stack([primary.states, primary.pressure]), primary.params, 1)
    found = [c for c in crossings(scene, primary, modes) if c.pressure > 0.5]  # (P = 0 is hoop-compressed: λθ < 1)
    first = found[0]
    assert first.m == 1 and first.order == 0 and abs(first.value) < 1e-10
    located_hoop = primary.disc.node_state(first.u)[0]
    assert np.ptp(located_hoop) < 1e-10  # the uniform state
    assert abs(located_hoop[0] - hoop) < 1e-7 and abs(first.pressure - pressure(hoop)) < 1e-7, \
        (located_hoop[0] - hoop, first.pressure - pressure(hoop))


def test_m_max_zero_is_said_not_assessed(tmp_path):
    """stability.m_max = 0: no m ≥ 1 block is computed, the file holds none (its branches' m_max 0) and inspect says
    "m ≥ 1 not assessed"; with m_max = 2 both blocks are stored and named."""
    from balloon_cg.app.tube_summary import format_tube, summarise_tube
    from balloon_cg.io.tube_file import read_tube_run, write_tube_run
    from balloon_cg.tube.picture import tube_picture

    for m_max, said in ((0, "m ≥ 1 not assessed"), (2, "m = 1..2 (the same under all three")):
        scene = tube_scene().with_overrides({"solver.degree": 12, "continuation.stop_stretch": 1.4,
                                             "stability.m_max": m_max})
        picture = tube_picture(scene, primary_only=True)
        path = write_tube_run(tmp_path / f"m{m_max}.h5", scene, picture)
        run = read_tube_run(path)
        assert set(run["branches"]["primary"]["azimuthal"]) == set(range(1, m_max + 1))
        assert (picture.modes is None) == (m_max == 0)
        assert said in format_tube(summarise_tube(run))


def coil_scene(M, degree=16, stop=1.2):
    """tube_spom1_L10_coil.toml's tube and coil (radius 2.5 about the middle) at M, m = 1 assessed."""
    return tube_scene("SPOM1", 10.0, 'ends = "sliding"\n[field]\nM = ' + repr(M) + '\n[[field.coils]]\nradius = 2.5\n'
                      'height = 0.0\ncurrent = 1.0\n').with_overrides(
        {"solver.degree": degree, "continuation.stop_stretch": stop, "stability.m_max": 1})


def test_tube_in_a_coil_field_reads_stable_held_and_unstable_free(tmp_path):
    """SPOM1, L = 10, sliding ends, one coaxial coil about the middle, M = 0.01, degree 16, to a hoop stretch of 1.2
    (P up to ~0.6): the free tube's m = 1 block has one negative eigenvalue at every point (the field pulls the tube
    sideways, towards the wire: measured −0.0041 at P = 0), the held tube's (the translation removed) none; its lowest
    eigenvalue is the free one's second (the translation's direction gone, the rest nearly unchanged: 0.0211 both at
    P = 0). Stored (lowest_m1_held, unstable_m1_held) and shown by inspect as "m = 1 held"."""
    from balloon_cg.app.tube_summary import format_tube, summarise_tube
    from balloon_cg.io.tube_file import HELD_M1, read_tube_run, write_tube_run
    from balloon_cg.tube.picture import tube_picture

    scene = coil_scene(0.01)
    picture = tube_picture(scene, primary_only=True)
    modes = picture.modes["primary"]
    assert modes.held is not None and len(picture.branches["primary"].pressure) > 5
    assert (modes.unstable[1] == 1).all() and (modes.held["unstable"] == 0).all()
    assert (modes.lowest[1][:, 0] < 0).all() and (modes.held["lowest"][:, 0] > 0).all()
    assert not [c for c in modes.crossings if c.held]
    run = read_tube_run(write_tube_run(tmp_path / "coil.h5", scene, picture))
    stored = run["branches"]["primary"]["azimuthal"]
    assert np.array_equal(stored[HELD_M1]["lowest"], modes.held["lowest"])
    assert np.array_equal(stored[1]["unstable"], modes.unstable[1])
    text = format_tube(summarise_tube(run))
    assert "m = 1 free: lowest eigenvalue ≥ -0.00" in text and "m = 1 held: lowest eigenvalue ≥ 0.0" in text
    assert "m = 1 (the same under all three" in text


def test_held_and_free_m1_at_zero_field_differ_by_the_translation_alone():
    """The coil scene at M = 0 (the coil present, no field): at a random state the block with no mode removed (the
    free tube's, the translation kept) has the eigenvalue 0 (the translation: 1e-10 of the next), and its other
    lowest eigenvalues are the held tube's (the translation removed, ``zero_modes(held=True)``) to 1e-10 relative; at
    M = 0 the held and free readings are one (``readings``), in a field two."""
    from balloon_cg.numerics.eigen import NO_CONSTRAINT, restricted

    scene = coil_scene(0.0)
    disc = IntervalDiscretisation(16, 10.0, ends=scene.geometry.ends)
    eq = Equilibrium(scene, disc)
    u = disc.reference() + 0.05 * np.random.default_rng(5).standard_normal(disc.size)
    params = Parameters(0.7, 0.0)
    H = azimuthal.hessian(eq, u, params, 1)
    kept = np.linalg.eigvalsh(restricted(H, azimuthal._factor(disc), NO_CONSTRAINT))
    held = np.linalg.eigvalsh(azimuthal.block(eq, u, params, 1, held=True))
    zero = np.argmin(np.abs(kept))
    assert abs(kept[zero]) <= 1e-10 * np.abs(kept).max()
    rest = np.delete(kept, zero)
    assert rest.size == held.size and np.max(np.abs(rest - held)) <= 1e-10 * np.abs(held).max()
    assert azimuthal.readings(eq, params, 1) == (False,)
    assert azimuthal.readings(eq, Parameters(0.7, 0.01), 1) == (False, True)
