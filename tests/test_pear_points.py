"""Pear-shaped equilibria in a field (one coil of radius 2 and the paper's two coils, M = 0.001): the m = 1 claim
of docs/paper.md checked by a second method (balloon_cg.analysis.stability.brute_force: the held m = 1 block from the
directly integrated 3D energy on a (θ, φ) grid, differenced numerically, against analysis.stability.azimuthal's generated
second variation; the longer study over whole traced pear branches is benchmarks/m1_brute_force.py), and the
energy landscape off the branch point (analysis.switching.landscape, Fig. 13)."""
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.points import branch_points as bifurcation
from balloon_cg.analysis.stability import azimuthal as az, brute_force as bf
from balloon_cg.analysis.switching.landscape import landscape, state_at
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.results import Block
from balloon_cg.analysis.stability.axisymmetric import assess_branch
from balloon_cg.analysis.switching.pear import trace_pear
from balloon_cg.scene import load_scene

SCENES = Path(__file__).resolve().parent.parent / "scenes"
N = 12  # perturbation degree of both methods (the same space, built differently)


def pear_branch(scene):
    """A short pear branch from the first pear pitchfork of the primary branch (5 continuation points)."""
    scene = scene.with_overrides({"continuation.stop_stretch": 1.75, "stability.m_max": 0})
    primary = trace_primary(scene)
    primary.stability, _ = assess_branch(primary, scene.stability.degree, True)
    index, block, k = next(p for p in bifurcation.detect(primary, primary.stability) if p[1] == Block.ODD_HELD)
    bp = bifurcation.locate(primary, index, block, k)
    short = dataclasses.replace(primary, scene=scene.with_overrides({"continuation.max_points": 8}))
    return trace_pear(short, bp, 1.0, "pear")


@pytest.fixture(scope="module")
def one_coil():
    """One coil of radius 2 in the equatorial plane (the membrane comes within 0.3 of its wire here)."""
    return pear_branch(load_scene(SCENES / "spom1_single_coil.toml").with_overrides(
        {"field.M": 0.001, "field.coils[0].radius": 2.0, "continuation.wire_gap": 0.05}))


@pytest.fixture(scope="module")
def two_coils():
    return pear_branch(load_scene(SCENES / "spom1_two_coils_M0.001.toml"))


@pytest.fixture(params=["one_coil", "two_coils"])
def pear(request):
    branch = request.getfixturevalue(request.param)
    assert not branch.disc.symmetric and len(branch.X) >= 3
    return branch


def state(branch, i):
    X = branch.X[i]
    return X[:-1], branch.params.with_value("P", X[-1])


def grid(branch, factor=1.0, n_phi=12):
    return bf.Grid(int(factor * (2 * (N + branch.disc.degree) + 20)), n_phi)


def test_assembled_hessian_is_the_second_difference_of_the_integrated_energy(pear):
    """cᵀHc of the node-wise differenced density equals d²E/dε² of the whole integrated energy (Richardson)."""
    u, params = state(pear, 1)
    g = grid(pear)
    block = bf.m1_block(pear.disc, pear.scene, u, params, N, g)
    c = np.random.default_rng(3).normal(size=block.H.shape[0]) / np.arange(1, block.H.shape[0] + 1)
    direction = bf.basis_vectors(g, N) @ c
    E = lambda eps: bf.energy(pear.disc, pear.scene, u, params, g, eps * direction)  # noqa: E731
    d2 = lambda eps: (E(eps) + E(-eps) - 2 * E(0.0)) / eps**2  # noqa: E731
    assert c @ block.H @ c == pytest.approx((4 * d2(5e-4) - d2(1e-3)) / 3, rel=1e-6)


def test_held_m1_eigenvalue_of_pear_points_is_negative_by_both_methods(pear):
    """On the pear points the lowest held m = 1 eigenvalue is negative (a constrained direction of negative
    second variation: unstable, at any N) and both methods give the same value on the same space to 1e-6."""
    eq = equilibrium_of(pear)
    for i in (0, len(pear.X) - 1):
        u, params = state(pear, i)
        brute = bf.m1_block(pear.disc, pear.scene, u, params, N, grid(pear)).lowest(2, held=True)
        generated = az.spectrum(eq, u, params, 1, N, 2, held=True)
        assert brute[0] < -1e-2
        assert brute == pytest.approx(generated, rel=1e-6, abs=1e-8)


def test_brute_force_eigenvalue_is_converged_in_the_grid_and_the_step(one_coil):
    """1.5 times the nodes in θ, 16 instead of 12 in φ, and half the difference step change the lowest held value
    by < 1e-7 (the point nearest the wire)."""
    pear = one_coil
    u, params = state(pear, len(pear.X) - 1)
    base = bf.m1_block(pear.disc, pear.scene, u, params, N, grid(pear)).lowest(1)[0]
    finer = bf.m1_block(pear.disc, pear.scene, u, params, N, grid(pear, 1.5, 16)).lowest(1)[0]
    smaller = bf.m1_block(pear.disc, pear.scene, u, params, N, grid(pear), step=bf.STEP / 2).lowest(1)[0]
    assert abs(finer - base) < 1e-7 * max(1.0, abs(base))
    assert abs(smaller - base) < 1e-7 * max(1.0, abs(base))


def test_landscape_off_the_branch_point(two_coils):
    """At the last pear point's pressure: the symmetric state (solved from the primary side) and the pear state
    are stationary points of ΔΠ at Λ = 0 and Λ = |u_p − u_s|; μ = −dΔΠ/dΛ (the derivative of a degree-8 fit
    of the samples); past a supercritical pitchfork the pear state lies below the symmetric one."""
    pear = two_coils
    u_pear, params = state(pear, len(pear.X) - 1)
    eq = equilibrium_of(pear)
    u_sym = state_at(eq, params, u_pear - 0.9 * (u_pear - pear.X[0, :-1]), params.P, pear.scene.solver)
    assert np.linalg.norm(u_pear - u_sym) > 1e-3
    land = landscape(eq, params, u_sym, u_pear, pear.scene.solver, samples=11)
    found = land.equilibria
    assert np.abs(found).min() < 1e-12 and np.abs(found - land.pear_amplitude).min() < 5e-3 * land.pear_amplitude
    fit = np.polynomial.Polynomial.fit(land.amplitude, land.energy, 8)
    slope = fit.deriv()(land.amplitude)
    assert -land.multiplier == pytest.approx(slope, abs=1e-4 * np.abs(slope).max())
    lowest = land.amplitude[np.argmin(land.energy)]  # a double well: the pear state is the minimum on its side
    assert abs(abs(lowest) - land.pear_amplitude) <= np.diff(land.amplitude)[0] and land.energy.min() < 0
