"""The m = 1 instability of the SPOM1 bulge (L = 10, sliding closed ends; docs/tubes.md "m ≥ 1 stability") checked
by a second method: the second variation of the tube's energy written here from the strain energy alone, on a basis
of its own, against the Galerkin block of tube/azimuthal.py (Legendre series, the generated ``azimuthal_hessian``).

The state x0 = ρ(S) e_ρ + η(S) e_z is the bulge branch's (its Legendre series evaluated at 200 Gauss nodes, the
only thing shared); the perturbation δx = R cos φ e_ρ + T sin φ e_φ + Z cos φ e_z on the mirror basis of the sliding
ends R_j = T_j = cos(jπS/L), Z_j = sin(jπS/L), j < J (Z = 0 on the end planes, R' = T' = 0 there). The energy per 2π
is E = (1/2π) ∫∫ [Φ(λ1, λ2) − P ½ x_h · (x_S × x_φ)] dS dφ (λ1², λ2² the eigenvalues of the metric (a, b, c) =
(x_S·x_S, x_S·x_φ, x_φ·x_φ): the reference metric is the identity; the pressure's work over the volume between the end
planes). x is linear in the amplitudes, so the metric and the volume density are polynomials in them and their
second-order parts are exact bilinear forms; Φ enters through F(a, b, c) = Φ and its first and second derivatives at
the unperturbed metric, by 8th-order central stencils in (a, b, c). So d²E/dε² = cᵀHc with

    H = 2 Σ W [F_a a₂ + F_b b₂ + F_c c₂ + ½ g₁ᵀ F_gg g₁] − P (B + Bᵀ),   B the volume density's second-order part,

on the trapezoidal rule in φ (8 nodes: the integrand's ε² part is a trigonometric polynomial of degree 2) and
Gauss–Legendre in S. The eigenvalues of H c = μ G c, G the Gram matrix of ½ ∫ (R² + T² + Z²) dS, the sideways
translation (R = 1, T = −1) removed, are the block's.
"""
import numpy as np
import pytest
from scipy.linalg import eigh

from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.galerkin.interval import IntervalDiscretisation, Mirror
from balloon_cg.tube import azimuthal
from balloon_cg.tube.azimuthal_crossings import crossings
from balloon_cg.tube.bulge import bulge_branch
from balloon_cg.tube.primary import primary_branch
from balloon_cg.numerics.threads import limited_blas

from test_interval import ogden, tube_scene

SECOND = (-205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560)  # f'' ≈ Σ_j c_j (f(jh) + f(−jh))/h², error O(h⁸)
FIRST = (4 / 5, -1 / 5, 4 / 105, -1 / 280)  # f' ≈ Σ_j c_j (f((j+1)h) − f(−(j+1)h))/h
NODES, AROUND, MODES = 200, 8, 40  # Gauss nodes in S, trapezoid nodes in φ, cosines per component


def metric_density(material, g):
    """F(a, b, c) = Φ(λ1, λ2), λ1², λ2² the eigenvalues of the metric (a, b, c) (rows of g)."""
    a, b, c = g
    root = np.sqrt((a - c) ** 2 / 4 + b * b)
    return ogden(material, np.sqrt((a + c) / 2 + root), np.sqrt((a + c) / 2 - root))


def metric_derivatives(material, g, h=1e-3):
    """F_g (3, n) and F_gg (3, 3, n) at the metrics g (3, n), by the stencils."""
    unit = np.eye(3)[:, :, None]

    def second(d):
        return sum(c * (metric_density(material, g + j * h * d) + metric_density(material, g - j * h * d))
                   / (2 if j == 0 else 1) for j, c in enumerate(SECOND)) / h**2

    grad = np.array([sum(c * (metric_density(material, g + (j + 1) * h * unit[i])
                              - metric_density(material, g - (j + 1) * h * unit[i])) for j, c in enumerate(FIRST)) / h
                     for i in range(3)])
    hess = np.zeros((3, 3, g.shape[1]))
    for i in range(3):
        hess[i, i] = second(unit[i])
    for i in range(3):
        for k in range(i + 1, 3):
            hess[i, k] = hess[k, i] = (second(unit[i] + unit[k]) - hess[i, i] - hess[k, k]) / 2
    return grad, hess


