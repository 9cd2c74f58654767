"""Natural frequencies (balloon_cg.dynamics, codegen/inertia.py; MODEL.md §11) against closed forms derived here.

Units. A sphere of reference radius R0, thickness T0, density ρ, strain energy per reference volume W = (μ/2) Φ
(Φ the nondimensional Ogden sum, Σ μ_i α_i = 4), pressure P̄ = P T0 (μ/2)/R0. A displacement R0 ε u(θ) of the
sphere of radius λ R0 has potential energy 2π T0 R0² (μ/2) [E₀ + ½ ε² K(u)] and kinetic energy
2π ρ T0 R0⁴ ½ ε̇² M(u) (both per 2π as below), so ω² = (μ/2) ν/(ρ R0²) for K u = ν M u and Ω² = ω² R0² ρ/μ = ν/2.

Breathing mode (the sphere's radial equation of motion). The mass 4π R0² ρ T0 of the membrane moves with the radius
r = λ R0: m r̈ = 4π r² P̄ − 4π R0 T0 W'(λ), W(λ) = (μ/2) φ(λ), φ(λ) = Φ(λ, λ). Linearised at fixed P̄ about the
equilibrium: m R0 δλ̈ = (8π R0² P̄ λ − 4π R0 T0 W'') δλ, so ω² = (W'' − 2 P̄ R0 λ/T0)/(ρ R0²) and

    Ω² = (φ''(λ) − 2 P λ)/2,

and as the equilibrium is P = φ'/λ², Ω² = λ² (dP/dλ)/2: zero at the pressure maximum.

Spheroidal modes of degree n (linearised membrane equations on spherical harmonics). The displacement
u = U e_r + W e_θ, U = w P_n(cos θ), W = v dP_n(cos θ)/dθ, on the sphere of radius λ: x = (λ + εU) e_r + εW e_θ,
x_θ = ε(U' − W) e_r + (λ + ε(U + W')) e_θ, so λ1 = λ + εA + ε² B²/(2λ) + O(ε³), A = U + W', B = U' − W, and
λ2 = ρ/sin θ = λ + εC exactly, C = U + W cot θ. With Φ1 = Φ2, Φ11 = Φ22, Φ12 at (λ, λ) the ε² part of
∫ Φ sin θ dθ is ∫ [Φ1 B²/(2λ) + ½ Φ11 (A² + C²) + Φ12 A C] sin θ dθ. The volume per 2π,
V/2π = (1/3) ∫ ρ [a(a + b') − b(a' − b)] dθ (a = λ + εU, b = εW, ρ = a sin θ + b cos θ), has the ε² part
(1/3) ∫ [λ sin θ (U² + U W' − W U' + W²) + λ (U sin θ + W cos θ)(2U + W')] dθ. K(u) is twice the ε² part of
∫ Φ sin θ dθ − P V/2π, M(u) = ∫ (U² + W²) sin θ dθ; in x = cos θ every integrand is a polynomial, integrated
exactly by Gauss–Legendre. (w, v) → K, M by polarisation; Ω² = eig(K, M)/2 (two per n ≥ 1).
"""
import json
from pathlib import Path

import h5py
import numpy as np
import pytest
from numpy.polynomial import legendre
from scipy import linalg, optimize

import balloon_cg as bc
from balloon_cg.analysis.stability import azimuthal as az
from balloon_cg.analysis.results import Block, Status
from balloon_cg.app.cli import main
from balloon_cg.app.sweep import run_sweep
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import branch_system, equilibrium_of
from balloon_cg.dynamics.frequencies import branch_frequencies, frequencies, matching_block
from balloon_cg.dynamics.modes import block_modes
from balloon_cg.dynamics.pencil import mass_variation
from balloon_cg.dynamics.translation import DIRECTIONS
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.io.sweep_file import read_sweep
from balloon_cg.model.field import field_squared
from balloon_cg.post.plotting import MODE_AMPLITUDE, plot
from balloon_cg.scene import load_scene, shipped_scenes
from netcdf_groups import uncoordinated

ROOT = Path(__file__).resolve().parent.parent
DEGREE = 14
MATERIALS = {"neo-Hookean": ((2.0,), (2.0,)), "SPOM1": ((3.00508, 0.0145, -0.0177), (1.3, 4.0, -2.0))}


def ogden(name):
    mu, alpha = MATERIALS[name]
    return np.array(mu)[:, None], np.array(alpha)[:, None]


