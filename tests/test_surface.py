"""The whole-sphere engine (surface/, MODEL.md §8) against the axisymmetric solver and the azimuthal second variation:
its Hessian against finite differences, axisymmetric states as its equilibria, the sphere's spectrum as the union
of the m-blocks, the exact zero modes, and the gauge."""
from pathlib import Path

import h5py
import numpy as np
import pytest
from scipy import linalg

from balloon_cg.analysis.stability import azimuthal as az
from balloon_cg.galerkin.coordinate_map import WireMap
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.model.sphere import sphere_pressure
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import load_scene, parse_scene
from balloon_cg.surface import stability
from balloon_cg.surface.basis import EQUATOR, HALF_TURN, INVERSION, MIRROR_Y, SphericalBasis
from balloon_cg.surface.embedding import axisymmetric_coefficients, displacement_coefficients, mode_coefficients
from balloon_cg.surface.equilibrium import SurfaceEquilibrium
from balloon_cg.surface.gauge import FieldSymmetry, Gauge, UnsupportedGauge
from balloon_cg.surface.measures import axial_stretch_row, measures
from balloon_cg.surface.system import SurfaceSystem

import shared_pictures

ROOT = Path(__file__).resolve().parent.parent


def sphere(scene, stretch, degree):
    """The axisymmetric problem on the full (m = 0) basis and the exact sphere of radius ``stretch``."""
    disc = Discretisation(degree, symmetric=False, pin_translation=False)
    a, b = np.zeros(degree + 1), np.zeros(degree + 1)
    a[0], b[1] = stretch, stretch
    voltage = 0.0 if scene.electric is None else scene.electric.voltage
    return (Equilibrium(scene, disc), disc.join(a, b),
            Parameters(sphere_pressure(scene.material, stretch, voltage), voltage=voltage))


@pytest.mark.parametrize("semi_axes", [(1.3, 1.3, 0.8), (1.0, 1.0, 1.4), (1.3, 1.2, 0.8)])
def test_the_tilt_is_that_of_the_body_axis_whether_elongated_or_flattened(semi_axes):
    """Spheroids with their axis (the third) turned by 30° about e_y: flattened along it (oblate), elongated
    (prolate), and a flattened body with unequal other axes: the tilt is 30° (the axis of the largest moment of the
    oblate body is any direction normal to its axis: it read 60°–90°)."""
    basis = SphericalBasis(6, (MIRROR_Y,))
    X = basis.nodes["reference"][:3]
    t = np.radians(30.0)
    turn = np.array([[np.cos(t), 0.0, np.sin(t)], [0.0, 1.0, 0.0], [-np.sin(t), 0.0, np.cos(t)]])
    c = displacement_coefficients(basis, turn @ (np.array(semi_axes)[:, None] * X) - X)
    assert measures(basis, c)["tilt"] == pytest.approx(30.0, abs=1e-9)


@pytest.fixture(scope="module")
def spom1():
    return load_scene(ROOT / "scenes" / "spom1.toml")


@pytest.mark.parametrize("symmetry", [(), (MIRROR_Y,), (MIRROR_Y, EQUATOR), (MIRROR_Y, INVERSION),
                                      (MIRROR_Y, HALF_TURN, EQUATOR)])
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


@pytest.mark.parametrize("symmetry, characters, n_phi", [((), (), 0), ((MIRROR_Y, EQUATOR), (-1, 1), 0),
                                                         ((MIRROR_Y,), (1,), 7), ((HALF_TURN,), (-1,), 6)])
def test_the_gather_plan_is_the_discrete_phi_sum_of_every_block_pair(symmetry, characters, n_phi):
    """The plan the Hessian contracts (product-to-sum on the φ-Fourier table) against the sum over the φ-nodes itself,
    Σ_k W_j f_jk p^e_b(φ_k) p^e'_b'(φ_k), for every block pair and φ-type pair, with N_φ at the basis' default and
    below 2M (frequencies m + m' alias mod N_φ)."""
    basis = SphericalBasis(6, symmetry, characters, n_phi=n_phi, order=4 if n_phi else -1)
    f = np.random.default_rng(3).standard_normal((basis.n_theta, basis.n_phi))
    fourier = basis.fourier_table(f)[0]  # (n_theta, 2 N_φ)
    phis, weights = basis.tables["phi"], basis.nodes["weights"]
    components = basis.tables["components"]
    for c in range(3):
        for c2 in range(3):
            i1, i2, a1, a2 = basis._products[c, c2]
            rows, cols = components[c]["blocks"], components[c2]["blocks"]
            for e in (0, 1):
                for e2 in (0, 1):
                    direct = np.einsum("jk,bk,ck->jbc", weights[:, None] * f, phis[rows, e], phis[cols, e2])
                    gathered = (a1[e, e2] * fourier[:, i1[e, e2]] + a2[e, e2] * fourier[:, i2[e, e2]])
                    assert np.abs(gathered - direct).max() <= 1e-13 * np.abs(direct).max()