def cosine_basis(S, L, count=MODES):
    """(R, R', T, T', Z, Z') at the nodes S (each (n, unknowns)): R_j, T_j = cos(jπS/L), Z_j = sin(jπS/L), j ≥ 1."""
    k = np.arange(count) * np.pi / L
    c, dc = np.cos(np.outer(S, k)), -k * np.sin(np.outer(S, k))
    s, ds = np.sin(np.outer(S, k))[:, 1:], (k * np.cos(np.outer(S, k)))[:, 1:]
    zero, none = np.zeros_like(c), np.zeros_like(s)
    return [np.hstack(parts) for parts in ((c, zero, none), (dc, zero, none), (zero, c, none), (zero, dc, none),
                                           (zero, zero, s), (zero, zero, ds))]


def brute_force_block(material, L, P, state, count=MODES):
    """(H, G) of the module docstring at the state (ρ, ρ', η, η') given at the NODES Gauss nodes of [0, L]."""
    s, w = np.polynomial.legendre.leggauss(NODES)
    S, W = L / 2 * (s + 1), L / 2 * w
    rho, drho, eta, deta = state
    phi = 2 * np.pi * np.arange(AROUND) / AROUND
    cos, sin = np.cos(phi)[None, :, None], np.sin(phi)[None, :, None]
    R, dR, T, dT, Z, dZ = (f[:, None, :] for f in cosine_basis(S, L, count))  # (n, 1, unknowns)
    zero = np.zeros((NODES, AROUND, R.shape[2]))
    dxs = np.array([dR * cos + zero, dT * sin + zero, dZ * cos + zero])  # δx_S (e_ρ, e_φ, e_z), (3, n, φ, unknowns)
    dxp = np.array([-(R + T) * sin, (T + R) * cos, -Z * sin + zero])  # δx_φ (∂e_ρ/∂φ = e_φ, ∂e_φ/∂φ = −e_ρ)
    dxh = np.array([R * cos + zero, T * sin + zero, zero])  # δx's horizontal part
    weight = np.repeat(W / AROUND, AROUND)  # per (node, φ), E per 2π
    flat = [x.reshape(3, NODES * AROUND, -1) for x in (dxs, dxp, dxh)]
    dxs, dxp, dxh = flat
    each = lambda q: np.repeat(q, AROUND)  # a quantity of S at every (node, φ)
    g0 = np.array([drho**2 + deta**2, 0 * rho, rho**2])
    grad, hess = (np.repeat(x, AROUND, axis=-1) for x in metric_derivatives(material, g0))
    xs0, rho_n = np.array([each(drho), 0 * each(rho), each(deta)]), each(rho)

    def form(left, right, scale):
        return left.T @ (scale[:, None] * right)

    g1 = np.array([2 * np.einsum("cn,cni->ni", xs0, dxs), np.einsum("cn,cni->ni", xs0, dxp) + rho_n[:, None] * dxs[1],
                   2 * rho_n[:, None] * dxp[1]])
    elastic = sum(form(dxs[c], dxs[c], weight * grad[0]) + form(dxp[c], dxp[c], weight * grad[2])
                  + 0.5 * (form(dxs[c], dxp[c], weight * grad[1]) + form(dxp[c], dxs[c], weight * grad[1]))
                  for c in range(3))
    elastic += 0.5 * sum(form(g1[a], g1[b], weight * hess[a, b]) for a in range(3) for b in range(3))
    # ½ x_h·(x_S × x_φ): second order ½ [δx_h·(δx_S × x_φ0 + x_S0 × δx_φ) + x_h0·(δx_S × δx_φ)], x_φ0 = ρ e_φ, x_h0 = ρ e_ρ
    linear = np.array([-rho_n[:, None] * dxs[2] + xs0[1][:, None] * dxp[2] - xs0[2][:, None] * dxp[1],
                       xs0[2][:, None] * dxp[0] - xs0[0][:, None] * dxp[2],
                       rho_n[:, None] * dxs[0] + xs0[0][:, None] * dxp[1] - xs0[1][:, None] * dxp[0]])
    volume = 0.5 * sum(form(dxh[c], linear[c], weight) for c in range(3))
    volume += 0.5 * (form(dxs[1], dxp[2], weight * rho_n) - form(dxs[2], dxp[1], weight * rho_n))
    H = 2 * elastic - P * (volume + volume.T)
    gram = 0.5 * sum(f[:, 0, :].T @ (W[:, None] * f[:, 0, :]) for f in (R, T, Z))
    return H, gram