def phi_derivatives(name, lam):
    """Φ1, Φ11, Φ12 of Φ = Σ (μ/α)(λ1^α + λ2^α + (λ1 λ2)^−α − 3) at λ1 = λ2 = λ, and φ' , φ'' of φ(λ) = Φ(λ, λ)."""
    mu, alpha = ogden(name)
    lam = np.atleast_1d(np.asarray(lam, dtype=float))
    phi1 = np.sum(mu * (lam ** (alpha - 1) - lam ** (-2 * alpha - 1)), axis=0)
    phi11 = np.sum(mu * ((alpha - 1) * lam ** (alpha - 2) + (alpha + 1) * lam ** (-2 * alpha - 2)), axis=0)
    phi12 = np.sum(mu * alpha * lam ** (-2 * alpha - 2), axis=0)
    dphi = np.sum(mu * (2 * lam ** (alpha - 1) - 2 * lam ** (-2 * alpha - 1)), axis=0)  # φ' = 2 Φ1
    ddphi = np.sum(mu * (2 * (alpha - 1) * lam ** (alpha - 2) + 2 * (2 * alpha + 1) * lam ** (-2 * alpha - 2)), axis=0)
    return phi1, phi11, phi12, dphi, ddphi


def pressure(name, lam):
    """The sphere's equilibrium: 4π r² P̄ = 4π R0 T0 W'(λ) ⇔ P = φ'(λ)/λ² (MODEL.md §4's 2Σμ(λ^(α−3) − λ^(−2α−3)))."""
    return phi_derivatives(name, lam)[3] / np.asarray(lam) ** 2


def breathing(name, lam, P):
    """Ω² of the radial equation of motion linearised at fixed P (module docstring)."""
    return (phi_derivatives(name, lam)[4] - 2 * P * lam) / 2


def pressure_maximum(name):
    """dP/dλ = 0: φ'' λ² − 2 λ φ' = 0 (the first root above λ = 1)."""
    def slope(lam):
        _, _, _, dphi, ddphi = phi_derivatives(name, lam)
        return float(ddphi[0] * lam - 2 * dphi[0])
    grid = np.linspace(1.01, 6.0, 500)
    values = [slope(g) for g in grid]
    k = next(i for i in range(len(grid) - 1) if values[i] * values[i + 1] < 0)
    return optimize.brentq(slope, grid[k], grid[k + 1], xtol=1e-15, rtol=1e-15)


def spheroidal(name, lam, P, n):
    """The two Ω² of the degree-n spheroidal modes (module docstring), n ≥ 1."""
    phi1, phi11, phi12 = (float(d[0]) for d in phi_derivatives(name, lam)[:3])
    x, weights = legendre.leggauss(2 * n + 8)
    s = np.sqrt(1 - x * x)
    c = np.zeros(n + 1)
    c[n] = 1.0
    p, dp, ddp = (legendre.legval(x, legendre.legder(c, k)) for k in range(3))  # P_n and its x-derivatives

    def fields(w, v):
        U, dU = w * p, -w * s * dp  # d/dθ = −sin θ d/dx
        W = -v * s * dp
        dW = -v * (x * dp - s * s * ddp)
        W_cot = -v * x * dp  # W cot θ
        return U, dU, W, dW, W_cot

    def quadratic_forms(w, v):
        U, dU, W, dW, W_cot = fields(w, v)
        A, B, C = U + dW, dU - W, U + W_cot
        elastic = phi1 * B * B / (2 * lam) + 0.5 * phi11 * (A * A + C * C) + phi12 * A * C  # × sin θ dθ = dx
        # (1/3)[λ sin θ (U² + U W' − W U' + W²) + λ (U sin θ + W cos θ)(2U + W')] dθ, U sin θ + W cos θ = sin θ (U + W cot θ)
        volume = lam * (U * U + U * dW - W * dU + W * W) / 3 + lam * (U + W_cot) * (2 * U + dW) / 3  # × dx
        stiffness = 2 * weights @ (elastic - P * volume)
        mass = weights @ (U * U + W * W)
        return stiffness, mass

    def matrix(which):
        q = lambda w, v: quadratic_forms(w, v)[which]  # noqa: E731
        off = (q(1, 1) - q(1, 0) - q(0, 1)) / 2
        return np.array([[q(1, 0), off], [off, q(0, 1)]])

    return linalg.eigh(matrix(0), matrix(1), eigvals_only=True) / 2


def sphere(name, lam):
    """The equilibrium object (full basis, b_0 kept), the exact sphere of radius lam and its pressure."""
    scene = load_scene(ROOT / "scenes" / "spom1.toml").with_overrides({"material.preset": name})
    disc = Discretisation(DEGREE, symmetric=False, pin_translation=False)
    a, b = np.zeros(DEGREE + 1), np.zeros(DEGREE + 1)
    a[0], b[1] = lam, lam  # λ2 = λ, η = λ cos θ
    return Equilibrium(scene, disc), disc.join(a, b), float(pressure(name, lam)[0])