def test_sphere_spectrum_is_the_union_of_the_azimuthal_blocks(spom1):
    """MODEL.md §8 check: at a sphere state (M = 0) the 2D Hessian in the mirror sector y → −y (the cos mφ family of
    every m: no torsion) has the eigenvalues of the axisymmetric m = 0 Hessian and of the m = 1..L blocks of
    analysis/stability/azimuthal.py, in the same displacement norm; the lowest 40 (every sphere mode of degree n well below L,
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
    ('[material]\npreset = "neo-Hookean"\n[electric]\nvoltage = 0.3\n', 1.6),
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
    system = SurfaceSystem(eq, Gauge(basis, held=True, field_symmetry=FieldSymmetry.NONE), params)
    row, offset = axial_stretch_row(basis)
    X0 = system.point(c + 0.01 * np.random.default_rng(3).standard_normal(basis.size), params.P * 1.05)
    X0[:-1] = system.gauge.reduce(system.gauge.expand(X0[:-1]))
    reduced_row = np.append(system.gauge.reduce(row), 0.0)
    result = newton(system.residual, system.jacobian, X0, reduced_row, stretch - offset, 1e-13, 30)
    assert result.converged
    assert abs(result.x[-1] - params.P) <= 1e-10 * params.P


def test_an_even_mode_keeps_the_half_turn(two_coil_picture, spom1):
    """The branch of an m-mode keeps the rotation by π about the axis exactly when m is even (mode_symmetry on the
    lowest held m-block eigenvector, a simple one, at the first m = 1 point of the two-coil scene, an equator-symmetric
    branch: m = 1 even in z, m = 2 and 4 odd in z keep no z-reflection, m = 3 keeps the inversion); the embedded mode
    lies wholly in the returned subspace and has no part in a smaller one. (At a sphere the
    lowest eigenvalue of an m-block is double and its eigenvector of no definite parity.) At a sphere state the
    sectors of (MIRROR_Y, HALF_TURN) hold the mirror subspace's spectrum to 1e-9."""
    from dataclasses import replace

    from balloon_cg.analysis.surface.branches import critical_mode, mode_symmetry

    primary = two_coil_picture.primary
    bp = next(s for s in primary.branch_points() if s.m == 1 and s.block.held)
    for m in (1, 2, 3, 4):
        az_basis, vector = critical_mode(primary, replace(bp, m=m), 12)
        symmetry = mode_symmetry(primary, az_basis, vector, 12)
        assert (HALF_TURN in symmetry) == (m % 2 == 0) and symmetry[0] == MIRROR_Y, (m, symmetry)
        whole = np.linalg.norm(mode_coefficients(SphericalBasis(12, (MIRROR_Y,)), az_basis, vector))
        part = np.linalg.norm(mode_coefficients(SphericalBasis(12, symmetry), az_basis, vector))
        assert abs(part - whole) <= 1e-10 * whole
        for reflection in {EQUATOR, INVERSION} - set(symmetry):  # none other is kept (the largest group)
            if not (HALF_TURN in symmetry and {EQUATOR, INVERSION} & set(symmetry)):
                smaller = SphericalBasis(12, (*symmetry, reflection))
                assert np.linalg.norm(mode_coefficients(smaller, az_basis, vector)) <= 1e-10 * whole
    eq1, u, params = sphere(spom1, 1.5, 12)
    mirror = SphericalBasis(8, (MIRROR_Y,))
    eq = SurfaceEquilibrium(spom1, mirror)
    c = axisymmetric_coefficients(mirror, eq1.disc, u)
    ours = np.sort(linalg.eigvalsh(eq.hessian(c, params)))
    halves = []
    for sector in SphericalBasis(8, (MIRROR_Y, HALF_TURN)).sectors():
        if sector.characters[0] == 1:
            halves += list(linalg.eigvalsh(eq.hessian(c, params, sector)))
    assert len(halves) == mirror.size
    assert np.abs(np.sort(halves) - ours).max() <= 1e-9 * np.abs(ours).max()


def test_the_critical_mode_of_a_later_crossing_is_the_one_that_crosses(two_coil_picture):
    """At the second held m = 1 point of the two-coil scene (P = 1.965, past the pressure maximum, the membrane near
    the wires) the lowest m = 1 eigenvalue is already negative (it crossed at the first point): the critical mode is
    the eigenvector whose eigenvalue is zero there (|μ| ≤ 1e-6 against a lowest μ < −1), at the perturbation degree
    the point was located at (320; at stability.degree the crossing eigenvalue reads 0.13: unresolved). The lowest
    mode, or the one nearest zero at stability.degree, could not start a branch (the first correction landed on
    another branch)."""
    from balloon_cg.analysis.branches.problem import equilibrium_of
    from balloon_cg.analysis.surface.branches import critical_mode, located_degree

    primary = two_coil_picture.primary
    second = [s for s in primary.branch_points() if s.m == 1 and s.block.held][1]
    degree = located_degree(primary, second)
    assert degree > primary.scene.stability.degree
    _, vector = critical_mode(primary, second, degree)
    H, G = az.azimuthal_hessian(equilibrium_of(primary), second.X[:-1], primary.params_at(second.X), 1, degree)
    assert abs(vector @ H @ vector / (vector @ G @ vector)) <= 1e-6
    _, lowest = critical_mode(primary, second, degree, count=1)
    assert lowest @ H @ lowest / (lowest @ G @ lowest) < -1.0