def brute_force_lowest(material, L, P, state, count=MODES):
    """The eigenvalues of H c = μ G c, the sideways translation (R_0 = 1, T_0 = −1) removed, and their vectors."""
    H, G = brute_force_block(material, L, P, state, count)
    translation = np.zeros(H.shape[0])
    translation[0], translation[count] = 1.0, -1.0
    basis = np.linalg.qr(np.column_stack([G @ translation, np.eye(H.shape[0])]))[0][:, 1:]
    values, vectors = eigh(basis.T @ H @ basis, basis.T @ G @ basis)
    return values, basis @ vectors


@pytest.fixture(scope="module")
def bulge():
    """SPOM1, L = 10, degree 40: the bulge branch from the onset to V/V0 = 5, its m = 1 blocks and located zeros."""
    scene = tube_scene("SPOM1", 10.0, "[solver]\ndegree = 40\n[continuation]\nstep_max = 0.5\nstop_stretch = 5.0\n")
    primary = primary_branch(scene)
    branch = bulge_branch(scene, primary, primary.branch_points(Mirror.ODD)[0], stop_volume=5.0 * np.pi * scene.geometry.length)
    eq = Equilibrium(scene, branch.disc)
    modes = azimuthal.branch_modes(eq, np.column_stack([branch.states, branch.pressure]), branch.params, 1)
    fine = IntervalDiscretisation(branch.disc.degree, branch.disc.length, quadrature=NODES)
    return scene, branch, modes, crossings(scene, branch, modes), fine


@limited_blas
def second_method(scene, fine, u, P):
    return brute_force_lowest(scene.material, scene.geometry.length, P, fine.node_state(u))


def test_lowest_m1_eigenvalue_is_the_brute_force_second_variations(bulge):
    """At every third point of the bulge branch the three lowest m = 1 eigenvalues of the Galerkin block (degree 40)
    against the second method's (40 cosines per component, whose lowest eigenvalue changes by < 1e-9 from 48 to 64
    cosines): within 2e-6 (measured ≤ 5.1e-7, largest where the bulge is steepest; at degree 30 1.4e-5 there: the
    Galerkin block's own degree), the same unstable count at every point, and one unstable direction, the lowest
    −0.0723 (docs/tubes.md: −0.072300 at degree 30, −0.072302 at 40)."""
    scene, branch, modes, _, fine = bulge
    seen = []
    for i in range(0, len(branch.pressure), 3):
        values, _ = second_method(scene, fine, branch.states[i], branch.pressure[i])
        galerkin = modes.lowest[1][i]
        assert np.max(np.abs(galerkin - values[:3])) <= 2e-6, (i, galerkin, values[:3])
        assert int((values < 0).sum()) == modes.unstable[1][i]
        seen.append(values[0])
    assert max(int((v < 0)) for v in seen) == 1 and -0.0725 < min(seen) < -0.0720