@pytest.fixture(scope="module", params=list(MATERIALS))
def material(request):
    eq, _, _ = sphere(request.param, 1.5)
    return request.param, eq, mass_variation(eq, DEGREE)


def sphere_frequencies(material, lam, m_max=0, count=4):
    name, eq, variation = material
    _, u, P = sphere(name, lam)
    return frequencies(variation, u, Parameters(P), True, m_max, count), P


def test_mass_matrices_are_the_kinetic_energy_of_the_displacement():
    """cᵀ M c = (1/2π) ∫∫ |δx|² dA for random coefficients c: m = 0 from δx = sin θ δλ2 e_ρ + δη e_z at the nodes
    of a finer rule, m = 1, 2, 3 from the Cartesian displacement (AzimuthalBasis.cartesian) on a θ × φ grid."""
    rng = np.random.default_rng(39)
    eq, _, _ = sphere("neo-Hookean", 1.5)
    variation = mass_variation(eq, DEGREE)
    c = rng.standard_normal(variation.basis.size)
    x, weights = legendre.leggauss(60)
    a, b = variation.basis.split(c)
    dlam2, deta = legendre.legval(x, a), legendre.legval(x, b)
    direct = weights @ ((1 - x * x) * dlam2**2 + deta**2)
    assert c @ variation.gram @ c == pytest.approx(direct, rel=1e-13)
    x, wx = legendre.leggauss(50)
    phi = 2 * np.pi * np.arange(24) / 24
    theta = np.repeat(np.arccos(x), phi.size)
    for m in (1, 2, 3):
        basis = az.AzimuthalBasis(m, 12, 40)
        c = rng.standard_normal(basis.size)
        dx = basis.cartesian(c, theta, np.tile(phi, x.size)).reshape(3, x.size, phi.size)
        direct = wx @ np.mean(np.sum(dx**2, axis=0), axis=1)  # (1/2π) ∫ dφ ∫ d(cos θ)
        assert c @ basis.gram @ c == pytest.approx(direct, rel=1e-13)


def test_breathing_mode_is_the_radial_equation_of_motion_along_the_sphere_branch(material):
    """Pressure control, held: the breathing mode's Ω² (in the 'even' block) equals (φ'' − 2Pλ)/2 to 1e-9 at
    every λ of the branch (the whole block's lowest values are the breathing mode and the even n ≥ 2 spheroidal
    pairs), and changes sign at the pressure maximum to 1e-10."""
    name = material[0]
    for lam in np.linspace(1.05, 4.0, 12):
        blocks, P = sphere_frequencies(material, lam)
        expected = np.sort(np.concatenate([[breathing(name, lam, P)[0]],
                                           *(spheroidal(name, lam, P, n) for n in (2, 4, 6))]))[:4]
        assert blocks["even"] == pytest.approx(expected, rel=1e-9, abs=1e-9)

    def lowest_even(lam):
        blocks, _ = sphere_frequencies(material, lam, count=1)
        return blocks["even"][0]

    peak = pressure_maximum(name)
    found = optimize.brentq(lowest_even, peak - 0.05, peak + 0.05, xtol=1e-14)
    assert abs(found - peak) < 1e-10
    if name == "neo-Hookean":
        assert peak == pytest.approx(7 ** (1 / 6), abs=1e-14)  # P = 4(1/λ − 1/λ⁷): λ⁶ = 7


@pytest.mark.parametrize("lam", [1.3, 2.5])
def test_spheroidal_modes_of_every_degree_are_in_every_block_m_up_to_n(material, lam):
    """Degrees n = 2..5: both spheroidal Ω² of the closed form appear in the m = 0 block of their parity and in
    every block m = 1..n (the sphere's degeneracy), each to 1e-9; the values found for one mode agree across m."""
    name = material[0]
    blocks, P = sphere_frequencies(material, lam, m_max=5, count=16)
    for n in range(2, 6):
        axisymmetric = blocks["even" if n % 2 == 0 else "odd_held"]
        for value in spheroidal(name, lam, P, n):
            found = [axisymmetric[np.argmin(abs(axisymmetric - value))]]
            found += [blocks[f"m{m}_held"][np.argmin(abs(blocks[f"m{m}_held"] - value))] for m in range(1, n + 1)]
            assert np.allclose(found, value, rtol=1e-9, atol=1e-9), (n, value, found)
            assert np.ptp(found) <= 1e-9 * max(1.0, abs(value))