def test_primary_branch_states_are_equilibria_with_a_field(two_coil_picture):
    """Points of the two-coil M = 0.002 primary branch (field on) and its first m = 1 point, each solved again at
    its P on the axisymmetric solver's wire map at degree 150 (the run's degree 90 leaves a truncation that the
    whole sphere sees: residuals up to 4e-10), embedded on the whole sphere with the same map at degree 104, order 3:
    the residual is ≤ 1e-10 (measured 4e-12 to 4e-11), and Newton at the prescribed north pole stretch returns P to
    1e-10."""
    branch = two_coil_picture.primary
    fine = Discretisation(150, branch.disc.symmetric, branch.disc.pin_translation, mapping=branch.disc.mapping)
    eq1 = Equilibrium(branch.scene, fine)
    basis = SphericalBasis(104, (MIRROR_Y, EQUATOR), order=3, mapping=branch.disc.mapping)
    eq = SurfaceEquilibrium(branch.scene, basis)
    bp = next(s for s in branch.branch_points() if s.m == 1)
    for X in (branch.X[len(branch.X) // 3], branch.X[2 * len(branch.X) // 3], bp.X):
        params = branch.params_at(X)
        axisymmetric = newton(lambda x: eq1.residual(x[:-1], params.with_value("P", x[-1])),
                              lambda x: eq1.bordered_jacobian(x[:-1], params.with_value("P", x[-1]), "P"),
                              np.append(branch.disc.transfer(X[:-1], fine), params.P), np.eye(fine.size + 1)[-1],
                              params.P, 1e-14, 30)
        assert axisymmetric.converged and fine.tail(axisymmetric.x[:-1]) <= 1e-11
        c = axisymmetric_coefficients(basis, fine, axisymmetric.x[:-1])
        assert np.abs(eq.residual(c, params)).max() <= 1e-10
        system = SurfaceSystem(eq, Gauge(basis, held=True, field_symmetry=FieldSymmetry.AXIAL), params)
        row, offset = axial_stretch_row(basis)
        stretch = branch.pole_values(X)["lam2_top"][0]
        result = newton(system.residual, system.jacobian, system.point(c, params.P * 1.01),
                        np.append(system.gauge.reduce(row), 0.0), stretch - offset, 1e-13, 30)
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
    fields = stability.zero_mode_fields(eq.node_values(c)["state"], basis, FieldSymmetry.NONE, True)
    rows = stability.mode_rows(basis, fields)
    assert len(rows) == 9
    for v in rows:
        assert np.abs(H @ v).max() <= 1e-10 * np.abs(H).max() * np.linalg.norm(v)
    held = stability.Reading(True)
    values = stability.sector_spectra(eq, c, params, readings=(held,))[held]
    assert min(v.min() for v in values.values()) > 0


def test_gauge_removes_the_subspace_zero_modes(spom1):
    """The relabelling about y lives in the mirror subspace and is removed, and a held balloon's x and z translations
    (the y one is odd under the mirror); a free balloon keeps its translations; a subspace that keeps a rigid
    rotation the field leaves free is refused."""
    basis = SphericalBasis(8, (MIRROR_Y,))
    gauge = Gauge(basis, held=True, field_symmetry=FieldSymmetry.AXIAL)
    assert gauge.size == basis.size - 3  # the x and z translations held (the reaction: the field's net force)
    assert Gauge(basis, held=False, field_symmetry=FieldSymmetry.AXIAL).size == basis.size - 1  # the relabelling
    a = np.random.default_rng(1).standard_normal(gauge.size)
    c = gauge.expand(a)
    assert np.abs(gauge.constraints @ c).max() <= 1e-14
    assert np.allclose(gauge.reduce(c), a)
    with pytest.raises(UnsupportedGauge, match="rotation about the y axis"):
        Gauge(basis, held=True, field_symmetry=FieldSymmetry.NONE)


def test_measures_of_a_shifted_ellipsoid():
    """Volume, centroid, tilt and pole stretches of x = (1.5 X + 0.1, 1.2 Y, Z) against the closed forms."""
    basis = SphericalBasis(6, (MIRROR_Y,))
    X = basis.nodes["reference"][:3]
    c = displacement_coefficients(basis, np.array([1.5 * X[0] + 0.1, 1.2 * X[1], X[2]]) - X)
    m = measures(basis, c)
    assert m["volume"] == pytest.approx(4 / 3 * np.pi * 1.5 * 1.2 / (2 * np.pi), rel=1e-13)
    assert np.allclose(m["centroid"], [0.1, 0, 0], atol=1e-13)
    assert m["tilt"] == pytest.approx(90.0, abs=1e-9)
    assert m["lam_top"] == pytest.approx(np.sqrt(1.5 * 1.2), rel=1e-13)


@pytest.fixture(scope="module")
def spom1_picture(spom1):
    from balloon_cg.analysis.picture import analyse
    return analyse(spom1.with_overrides({"continuation.stop_stretch": 4.0, "surface.branches": "none"}))


def sideways_poles(basis, c) -> np.ndarray:
    """(λ+, λ−): the stretches of the whole-sphere state c at the material points ±e_x, the poles of a pear turned
    by 90° about y."""
    _, a = basis.point_values(c, np.full(2, np.pi / 2), np.array([0.0, np.pi]))
    return np.linalg.norm(a, axis=0)


def turned_pear(poles, pears, shoot=False):
    """(P, λ2(π)) of the axisymmetric pear with λ2(0) = poles[0] (a pear or its mirror, ``pears``, whose nearest
    stored point to ``poles`` starts the solve), against which a sideways pear with these pole stretches is
    compared: the Galerkin pear at its run's degree (point_solve), or with ``shoot`` the shooting solution
    (model/shooting.shoot_general: ODE integration of the Euler–Lagrange system, independent of both Galerkin
    discretisations) started from it."""
    from balloon_cg.galerkin.point_solve import constrained_newton
    from balloon_cg.model.shooting import shoot_general

    def distance(b):
        ends = b.pole_values()
        return np.abs(ends["lam2_top"] - poles[0]) + np.abs(ends["lam2_bottom"] - poles[1])

    pear = min(pears, key=lambda b: distance(b).min())
    nearest = int(np.argmin(distance(pear)))
    result, eq = constrained_newton(pear.scene, pear.disc.degree, pear.X[nearest], pear.disc, poles[0], pear.params,
                                    tol=1e-13)
    assert result.converged, (poles, result.message)
    rows, u = eq.disc.pole_rows(), result.x[:-1]
    if not shoot:
        return result.x[-1], rows["lam2_bottom"] @ u
    shot = shoot_general(pear.scene, poles[0], result.x[-1], rows["eta_top"] @ u, rows["lam2_bottom"] @ u,
                         rows["eta_bottom"] @ u, tol=1e-13, max_iter=30)
    assert shot.converged, (poles, shot.message)
    return shot.P, shot.lam2_bottom


def test_m1_branch_at_M0_is_the_pear_branch_turned_by_90_degrees(spom1_picture):
    """MODEL.md §8 check: at M = 0 the branch born at the m = 1 copy of the pear point is the axisymmetric pear
    branch rotated by 90° about y: its material points ±e_x are the pear's poles. At every traced point the stretches
    there, (λ+, λ−), and P agree with the axisymmetric pear branch solved at λ2(0) = λ+ (point_solve on its
    discretisation): P and λ2(π) = λ− to 1e-9 (the whole branch against shooting: the slow test below)."""
    from dataclasses import replace

    from balloon_cg.analysis.results import Block
    from balloon_cg.analysis.surface.branches import SurfaceTrace, rotated, trace_surface

    primary = spom1_picture.primary
    bp = primary.branch_points()[0]
    branch = trace_surface(primary, 0, replace(bp, m=1, block=Block.M1_HELD), 1.0, "m1", 12)
    assert branch.special[0].classification == bp.classification  # pitchfork-super, as the axisymmetric pear point
    pears = [b for b in spom1_picture.branches[1:] if b.parent == ("primary", 0)]
    checked = 0
    for c, P in zip(branch.coefficients[1:], branch.values[1:]):
        poles = sideways_poles(branch.basis, c)
        reference, south = turned_pear(poles, pears)
        assert abs(reference - P) <= 1e-9 * P
        assert abs(south - poles[1]) <= 1e-9
        checked += 1
    assert checked >= 8 and branch.measures["tilt"][1:].min() > 89.999
    image = rotated(branch, "m1_rotated")  # the other direction of the pitchfork: exact, by symmetry
    trace = SurfaceTrace(branch.scene, branch.basis, branch.params)
    for c, P in zip(image.coefficients, image.values):
        assert np.abs(trace.eq.residual(c, Parameters(P))).max() <= 1e-10
    assert np.allclose(image.measures["centroid"][:, 0], -branch.measures["centroid"][:, 0])
    with pytest.raises(ValueError, match="maps the m = 2 mode"):  # an even mode is its own image: traced along −φ
        rotated(replace(branch, m=2), "m2_rotated")


OFF_EQUATOR = """[material]
preset = "SPOM1"
[field]
M = {M}
[[field.coils]]
radius = 2.0
height = 0.5
current = 1.0
[continuation]
stop_stretch = 2.0
[surface]
branches = "none"
"""


def test_held_m1_branch_of_an_off_equator_coil(tmp_path):
    """Issue 41: a coil off the equator (r = 2, h = 0.5, M = 0.002) keeps no z-reflection, so the held m = 1 branch is
    traced with the mirror y → −y alone and every translation held: its branch point is solved on the whole sphere
    as the axisymmetric held state (whose net axial field force, the hold's reaction, is not zero: the gauge that
    left the axial translation free had no such equilibrium and switching failed), every point is a held
    equilibrium, and the pear it becomes is tilted (neither axial nor turned by 90°, as the equator-symmetric
    scenes' are: nothing fixes its axis here)."""
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.analysis.surface.branches import SurfaceTrace, trace_surface
    from balloon_cg.surface.loads import loads

    primary = analyse(parse_scene(OFF_EQUATOR.format(M=0.002), name="off_equator"), pear=False).primary
    assert not primary.disc.symmetric
    k, bp = next((k, bp) for k, bp in enumerate(primary.branch_points()) if bp.m == 1 and bp.block.held)
    assert abs(bp.X[-1] - 2.266905948) < 1e-8  # the held m = 1 point (its scene: the default gap, stop 3)
    branch = trace_surface(primary, k, bp, 1.0, "m1", 6)
    assert branch.basis.symmetry == (MIRROR_Y,) and branch.held and len(branch.values) == 6
    assert branch.residual.max() <= 1e-10  # point 0 included: solved, not the embedded state
    trace = SurfaceTrace(branch.scene, branch.basis, branch.params)
    force = loads(trace.eq, branch.coefficients[0], branch.params.with_value("P", branch.values[0]))["force"]
    assert abs(force[2]) > 1e-4 and np.abs(force[:2]).max() < 1e-12  # the axial reaction of the hold
    assert np.all(np.abs(trace.gauge.constraints @ branch.coefficients.T) < 1e-12)  # the centre held
    tilt = branch.measures["tilt"][1:]
    assert 1.0 < tilt.min() and tilt.max() < 89.0


def rotation_invariants(basis, c) -> np.ndarray:
    """(V, the central second moments m0 ≤ m1 ≤ m2 of the enclosed body), per 2π: unchanged by a rigid rotation and
    by a relabelling of the material, so a pear turned about any axis has its axial pear's."""
    from balloon_cg.surface.measures import body_moments

    volume, first, second = body_moments(basis, basis.node_state(c))
    centroid = first / volume
    return np.concatenate([[volume], np.linalg.eigvalsh(second / volume - np.outer(centroid, centroid))])


@pytest.mark.slow
def test_the_off_equator_held_m1_branch_tends_to_the_turned_pear_as_M_vanishes(spom1_picture, monkeypatch):
    """Issue 41: the held m = 1 branch of the off-equator coil (r = 2, h = 0.5), switched without a kept reflection
    (mirror y → −y alone) at M = 4e-4 and traced 8 points, is at M → 0 the SPOM1 pear branch turned about y. At
    M = 0 every turned pear is an equilibrium; the field's torque picks the tilt (here 47°, neither axial nor
    sideways), so the comparison reads what no rotation or relabelling changes: the volume and the body's central
    second moments. At P = 2.258 and 2.2565 the branch's point is continued in M at fixed P (halving from M = 4e-4,
    secant predictor) to 3.125e-6; the deviation from the axisymmetric pear solved at the same P (Galerkin,
    point-solved from the M = 0 pear branch) is linear in M (dV/M → −34.8), and its quadratic fit through the three
    smallest M has an intercept ≤ 1e-9 in every invariant (measured ≤ 2.1e-10). 30–60 s on a loaded 2-core machine."""
    from balloon_cg.analysis.surface import branches as surface_branches
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.analysis.branches.problem import equilibrium_of
    from balloon_cg.analysis.surface.branches import SurfaceTrace, trace_surface

    monkeypatch.setattr(surface_branches, "assess", lambda *args: None)  # the stability is not read here
    M0 = 4e-4
    primary = analyse(parse_scene(OFF_EQUATOR.format(M=M0), name="off_equator"), pear=False).primary
    k, bp = next((k, bp) for k, bp in enumerate(primary.branch_points()) if bp.m == 1 and bp.block.held)
    branch = trace_surface(primary, k, bp, 1.0, "m1", 8)
    assert branch.basis.symmetry == (MIRROR_Y,) and branch.held and branch.values[-1] < 2.2565
    trace = SurfaceTrace(branch.scene, branch.basis, branch.params)
    pear = next(b for b in spom1_picture.branches[1:] if b.parent == ("primary", 0))
    pear_eq = equilibrium_of(pear)

    def pear_at(P):
        X = pear.X[int(np.argmin(np.abs(pear.X[:, -1] - P)))]
        result = newton(lambda X: pear_eq.residual(X[:-1], pear.params_at(X)),
                        lambda X: pear_eq.bordered_jacobian(X[:-1], pear.params_at(X), "P"), X,
                        np.eye(X.size)[-1], P, 1e-13, 30)
        assert result.converged
        basis = SphericalBasis(40, (MIRROR_Y,), order=2, mapping=pear.disc.mapping)
        return rotation_invariants(basis, axisymmetric_coefficients(basis, pear.disc, result.x[:-1]))

    for P in (2.258, 2.2565):
        X = trace.system.point(branch.coefficients[int(np.argmin(np.abs(branch.values - P)))], P)
        on_branch = newton(trace.system.residual, trace.system.jacobian, X, np.eye(X.size)[-1], P, 1e-12, 30)
        assert on_branch.converged
        X = on_branch.x
        system = SurfaceSystem(trace.eq, trace.gauge, branch.params.with_value("P", P), "M")
        X, previous, deviation = system.point(trace.system.coefficients(X), M0), None, {}
        reference = pear_at(P)
        while X[-1] > 4e-6:
            M = X[-1] / 2
            guess = X.copy() if previous is None else X + (X - previous) * (M - X[-1]) / (X[-1] - previous[-1])
            guess[-1] = M
            result = newton(system.residual, system.jacobian, guess, np.eye(X.size)[-1], M, 1e-12, 30)
            assert result.converged, (P, M, result.message)
            previous, X = X, result.x
            deviation[M] = rotation_invariants(branch.basis, system.coefficients(X)) - reference
        smallest = sorted(deviation)[:3]
        fit = np.polynomial.polynomial.polyfit(smallest, np.array([deviation[M] for M in smallest]), 2)
        assert np.abs(fit[0]).max() <= 1e-9, (P, fit[0])
        assert abs(fit[1][0]) > 10  # the deviation at finite M is the field's, linear in M
        tilt = measures(branch.basis, system.coefficients(X))["tilt"]
        assert 30 < tilt < 60


@pytest.fixture(scope="module")
def two_coil_picture(tmp_path_factory):
    return shared_pictures.two_coil_picture(tmp_path_factory)  # its primary branch is read


def test_m1_eigenvalue_and_crossing_with_a_field(two_coil_picture):
    """Two coils, M = 0.002: on the wire-mapped whole-sphere basis (degree 72, order 4) the held m = 1 spectrum
    (``stability.azimuthal_spectrum``) equals analysis/stability/azimuthal's at perturbation degree 80 to 1e-9 at the
    first located m = 1 point, and the zero of its lowest eigenvalue along the primary branch (Brent on the chord,
    as azimuthal_points.locate) is that point's P to 1e-9."""
    from balloon_cg.analysis.branches.problem import branch_system
    from balloon_cg.numerics import continuation

    primary = two_coil_picture.primary
    bp = next(s for s in primary.branch_points() if s.m == 1 and s.block.held)
    basis = SphericalBasis(72, (MIRROR_Y,), order=4, mapping=primary.disc.mapping)
    eq = SurfaceEquilibrium(primary.scene, basis)
    eq1 = Equilibrium(primary.scene, primary.disc)

    def lowest(X, count=1):
        c = axisymmetric_coefficients(basis, primary.disc, X[:-1])
        return stability.azimuthal_spectrum(eq, c, primary.params_at(X), 1, True, count)

    ours = lowest(bp.X, 3)
    theirs = az.spectrum(eq1, bp.X[:-1], primary.params_at(bp.X), 1, 80, 3, held=True)
    assert np.abs(ours - theirs).max() <= 1e-9
    system, solver = branch_system(primary), primary.scene.solver
    X0, X1 = primary.X[bp.index], primary.X[bp.index + 1]
    d = (X1 - X0) / np.linalg.norm(X1 - X0)

    def value_at(s):
        result = newton(system.residual, system.jacobian, X0 + s * d, d, d @ X0 + s, solver.tol, solver.max_newton)
        return float(lowest(result.x)[0]), result.x

    found = continuation.locate_root(value_at, float(np.linalg.norm(X1 - X0)))
    assert found.status == continuation.RootStatus.LOCATED
    assert abs(found.payload[-1] - bp.X[-1]) <= 1e-9 * bp.X[-1]


def test_run_lists_the_m1_branch_born_at_the_first_m1_point(tmp_path, tmp_path_factory, capsys):
    """`balloon-cg run` on the shipped two-coil scene stores the branch born at the first m = 1 point and its image:
    the branch reaches its stop (the membrane within wire_gap of the wires on one side, 14 points), every point
    resolved (tail ≤ solver.max_error) and an equilibrium (point 0, the branch point, solved in the axisymmetric
    family: residual ≤ 1e-10), the parent point classified, its secondary branch point located, every point read
    held and free under pressure, volume and gas control; `inspect --json` lists every branch with its m, the surface
    branches with their parent and pressures; [surface] branches = "none" leaves them out."""
    import json

    import balloon_cg as bc
    from balloon_cg.app.cli import main
    from balloon_cg.io.run_file import read_run, stored_scene

    scene = ROOT / "scenes" / "spom1_two_coils_M0.002.toml"
    out = tmp_path / "run.h5"
    assert main(["run", str(scene), "-o", str(out), "--quiet"]) == 0
    capsys.readouterr()
    assert main(["inspect", str(out), "--json"]) == 0
    branches = json.loads(capsys.readouterr().out)["branches"]
    surface = {name: b for name, b in branches.items() if b["m"] != 0}
    assert set(surface) == {"m1_bp1", "m1_bp1_rotated"}
    assert all(b["m"] == 0 for name, b in branches.items() if name not in surface)
    first = surface["m1_bp1"]
    assert first["m"] == 1 and first["parent"][0] == "primary" and len(first["pressures"]) == first["points"] > 10
    parent = [s for s in branches["primary"]["special_points"] if s["kind"] == "BP"][first["parent"][1]]
    assert parent["block"].startswith("m1") and first["parent_label"] == parent["label"]  # one name: its label
    legend = [t.get_text() for t in bc.plot(out).legends[0].get_texts()]
    assert f"m = 1 from {parent['label']}" in legend, legend  # the figure's name of it, as inspect's
    assert first["stop_codes"] == {"forward": "wire_gap"}
    assert first["max_error_estimate"] <= load_scene(scene).solver.max_error and first["max_residual"] <= 1e-10
    origin, *inner, end = first["special_points"]
    assert origin["classification"] == "pitchfork-super" and end["kind"] == "EP"
    assert [s["status"] for s in inner if s["kind"] == "BP"] == ["located"]
    assert set(first["stable_points"]) == {f"stable_{control}{reading}" for control in ("pressure", "volume", "gas")
                                           for reading in ("", "_free")}
    with h5py.File(out) as f:  # the m = 1 points "first" leaves out, named in one stated (not failing) entry
        gaps = list(f.attrs["incomplete_gaps"])
        assert bool(f.attrs["complete"]) and gaps.count("not_asked") == 1
        names = f.attrs["incomplete_branches"][gaps.index("not_asked")]
    bps = [s for s in branches["primary"]["special_points"] if s["kind"] == "BP"]
    points = [f"m1_bp{k}" for k, bp in enumerate(bps) if bp["block"].startswith("m1") and k != 1]
    assert names.split(", ") == points and len(points) >= 3  # the held and the free readings' other points
    none = shared_pictures.two_coil_run_file(tmp_path_factory)  # `run` of the scene to 1.7 with branches "none"
    assert stored_scene(read_run(none)).surface.branches == "none"
    capsys.readouterr()
    assert main(["inspect", str(none), "--json"]) == 0
    assert all(b["m"] == 0 for b in json.loads(capsys.readouterr().out)["branches"].values())


@pytest.mark.slow
def test_the_one_coil_m1_branch_reaches_the_wire_past_a_located_fold(tmp_path):
    """One coil of radius 2 in the equatorial plane, M = 0.001: the branch born at the first m = 1 point starts
    there (point 0 solved), turns at a located fold in P and reaches the wire gap; every point resolved, with
    stability (about a minute: ``pytest -m slow``)."""
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.analysis.results import Kind, Status, StopCode
    from balloon_cg.analysis.surface.branches import trace_surface

    text = (ROOT / "scenes" / "spom1_single_coil.toml").read_text()
    scene = parse_scene(text.replace("radius = 4.0", "radius = 2.0").replace("M = 0.002", "M = 0.001"))
    primary = analyse(scene, pear=False).primary
    bp = next(s for s in primary.branch_points() if s.m == 1 and s.block.held)
    branch = trace_surface(primary, 0, bp, 1.0, "m1", scene.surface.max_points)
    assert branch.special[-1].stop.code == StopCode.WIRE_GAP
    assert [s.status for s in branch.special if s.kind == Kind.LP] == [Status.LOCATED]
    assert branch.error_estimate.max() <= scene.solver.max_error and branch.residual.max() <= 1e-10
    assert set(branch.stability) == {"held", "free", "held_volume", "free_volume", "held_gas", "free_gas"}


def test_a_mapped_basis_reads_its_poles_as_the_limit():
    """(x, a_θ) at a pole of a wire-mapped basis equal their values 1e-7 away, for maps whose h(±1) is off ±1 by an
    ulp (about one map in six: those read dθ_s/dθ = 0/ε = 0 at the pole, a pole stretch of exactly 1)."""
    rng = np.random.default_rng(0)
    for _ in range(30):
        centre, width = rng.uniform(0.3, 0.7), rng.uniform(0.005, 0.1)
        basis = SphericalBasis(16, (MIRROR_Y, EQUATOR), order=6, mapping=WireMap((centre, -centre), (width, width)))
        c = 0.05 * rng.standard_normal(basis.size)
        for pole, near in ((0.0, 1e-7), (np.pi, np.pi - 1e-7)):
            at = basis.point_values(c, np.full(2, pole), np.array([0.0, np.pi / 2]))
            by = basis.point_values(c, np.full(2, near), np.array([0.0, np.pi / 2]))
            assert np.abs(at[1] - by[1]).max() <= 1e-4 and np.abs(at[0] - by[0]).max() <= 1e-4


def test_volume_and_gas_control_at_a_sphere_hold_the_axisymmetric_readings(spom1):
    """Past the pressure maximum (λ = 1.5) a sphere's breathing mode is unstable under pressure control and held
    under volume and gas control. The whole-sphere readings (``stability.READINGS``, held; mirror sector, L = 10)
    hold the three lowest eigenvalues of the axisymmetric m = 0 pencil (H, G) in the same displacement norm, built
    here from the axisymmetric solver (its Jacobian, ∂Ṽ/∂u = −∂R/∂P, the translation removed; with gᵀδ = 0 for
    volume control, H + (P/Ṽ) g gᵀ for gas control) on an explicit null space, to 1e-9; the breathing eigenvalue is
    in the pressure reading only."""
    L = 10
    eq1, u, params = sphere(spom1, 1.5, L + 4)
    basis = SphericalBasis(L, (MIRROR_Y,))
    eq = SurfaceEquilibrium(spom1, basis)
    c = axisymmetric_coefficients(basis, eq1.disc, u)
    readings = [stability.Reading(True, control) for control in stability.Control]
    ours = stability.sector_spectra(eq, c, params, 40, readings)
    ops, w, s = eq1.disc.ops, eq1.disc.weights, eq1.disc.sin_theta
    G = (ops[0].T * (w * s * s)) @ ops[0] + (ops[2].T * w) @ ops[2]
    H = eq1.jacobian(u, params)
    g = -eq1.parameter_derivative(u, params, "P")
    translation = eq1.disc.join(np.zeros(L + 5), np.eye(L + 5)[0])
    references = []
    for normals, matrix in (([G @ translation], H), ([G @ translation, g], H),
                            ([G @ translation], H + (params.P / eq1.volume(u)) * np.outer(g, g))):
        N = linalg.null_space(np.array(normals))
        references.append(linalg.eigh(N.T @ matrix @ N, N.T @ G @ N, eigvals_only=True)[:3])
    for reading, reference in zip(readings, references):
        for value in reference:
            assert np.abs(ours[reading][(1,)] - value).min() <= 1e-9 * max(1.0, abs(value))
    breathing = references[0][0]
    assert breathing < 0.0 < min(references[1][0], references[2][0])
    for reading in readings[1:]:
        assert ours[reading][(1,)].min() > 0.0 and np.abs(ours[reading][(1,)] - breathing).min() > 1e-3


@pytest.mark.slow
@pytest.mark.timeout(5400)
def test_the_whole_m1_isola_at_M0_is_the_pear_isola_turned_by_90_degrees(spom1, monkeypatch):
    """The M = 0 check along the whole branch: from the m = 1 copy of the first pear point to its rejoin of the
    primary branch at the second, traced with solver.max_error = 1e-11; at every point P and the other pole stretch
    agree with the axisymmetric pear shot (``turned_pear(..., shoot=True)``: ODE integration, independent of both
    Galerkin discretisations) at the faster-moving of the two pole stretches to 1e-9 (measured 2026-12-02: 178
    points, median 2.5e-13, worst 5.7e-11). The curve is parametrised by its faster-moving pole stretch: at a fixed
    λ+ it is ill-conditioned where λ+ has its maximum (5.399, about point 95: a Galerkin reference there was off by
    3e-9), and a Galerkin reference at twice the pear's degree is itself off by ~1e-9 for these pears (λ+ up to
    5.4: degree 180 and 270 differ by 3e-9 in λ2(π)). The stability of the points is not computed here (``assess``
    skipped). A study of tens of minutes (degree up to 64 on the whole sphere): ``pytest -m slow``."""
    from dataclasses import replace

    from balloon_cg.analysis.surface import branches as surface_branches
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.analysis.results import Block, StopCode

    monkeypatch.setattr(surface_branches, "assess", lambda *args: None)
    # stop_stretch 6: the axisymmetric pear branches (the reference's starts) must reach the pear pole stretch the
    # sideways pear reaches (5.4; its stop rule reads the material poles, on its equator)
    scene = spom1.with_overrides({"continuation.stop_stretch": 6.0, "surface.branches": "none",
                                  "solver.max_error": 1e-11})
    picture = analyse(scene)
    primary = picture.primary
    bp = primary.branch_points()[0]
    branch = surface_branches.trace_surface(primary, 0, replace(bp, m=1, block=Block.M1_HELD), 1.0, "m1", 1000)
    assert branch.special[-1].stop.code == StopCode.REJOINED
    pears = [b for b in picture.branches[1:] if b.parent == ("primary", 0)]
    poles = np.array([sideways_poles(branch.basis, c) for c in branch.coefficients])
    errors = []
    for i in range(1, len(branch.values)):
        moving = np.abs(poles[min(i + 1, len(poles) - 1)] - poles[i - 1])
        pole = int(np.argmax(moving))  # the pear's north pole: +e_x, or −e_x (the mirror pear)
        reference, south = turned_pear(poles[i, [pole, 1 - pole]], pears, shoot=True)
        errors.append(max(abs(reference - branch.values[i]) / branch.values[i], abs(south - poles[i, 1 - pole])))
    assert len(errors) > 100 and max(errors) <= 1e-9, (len(errors), np.median(errors), max(errors))


def test_a_sub_basis_reads_upper_bounds_from_the_principal_submatrix(spom1):
    """``stability.sub_basis`` of a sector of a wire-mapped basis (degree 16, order 6) at a deformed state: its Hessian
    is the sector's principal submatrix on the same (component, order, type, degree) unknowns (a block's
    orthonormalisation is triangular) to rounding, and every reading read on it (``sector_spectra(within=)``) is an
    upper bound of the sector's (Rayleigh–Ritz, the zero modes and gᵀc = 0 included), reaching it on the sector
    itself; the bad sub-basis is refused naming degree and order."""
    _, _, params = sphere(spom1, 1.3, 8)
    basis = SphericalBasis(16, (MIRROR_Y, EQUATOR), order=6, mapping=WireMap((0.4, -0.4), (0.05, 0.05)))
    eq = SurfaceEquilibrium(spom1, basis)
    rng = np.random.default_rng(1)
    degrees = np.array([l for b in basis.blocks for l in b.degrees], dtype=float)
    c = displacement_coefficients(basis, 0.3 * basis.nodes["reference"][:3]) + 0.01 * rng.standard_normal(
        basis.size) / (1.0 + degrees) ** 2
    readings = stability.READINGS
    whole = stability.sector_spectra(eq, c, params, 4, readings)
    for sector in basis.sectors():
        key = sector.characters
        sub = stability.sub_basis(sector, 12, 4)
        blocks = {(b.component, b.m, b.t): b for b in sector.blocks}
        index = np.concatenate([blocks[b.component, b.m, b.t].offset
                                + np.searchsorted(blocks[b.component, b.m, b.t].degrees, b.degrees)
                                for b in sub.blocks])
        H = eq.hessian(c, params, sector)
        assert np.abs(eq.hessian(c, params, sub) - H[np.ix_(index, index)]).max() <= 1e-12 * np.abs(H).max()
        bounds = stability.sector_spectra(eq, c, params, 4, readings, only=(key,), within={key: sub})
        same = stability.sector_spectra(eq, c, params, 4, readings, only=(key,),
                                        within={key: stability.sub_basis(sector, 16, 6)})
        for r in readings:
            assert np.all(bounds[r][key] >= whole[r][key] - 1e-10 * np.maximum(1.0, np.abs(whole[r][key])))
            assert np.abs(same[r][key] - whole[r][key]).max() <= 1e-10 * max(1.0, np.abs(whole[r][key]).max())
        assert any(np.abs(bounds[r][key] - whole[r][key]).max() > 1e-6 for r in readings)
    with pytest.raises(ValueError, match="degree = 20, order = 4"):
        stability.sub_basis(basis, 20, 4)