def test_located_m1_zeros_are_zeros_of_the_brute_force_second_variation(bulge):
    """The two m = 1 zeros tube/azimuthal_crossings locates on the bulge branch (after its volume fold at V/V0 =
    2.7223: at P = 1.2262120, V/V0 = 2.8301697, and P = 0.8654444, V/V0 = 4.647265, docs/tubes.md): the second
    method's lowest eigenvalue at the located states is zero within 1e-6 (measured 1.1e-11 and −9.7e-8; its slope in
    P is ~0.25 there, so the second method's zeros lie within 4e-7 in P of the located ones), and its sign differs at
    the two points bracketing each."""
    scene, branch, modes, found, fine = bulge
    assert [(c.m, c.order, c.status.value) for c in found] == [(1, 0, "located")] * 2
    assert np.allclose([c.pressure for c in found], [1.226212, 0.865444], rtol=0, atol=1e-6)
    assert np.allclose([c.volume for c in found], [2.830170, 4.64727], rtol=0, atol=1e-5)
    for c in found:
        values, _ = second_method(scene, fine, c.u, c.pressure)
        assert abs(values[0]) <= 1e-6, (c.pressure, values[0])
        before, after = (second_method(scene, fine, branch.states[k], branch.pressure[k])[0][0]
                         for k in (c.index, c.index + 1))
        assert before * after < 0


def test_the_unstable_mode_bends_the_tube_at_the_bulge(bulge):
    """The second method's unstable eigenvector at the most unstable point (P ≈ 1.04, V/V0 ≈ 3.37): far from the
    bulge the tube moves sideways rigidly (T = −R, Z → 0 at S = L: |T + R| ≤ 5 % of |R|), the bulge's section at the
    mirror plane S = 0 the other way and several times as far (R(0) ≈ −10 R(L), T(0) ≈ 0: its centre moves with
    the cross-section's own hoop displacement), and the sections between tilt (Z ≠ 0): the tube bends at its bulge, a
    lateral buckle of the bulge, the route Hejazi, Hsiang & Phani (2021) report for bulges on tubes with fixed ends."""
    scene, branch, modes, _, fine = bulge
    i = int(np.argmin(modes.lowest[1][:, 0]))
    values, vectors = second_method(scene, fine, branch.states[i], branch.pressure[i])
    R, _, T, _, Z, _ = cosine_basis(np.array([0.0, 1.0, 10.0]), 10.0)
    r, t, z = R @ vectors[:, 0], T @ vectors[:, 0], Z @ vectors[:, 0]
    assert values[0] < -0.07 and abs(t[2] + r[2]) <= 0.05 * abs(r[2]) and abs(z[2]) <= 1e-12
    assert r[0] * r[2] < 0 and abs(r[0]) > 5 * abs(r[2]) and abs(t[0]) < 0.1 * abs(r[0])
    assert abs(z[1]) > abs(r[2])


def test_critical_mode_is_the_second_methods_null_vector(bulge):
    """At each located zero, the critical mode tube/azimuthal_crossings stores (tube/azimuthal.critical_mode, on the
    Legendre basis, ½ ∫ (R² + T² + Z²) dS = 1) against the second method's eigenvector of its eigenvalue nearest zero
    (on the cosines, the same norm): (R, T, Z) at 101 points of [0, L] within 1e-4 of the largest amplitude (measured
    1.4e-6 and 4.4e-5, the second zero's bulge steeper), up to the sign; the mode is largest at the bulge's mirror plane S = 0."""
    scene, branch, _, found, fine = bulge
    S = np.linspace(0.0, 10.0, 101)
    for c in found:
        values, vectors = second_method(scene, fine, c.u, c.pressure)
        R, _, T, _, Z, _ = cosine_basis(S, 10.0)
        theirs = np.array([f @ vectors[:, int(np.argmin(np.abs(values)))] for f in (R, T, Z)])
        ours = np.array(azimuthal.mode_profile(branch.disc, c.mode, S))
        theirs *= np.sign(np.sum(theirs * ours))
        scale = np.abs(ours).max()
        assert np.abs(ours - theirs).max() <= 1e-4 * scale
        assert np.argmax(np.linalg.norm(ours, axis=0)) == 0