def test_gas_stiffness_raises_and_the_volume_constraint_removes_the_breathing_mode(material):
    """Gas control (isothermal, P V = const): the breathing mode's stiffness gains (P/Ṽ)(dṼ/dλ)² = 6Pλ
    (Ṽ = ⅔λ³), so Ω²_gas = Ω² + 6Pλ/(2·2) (its mass ∫ sin θ dθ = 2); volume control leaves the even block
    without it (the n ≥ 2 modes keep their values: they keep the volume)."""
    name = material[0]
    for lam in (1.2, 1.6, 3.0):
        blocks, P = sphere_frequencies(material, lam, count=6)
        others = np.sort(np.concatenate([spheroidal(name, lam, P, n) for n in (2, 4, 6, 8)]))
        gas = breathing(name, lam, P)[0] + 1.5 * P * lam
        assert blocks["even_gas"] == pytest.approx(np.sort(np.append(others, gas))[:6], rel=1e-9, abs=1e-9)
        assert blocks["even_volume"] == pytest.approx(others[:6], rel=1e-9, abs=1e-9)


@pytest.fixture(scope="module")
def spom1_run(tmp_path_factory):
    """The SPOM1 whole picture to a pole stretch of 3 (an LP and the pear BP on the primary branch, a pear pair)
    with [dynamics] frequencies = true (m_max 1) and modes = true, analysed and written to a run file."""
    scene = load_scene(ROOT / "scenes" / "spom1.toml").with_overrides(
        {"continuation.stop_stretch": 3.0, "dynamics.frequencies": True, "dynamics.count": 4, "dynamics.modes": True})
    result = bc.analyse(scene)
    path = tmp_path_factory.mktemp("dynamics") / "spom1.h5"
    result.save(path)
    return result, path


def located_zeros(picture, zero: float | None = None) -> list:
    """The kinds of the located folds and branch points of ``picture``'s branches, after checking that one stored Ω²
    of each one's block (``matching_block``) is zero to ``zero`` (default the solver's tolerance) and that the points
    around it differ by one in that block's negative Ω² (the one that crossed: the lowest, or a higher one where a
    block already has a negative one)."""
    kinds = []
    for branch in picture.branches:
        for n, s in enumerate(branch.special):
            block = matching_block(s, branch)
            if block is None or s.status != Status.LOCATED:
                continue
            limit = branch.scene.solver.tol if zero is None else zero
            assert np.nanmin(np.abs(branch.frequencies.special[block][n])) <= limit, (branch.name, s)
            around = branch.frequencies.omega2[block][s.index:s.index + 2]
            assert np.diff((around < 0).sum(axis=1)) != 0, (branch.name, s, around)
            kinds.append(s.kind)
    return kinds


def test_located_special_points_have_a_vanishing_frequency_in_their_block(spom1_run):
    """At every located fold and branch point one stored Ω² of its block is zero and the points around it differ by
    one in that block's negative Ω² (``located_zeros``)."""
    result, _ = spom1_run
    assert len(located_zeros(result.picture)) >= 2  # the LP and the pear BP of the primary branch


def test_frequencies_are_stored_with_units_and_read_back(spom1_run):
    """frequencies/omega2_<block> (point, frequency) and special_omega2_<block> (special, frequency), units "1";
    bc.load and to_xarray give them back as computed; every group opens alone with its coordinates."""
    result, path = spom1_run
    primary = next(b for b in result.picture.branches if b.name == "primary")
    with h5py.File(path, "r") as f:
        group = f["branches/primary/frequencies"]
        assert group["omega2_even"].attrs["units"] == "1"
        assert "Ω²" in group["omega2_even"].attrs["long_name"]
        assert group.attrs["count"] == 4 and group.attrs["m_max"] == 1
        assert group["special_omega2_odd_held"].shape == (len(primary.special), 4)
    loaded = bc.load(path)
    stored = loaded.branches["primary"].data
    assert stored["frequencies"].keys() == primary.frequencies.omega2.keys()
    frame = loaded.to_xarray("primary")
    assert frame["omega2_even"].dims == ("point", "frequency") and frame["omega2_even"].attrs["units"] == "1"
    assert uncoordinated(path) == []  # frequencies/ opened alone: point, θ, special, frequency, component
    np.testing.assert_array_equal(frame["omega2_even"].values, primary.frequencies.omega2["even"])
    for block, values in primary.frequencies.omega2.items():
        np.testing.assert_array_equal(stored["frequencies"][block], values)
        np.testing.assert_array_equal(stored["special_frequencies"][block], primary.frequencies.special[block])


def unit_shape(shape):
    """A mode shape (components × θ) scaled to a largest magnitude of 1, that entry positive."""
    flat = shape.reshape(-1)
    return shape / flat[np.abs(flat).argmax()]


def test_the_fold_mode_is_the_branch_tangent(spom1_run):
    """At the primary branch's located LP the stored shape of the zero mode of the pressure-control block (even)
    is the branch's tangent there: the null vector of the equilibrium Jacobian ∂R/∂u (its smallest right singular
    vector), drawn as (δρ, δz) = (sin θ δλ2, δη), to 1e-6 after both are scaled to a largest entry of 1 (observed
    1e-15); the stored shapes are read back by bc.load, as (special, frequency, component, θ) with units and the θ
    scale of the profiles."""
    result, path = spom1_run
    primary = next(b for b in result.picture.branches if b.name == "primary")
    n, lp = next((n, s) for n, s in enumerate(primary.special) if s.kind.value == "LP")
    loaded = bc.load(path)
    data = loaded.branches["primary"].data
    theta = data["theta"]
    frame = loaded.to_xarray("primary")
    assert frame["modes_even"].dims == ("special", "frequency", "component", "theta")
    np.testing.assert_array_equal(frame["modes_even"].values, data["modes"]["even"])
    shape = data["modes"]["even"][n, 0]
    assert abs(data["special_frequencies"]["even"][n, 0]) < 1e-11
    np.testing.assert_array_equal(shape, primary.frequencies.modes["even"][n, 0])
    J = branch_system(primary).jacobian(lp.X)[:, :-1]
    null = linalg.svd(J)[2][-1]
    lam2, _, eta, _ = primary.disc.evaluate(null, theta)
    tangent = np.stack([np.sin(theta) * lam2, eta, np.zeros_like(eta)])
    np.testing.assert_allclose(unit_shape(shape), unit_shape(tangent), atol=1e-6)
    with h5py.File(path, "r") as f:
        stored = f["branches/primary/frequencies/modes_even"]
        assert stored.attrs["units"] == "1" and stored.shape == (len(primary.special), 4, 3, theta.size)
        assert stored.dims[3][0].name.endswith("/theta")


def test_the_modes_have_their_frequencies_and_the_kinetic_energy_as_mass(spom1_run):
    """At every special point of the run, for every block: ``block_modes`` (the pencil solved on the null space of
    its constraints) gives the stored Ω² to 1e-10, and each mode has unit modal mass (1/2π)∫∫|δx|² dA = 1 on a
    Gauss rule (its shape on Gauss nodes in θ: ∫(δρ² + δz²) dx for m = 0, ½∫(δρ² + δz² + δφ²) dx for m ≥ 1) to
    1e-10."""
    result, _ = spom1_run
    x, w = legendre.leggauss(120)
    for branch in result.picture.branches:
        eq, found = equilibrium_of(branch), branch.frequencies
        for n, s in enumerate(branch.special):
            variation = mass_variation(eq, int(found.degree[s.index:s.index + 2].max()))
            for block, stored in found.special.items():
                omega2, shapes = block_modes(variation, s.X[:-1], branch.params_at(s.X), branch.disc.symmetric,
                                             block, found.count, np.arccos(x))
                np.testing.assert_allclose(omega2, stored[n, :omega2.size], atol=1e-10, rtol=1e-10)
                weight = 0.5 if Block.order_of(block) else 1.0
                np.testing.assert_allclose(weight * (shapes ** 2).sum(axis=1) @ w, 1.0, atol=1e-10)


def test_free_translation_modes_become_the_rigid_translations_as_the_field_vanishes():
    """Two opposed coils at a small M: the lowest mode of the free blocks is the translation the field pulls
    (Ω² < 0), tending to the rigid translation as M → 0 (without a field the translation is no mode of any block:
    it is removed as a zero mode). At M = 1e-9: along the axis (odd_free) δz = 1/√2, δρ = 0 (unit modal mass);
    across it (m1_free) R = 1/√2, T = −1/√2, Z = 0 (δx uniform), to 1e-6; the distance falls as M (x100 ± 1%
    from M = 1e-7)."""
    theta = np.linspace(0.0, np.pi, 91)
    rigid = {"odd_free": (0.0, 2 ** -0.5, 0.0), "m1_free": (2 ** -0.5, 0.0, -2 ** -0.5)}
    distance = {}
    for M in (1e-7, 1e-9):
        scene = load_scene(ROOT / "scenes" / "spom1_two_coils_M0.002.toml").with_overrides({"field.M": M})
        branch = trace_primary(scene, stop_stretch=1.5, down=False)
        X = branch.X[-1]
        variation = mass_variation(equilibrium_of(branch), max(20, branch.disc.degree))
        for block, expected in rigid.items():
            omega2, shapes = block_modes(variation, X[:-1], branch.params_at(X), True, block, 2, theta)
            assert omega2[0] < 0
            distance[M, block] = np.abs(shapes[0] - np.array(expected)[:, None]).max()
    for block in rigid:
        assert distance[1e-9, block] < 1e-6
        assert distance[1e-7, block] / distance[1e-9, block] == pytest.approx(100.0, rel=0.01)


def test_inspect_tables_the_special_points_and_json_lists_the_frequencies(spom1_run, capsys):
    _, path = spom1_run
    assert main(["inspect", str(path)]) == 0
    text = capsys.readouterr().out.split("branch primary")[1].split("\nbranch ")[0]
    assert "lowest Ω² = ω² R0² ρ/μ per block at the special points" in text
    assert main(["inspect", str(path), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)["branches"]["primary"]
    stored = bc.load(path).branches["primary"].data
    assert summary["frequencies"]["even"] == pytest.approx(stored["frequencies"]["even"][:, 0], rel=0, abs=0)
    lp = next(n for n, s in enumerate(summary["special_points"]) if s["kind"] == "LP")
    assert abs(summary["special_frequencies"]["even"][lp]) < 1e-11


@pytest.mark.parametrize("key, value, allowed", [("count", "0", "an integer in [1, 50]"),
                                                 ("m_max", "9", "an integer in [0, 8]"),
                                                 ("frequencies", "1", "true or false"),
                                                 ("modes", "1", "true or false")])
def test_bad_dynamics_values_are_one_line_and_exit_2(tmp_path, capsys, key, value, allowed):
    out = tmp_path / "run.h5"
    assert main(["run", "spom1", "--set", f"dynamics.{key}={value}", "-o", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"dynamics.{key} = {value}: must be {allowed}" in err
    assert not out.exists()


def test_modes_need_the_frequencies(tmp_path, capsys):
    out = tmp_path / "run.h5"
    assert main(["run", "spom1", "--set", "dynamics.modes=true", "-o", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "dynamics.modes = true: needs dynamics.frequencies = true" in err
    assert not out.exists()


def test_frequency_pressure_figure(spom1_run, tmp_path):
    """plot --what frequencies: Ω² of every block against P, the LP and the pear BP marked at Ω² = 0."""
    _, path = spom1_run
    out = tmp_path / "frequencies.png"
    assert main(["plot", str(path), "--what", "frequencies", "-o", str(out)]) == 0
    assert out.read_bytes().startswith(b"\x89PNG")
    fig = plot([path], "frequencies")
    ax = fig.axes[0]
    assert ax.get_ylabel().startswith(r"$\Omega^2")
    marked = [line for line in ax.lines if line.get_marker() in ("o", "D") and len(line.get_xdata()) == 1]
    assert len(marked) >= 2 and all(line.get_ydata()[0] == 0.0 for line in marked)


def test_frequency_figure_insets_the_mode_of_each_block(spom1_run):
    """With stored mode shapes the frequency figure has an inset per block of the first branch (the primary): its
    lowest mode at the special point where that Ω² is nearest zero (the even block's at the LP, odd_held's at the
    pear BP), the outline and the outline ± the stored δρ, δz scaled to MODE_AMPLITUDE of the largest radius."""
    result, path = spom1_run
    primary = next(b for b in result.picture.branches if b.name == "primary")
    fig = plot([path], "frequencies")
    insets = {ax.get_title().split(":")[0]: ax for ax in fig.axes[1:]}
    assert set(insets) == set(primary.frequencies.modes)
    for block, kind in (("even", "LP"), ("odd_held", "BP")):
        n = next(n for n, s in enumerate(primary.special) if s.kind.value == kind)
        assert insets[block].get_title().endswith(f" {kind}")
        outline, plus = insets[block].lines[0], insets[block].lines[1]
        shape = primary.frequencies.modes[block][n, 0]
        rho = outline.get_xdata()
        scale = MODE_AMPLITUDE * rho.max() / np.abs(shape[:2]).max()
        np.testing.assert_allclose(plus.get_xdata() - rho, scale * shape[0], atol=1e-12)
        np.testing.assert_allclose(plus.get_ydata() - outline.get_ydata(), scale * shape[1], atol=1e-12)


def test_mode_figure(spom1_run, tmp_path, capsys):
    """plot --what modes: a panel per fold and branch point, the outline (black) and the outline ± the stored
    mode of the Ω² nearest zero, scaled to MODE_AMPLITUDE of the largest radius: at the LP the even block's
    breathing-like mode, drawn from the stored δρ, δz; a run without modes fails with one line (exit 2)."""
    result, path = spom1_run
    out = tmp_path / "modes.png"
    assert main(["plot", str(path), "--what", "modes", "-o", str(out)]) == 0
    assert out.read_bytes().startswith(b"\x89PNG")
    fig = plot([path], "modes")
    primary = next(b for b in result.picture.branches if b.name == "primary")
    crossings = [s for b in result.picture.branches for s in b.special if s.kind.value in ("LP", "LV", "LN", "BP")]
    panels = [ax for ax in fig.axes if ax.get_visible()]
    assert len(panels) == len(crossings)
    n = next(n for n, s in enumerate(primary.special) if s.kind.value == "LP")
    assert "LP, even" in panels[0].get_title()
    outline, plus = panels[0].lines[0], panels[0].lines[1]
    shape = primary.frequencies.modes["even"][n, 0]
    rho = outline.get_xdata()
    scale = MODE_AMPLITUDE * rho.max() / np.abs(shape[:2]).max()
    np.testing.assert_allclose(plus.get_xdata() - rho, scale * shape[0], atol=1e-12)
    np.testing.assert_allclose(plus.get_ydata() - outline.get_ydata(), scale * shape[1], atol=1e-12)
    bare = tmp_path / "bare.h5"
    bc.analyse(load_scene("spom1").with_overrides({"continuation.stop_stretch": 2.0, "surface.branches": "none",
                                                   "dynamics.frequencies": True})).save(bare)
    capsys.readouterr()
    assert main(["plot", str(bare), "--what", "modes", "-o", str(tmp_path / "no.png")]) == 2
    message = capsys.readouterr().err.strip().splitlines()
    assert len(message) == 1 and "modes = true" in message[0]


def test_rigid_translations_are_zero_frequencies_without_a_field(spom1_run):
    """M = 0: the free balloon's rigid translations (axial and lateral) cost nothing: Ω²_t = 0 at every point."""
    result, _ = spom1_run
    for branch in result.picture.branches:
        for values in branch.frequencies.translation.values():
            assert np.abs(values).max() < 1e-12


def field_translation_omega2(eq, u, chi, M, direction):
    """Ω²_t of a rigid translation in a field from the field energy alone: −½χM d²/dε² (1/2π)∫∫H²(x0 + ε e) dA
    (the membrane and the pressure do not see a translation) over its mass (1/2π)∫∫|e|² dA = 2, halved (units),
    the second difference in ε with one Richardson step, H² from the coil field at the 3D points."""
    x, w = legendre.leggauss(72)
    theta = np.arccos(x)
    lam2, _, eta, _ = eq.disc.evaluate(u, theta)
    phi = 2 * np.pi * np.arange(48) / 48
    points = np.stack([np.outer(lam2 * np.sin(theta), np.cos(phi)), np.outer(lam2 * np.sin(theta), np.sin(phi)),
                       np.outer(eta, np.ones_like(phi))])
    shift = np.zeros(3)
    shift[{"axial": 2, "lateral": 0}[direction]] = 1.0

    def field_integral(eps):
        y = points + eps * shift[:, None, None]
        r = np.hypot(y[0], y[1])
        H2 = np.array([[field_squared(r[i, j], y[2][i, j], eq.coils)[0] for j in range(phi.size)]
                       for i in range(x.size)])
        return w @ H2.mean(axis=1)

    e = 1e-2
    d2 = [(field_integral(h) + field_integral(-h) - 2 * field_integral(0.0)) / h**2 for h in (e, e / 2)]
    d2 = (4 * d2[1] - d2[0]) / 3
    return 0.5 * (-0.5 * chi * M * d2) / 2.0


def test_rigid_translations_in_a_field_are_the_field_stiffness():
    """Two opposed coils, M = 0.002, a point of the primary branch: the stored Ω²_t of each translation equals the
    field's second difference along it (``field_translation_omega2``) to 1e-6; the field pulls the paramagnetic
    balloon away from the centre both along and across the axis (Ω²_t < 0: |H|² of a current-free field is
    subharmonic, so no position restores it in every direction)."""
    scene = load_scene(ROOT / "scenes" / "spom1_two_coils_M0.002.toml")
    branch = trace_primary(scene, stop_stretch=1.5, down=False)
    found = branch_frequencies(branch, count=2, m_max=1)
    eq, X = equilibrium_of(branch), branch.X[-1]
    for direction in DIRECTIONS:
        expected = field_translation_omega2(eq, X[:-1], branch.params.chi, branch.params.M, direction)
        assert found.translation[direction][-1] == pytest.approx(expected, rel=1e-6)
    assert found.translation["axial"][-1] < 0 and found.translation["lateral"][-1] < 0


def test_a_sweep_stores_each_members_frequencies(tmp_path):
    """[dynamics] in a sweep over M (two opposed coils, primary branches to a pole stretch of 1.3): every member's
    branch carries its frequencies in the sweep file (and with modes = true their shapes at the special points),
    and the field retunes them (M = 0.001 against 0.003 at the first point, the same pole stretch)."""
    scene = load_scene(ROOT / "scenes" / "spom1_two_coils_M0.002.toml").with_overrides(
        {"continuation.stop_stretch": 1.3, "dynamics.frequencies": True, "dynamics.m_max": 0, "dynamics.modes": True})
    out = tmp_path / "sweep.h5"
    run_sweep(scene, ["M=0.001,0.003"], out, mode="primary-only", workers=1)
    members = read_sweep(out)["members"]
    even = [members[k]["branches"]["primary"]["frequencies"]["even"][0, 0] for k in sorted(members)]
    assert len(even) == 2 and np.all(np.isfinite(even)) and abs(even[1] - even[0]) > 1e-6
    for member in members.values():
        primary = member["branches"]["primary"]
        assert primary["modes"]["even"].shape == (len(primary["special_points"]), 3, 3, primary["theta"].size)


def test_continue_keeps_the_frequencies_a_scene_asks_for(spom1_run, tmp_path):
    """`continue` from the LP of a run with [dynamics] frequencies and modes: the branch traced again carries them,
    zero at its own located LP, and the mode shapes there."""
    _, path = spom1_run
    lp = next(s for s in bc.load(path).special_points if s["kind"] == "LP" and s["branch"] == "primary")
    out = tmp_path / "again.h5"
    assert main(["continue", str(path), str(lp["label"]), "-o", str(out)]) == 0
    again = bc.load(out).branches["primary"].data
    kinds = [s["kind"] for s in again["special_points"]]
    assert "frequencies" in again and "LP" in kinds
    assert abs(again["special_frequencies"]["even"][kinds.index("LP"), 0]) < 1e-11
    assert np.isfinite(again["modes"]["even"][kinds.index("LP"), 0]).all()


def resolved_zero(branch, special, block: str, omega2) -> float:
    """The tolerance of a zero Ω² at a located point of ``branch``: solver.tol on a branch stored in x (the
    perturbation basis holds the equilibrium's own Jacobian); on a wire-mapped branch max_error, or the Ω²'s own
    resolution where that is coarser: its change from the point's degree N to 1.5N (its perturbations in x resolve
    the mapped equilibrium to about max_error, but near a wire the eigenvalue of a fold moves in the degree: the
    paper coil's pear_free_2 LP reads 2.4e-9, -7.9e-9, 6.3e-10, -8.8e-9 at N = 320, 480, 560, 640)."""
    scene = branch.scene
    if branch.disc.mapping is None:
        return scene.solver.tol
    degree = int(branch.frequencies.degree[special.index:special.index + 2].max())
    finer = frequencies(mass_variation(equilibrium_of(branch), 3 * degree // 2), special.X[:-1],
                        branch.params_at(special.X), branch.disc.symmetric, branch.frequencies.m_max,
                        branch.frequencies.count)[block]
    nearest = np.nanargmin(np.abs(omega2))
    return max(scene.solver.max_error, abs(finer[nearest] - omega2[nearest]))


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(n for n in shipped_scenes() if not n.startswith("tube_")))  # tubes: test_dynamics_tube
def test_every_located_special_point_of_a_shipped_scene_has_a_zero_frequency(name):
    """The whole picture of a shipped scene with [dynamics] (count 6, m_max as the stability's): at every located
    fold and branch point one stored Ω² of its block is zero to the point's own tolerance (``resolved_zero``),
    the reflected mirror's rejoin BP included (its state on the mirrored wire map: analysis/switching/mirror.py)."""
    scene = load_scene(name)
    scene = scene.with_overrides({"dynamics.frequencies": True, "dynamics.count": 6,
                                  "dynamics.m_max": scene.stability.m_max})
    result = bc.analyse(scene)
    checked = 0
    for branch in result.picture.branches:
        for n, s in enumerate(branch.special):
            block = matching_block(s, branch)
            if block is not None and s.status == Status.LOCATED:
                omega2 = branch.frequencies.special[block][n]
                assert np.nanmin(np.abs(omega2)) <= resolved_zero(branch, s, block, omega2), (branch.name, s)
                checked += 1
    assert checked
