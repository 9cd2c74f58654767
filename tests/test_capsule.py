"""The capsule (docs/shapes.md): a cylinder of radius 1 and length L with hemispherical caps of the same membrane,
discretised as the sphere is over θ = S/κ (codegen/meridian.py, model/meridian.py), its quadrature split at the
joins where the reference curvature jumps (galerkin/discretisation.py: ``split_rule``), its cylinder one element or
cut into several (``geometry.element_length``), refined to max_error (analysis/branches/resolution.py).

Checked: the capsule of length 0 is the sphere (another kernel module); its meridian is C¹ with the curvature
jumping at the joins; the middle of a long capsule is the uniform closed-end tube and the capsule starts bulging at
the long tube's pressure maximum, both derived or computed independently of the capsule; the bulge of a long
capsule propagates at Maxwell's pressure (slow); volume control measures the capsule's volume (a quadrature written
here); run and inspect store profiles measured from the capsule; one-line errors.
"""
import json

import numpy as np
import pytest
from numpy.polynomial import legendre
import sympy as sp
from scipy.optimize import brentq

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.branches.primary import inflated_reference, start_parameters
from balloon_cg.analysis.branches.tracer import Tracer, unit
from balloon_cg.galerkin.discretisation import split_rule
from balloon_cg.galerkin.elements import CAPS, CYLINDER, element_series, element_table, families, sequence
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.model import meridian, tube
from balloon_cg.numerics import continuation
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import SceneError, Shape, parse_scene
from shared_pictures import shared

# the slow plateau test's start degree and max_error (docs/shapes.md: at the default max_error 1e-9 the branch stops
# at max_degree soon after its fold, the bulge's fronts wanting more than one cylinder element's degree)
DEGREE, PLATEAU_ERROR = 192, 1e-2
CAPSULE = '[material]\npreset = "SPOM1"\n[geometry]\nshape = "capsule"\nlength = {length}\n{split}[stability]\nm_max = 0\n'
# the longest cylinder element of the split capsules here (geometry.element_length)
ELEMENT = 5.0


def capsule_scene(length: float, extra: str = "", element: float | None = None):
    """The SPOM1 capsule of ``length`` (m = 0 stability), its cylinder one element or cut into elements of at
    most ``element`` radii."""
    split = "" if element is None else f"element_length = {element!r}\n"
    return parse_scene(CAPSULE.format(length=length, split=split) + extra)


def inflated(scene, degree: int, P: float):
    """(Equilibrium, u) of the capsule at the pressure P: from the start at pole stretch 1.005, natural
    continuation in P (Newton at prescribed P)."""
    tracer = Tracer(scene, True)
    params = start_parameters(scene, "P")
    u, P0 = inflated_reference(tracer, degree, 1.005, params)
    system = tracer.system(degree, params)

    def solve(X, value):
        return newton(system.residual, system.jacobian, X, unit(X.size, -1), value, 1e-13, 40)

    X, reached, message = continuation.natural(solve, np.append(u, P0), P0, P)
    assert reached == P, message
    return system.eq, X[:-1]


def test_capsule_of_length_zero_is_the_sphere():
    """SPOM1 to a pole stretch of 3 with m = 0 stability: the same points, fold and equator-breaking branch point
    as the sphere to 1e-10, although the capsule's kernels are another module (its R = sin(κ acos(cos θ)) with
    κ = 1, S' = κ, and the Galerkin state turned into the meridian's by R/sin θ)."""
    text = '[material]\npreset = "SPOM1"\n[stability]\nm_max = 0\n[continuation]\nstop_stretch = 3.0\n'
    sphere = parse_scene(text)
    capsule = parse_scene(text + '[geometry]\nshape = "capsule"\nlength = 0\n')
    assert capsule.geometry.shape == Shape.CAPSULE and meridian.joins(capsule.geometry) == ()
    one, other = (analyse(scene, pear=False).branches[0] for scene in (sphere, capsule))
    assert other.kernel_class != one.kernel_class
    assert [p.kind for p in other.special] == [p.kind for p in one.special]
    kinds = [p.kind.value for p in one.special]
    assert kinds.count("BP") == 1 and kinds.count("LP") == 1
    for a, b in zip(one.special, other.special):
        assert (a.kind, a.block, a.status) == (b.kind, b.block, b.status)
        assert abs(a.X[-1] - b.X[-1]) <= 1e-10 * abs(a.X[-1])
        assert np.abs(a.X[:-1] - b.X[:-1]).max() <= 1e-10
    assert one.X.shape == other.X.shape and np.abs(one.X - other.X).max() <= 1e-10


def test_reference_meridian_is_c1_with_the_curvature_jumping_at_the_joins():
    """model/meridian's R, R', Z of a capsule of length 6: R' is dR/dθ and S' = κ is sqrt(R'² + Z'²) (central
    differences of R and Z, 1e-8) on both caps and the cylinder; R, R', Z continuous at the joins θj = π/(2κ),
    where R'' jumps from −κ² to 0."""
    geometry = capsule_scene(6.0).geometry
    kappa = 1 + 6.0 / np.pi
    joint = np.pi / (2 * kappa)
    theta = np.array([0.2, joint - 1e-3, joint + 1e-3, 1.4, np.pi / 2, 2.0, np.pi - joint + 1e-3, 3.0])
    h = 1e-6
    R = lambda t: meridian.hoop(geometry, np.cos(t), np.sin(t))  # noqa: E731
    Z = lambda t: meridian.reference_height(geometry, t)  # noqa: E731
    dR, dZ = (R(theta + h) - R(theta - h)) / (2 * h), (Z(theta + h) - Z(theta - h)) / (2 * h)
    assert np.abs(dR - meridian.hoop_rate(geometry, np.cos(theta), np.sin(theta))).max() < 1e-8
    assert np.abs(np.hypot(dR, dZ) - kappa).max() < 1e-8
    assert abs(Z(np.array(0.0)) - (3.0 + 1)) < 1e-15 and abs(Z(np.array(np.pi)) + (3.0 + 1)) < 1e-15
    for t in (joint, np.pi - joint):
        for f in (R, Z, lambda s: meridian.hoop_rate(geometry, np.cos(s), np.sin(s))):
            assert abs(f(np.array(t - 1e-9)) - f(np.array(t + 1e-9))) < 1e-7
    second = lambda t: (R(t + 1e-4) - 2 * R(t) + R(t - 1e-4)) / 1e-8  # noqa: E731
    assert abs(second(joint - 1e-3) + kappa**2) < 1e-2 and abs(second(joint + 1e-3)) < 1e-6


def test_piecewise_basis_is_continuous_hierarchical_and_spans_piecewise_polynomials():
    """galerkin/elements.py at length 6, degree 40 (one cylinder element: joins ±c): φ_k continuous at the joins,
    φ_k(−x) = (−1)^k φ_k(x), dφ/dx the central differences of φ (1e-7), the degree-30 table the first 31 columns of
    degree 40's; a function continuous at the joins, cubic in x on each cap and quintic in θ on the cylinder
    (written here), is fitted exactly (least squares at 400 points, 1e-12), which one Legendre series in x of as
    many functions cannot (> 1e-5)."""
    kappa = 1 + 6.0 / np.pi
    joint = np.pi / (2 * kappa)
    c = np.cos(joint)
    joins = (-c, c)
    x = np.cos(np.linspace(0.0, np.pi, 400))
    p, dp = element_table(x, 40, joins)
    flipped, _ = element_table(-x, 40, joins)
    assert np.abs(flipped - p * (-1.0) ** np.arange(41)).max() < 1e-12
    for side in (c, -c):
        across, _ = element_table(np.array([side - 1e-12, side + 1e-12]), 40, joins)
        assert np.abs(across[0] - across[1]).max() < 1e-9
    h, inner = 1e-6, np.array([0.999, 0.9 * c + 0.1, 0.5 * c, -0.3 * c, -0.95])
    plus, minus = element_table(inner + h, 40, joins), element_table(inner - h, 40, joins)
    slope = element_table(inner, 40, joins)[1]
    assert np.abs((plus[0] - minus[0]) / (2 * h) - slope).max() < 1e-7 * np.abs(slope).max()
    lower, _ = element_table(x, 30, joins)
    assert np.array_equal(lower, p[:, :31])
    theta = np.arccos(x)
    xi = (np.pi / 2 - theta) / (np.pi / 2 - joint)
    cylinder = 1 + 0.3 * xi - 0.5 * xi**2 + 0.2 * xi**5
    f = np.where(x > c, 1.0 + 0.3 - 0.5 + 0.2 + 2 * (x - c) - 7 * (x - c) ** 3,
                 np.where(x < -c, 1.0 - 0.3 - 0.5 - 0.2 + (x + c) ** 2, cylinder))
    for table, exact in ((p, True), (legendre.legvander(x, 40), False)):
        residual = np.abs(table @ np.linalg.lstsq(table, f, rcond=None)[0] - f).max()
        assert residual < 1e-12 if exact else residual > 1e-5


@pytest.mark.parametrize("length", [12.0, 20.0])
def test_split_cylinder_basis_is_continuous_hierarchical_and_spans_piecewise_polynomials(length):
    """The cylinder of a capsule of length 12 (3 elements: a middle one and a mirror pair) and 20 (5: two mirror
    pairs) cut into an odd number of elements of at most ELEMENT radii (geometry.element_length, model/meridian.joins),
    degree 80: the inner boundaries at equal arclength (ξ_e = (2e − n)/n, the cylinder's S = κθ, written here) and
    mirror-symmetric; φ_k continuous at every join (1e-12 apart: by no more than its slope over the gap) and of parity (−1)^k (1e-12); dφ/dx the
    central differences of φ inside every element (1e-6 relative); the degree-60 table the first 61 columns of
    degree 80's; a function continuous at the joins with a different polynomial on every element (cubic in x on
    the caps, degree 3 + e in θ on cylinder element e: written here) fitted exactly (least squares at 1200 points,
    1e-11), which the single-cylinder basis of as many functions cannot (> 1e-4); ``element_series`` gives the same
    function on every element as the table (1e-12); the tail estimate reads every element's own series."""
    scene = capsule_scene(length, element=ELEMENT)
    joins = meridian.joins(scene.geometry)
    n = int(np.ceil(length / ELEMENT)) | 1
    kappa = 1 + length / np.pi
    theta_j = np.pi / (2 * kappa)
    bounds = (np.pi / 2 - theta_j) * (2 * np.arange(n + 1) - n) / n  # π/2 − θ at the boundaries
    assert len(joins) == n + 1 and np.allclose(np.arcsin(joins), bounds, atol=1e-14)
    assert np.array_equal(np.array(joins), -np.array(joins)[::-1])
    x = np.cos(np.linspace(0.0, np.pi, 1200))
    p, _ = element_table(x, 80, joins)
    flipped, _ = element_table(-x, 80, joins)
    assert np.abs(flipped - p * (-1.0) ** np.arange(81)).max() < 1e-12
    for side in joins:  # continuous: apart by no more than the slope over the gap
        across, slopes = element_table(np.array([side - 1e-12, side + 1e-12]), 80, joins)
        assert np.all(np.abs(across[0] - across[1]) < 1e-12 + 2e-12 * np.abs(slopes).max(axis=0))
    # inside every element: each cap, each cylinder element's middle
    inner = np.concatenate([[0.999, -0.97 * joins[-1] - 0.03], np.sin(0.5 * (bounds[1:] + bounds[:-1]))])
    h = 1e-7
    plus, minus = element_table(inner + h, 80, joins), element_table(inner - h, 80, joins)
    slope = element_table(inner, 80, joins)[1]
    assert np.abs((plus[0] - minus[0]) / (2 * h) - slope).max() < 1e-6 * np.abs(slope).max()
    lower, _ = element_table(x, 60, joins)
    assert np.array_equal(lower, p[:, :61])
    # a continuous function: its values at the boundaries given, a bubble of degree 3 + e on element e
    s = np.pi / 2 - np.arccos(x)  # π/2 − θ
    knots = np.cos(np.arange(n + 1))  # its values at the cylinder's boundaries
    f = np.empty_like(x)
    for e in range(n):
        on = (s >= bounds[e]) & (s <= bounds[e + 1])
        t = (2 * s[on] - bounds[e] - bounds[e + 1]) / (bounds[e + 1] - bounds[e])
        f[on] = knots[e] * (1 - t) / 2 + knots[e + 1] * (1 + t) / 2 + (1 - t**2) * (0.3 + 0.1 * e) * t ** (1 + e)
    c = joins[-1]
    f = np.where(x > c, knots[-1] + 2 * (x - c) - 7 * (x - c) ** 3, np.where(x < -c, knots[0] + (x + c) ** 2, f))
    single, _ = element_table(x, 80, (-c, c))
    for table, exact in ((p, True), (single, False)):
        residual = np.abs(table @ np.linalg.lstsq(table, f, rcond=None)[0] - f).max()
        assert residual < 1e-11 if exact else residual > 1e-4
    coefficients = np.random.default_rng(1).normal(size=81)
    north, cylinder, south = element_series(coefficients, joins)
    values = p @ coefficients
    on_cylinder = np.abs(x) <= c
    element = np.clip(np.searchsorted(bounds, s, side="right") - 1, 0, n - 1)
    t = (2 * s - bounds[element] - bounds[element + 1]) / (bounds[element + 1] - bounds[element])
    from_series = np.array([legendre.legval(ti, cylinder[e]) for e, ti in zip(element, t)])
    xi_cap = (2 * np.abs(x) - 1 - c) / (1 - c)
    from_series = np.where(x > c, legendre.legval(xi_cap, north),
                           np.where(x < -c, legendre.legval(xi_cap, south), from_series))
    assert np.abs(from_series - values).max() < 1e-12 and on_cylinder.sum() > 0
    groups = families(80, joins)
    assert len(groups) == n // 2 + (n % 2) + 1  # the cylinder's mirror groups and the caps
    assert sorted(np.unique(np.concatenate([g.ravel() for g in groups])).tolist()) == sorted(
        k for k, (family, _, _) in enumerate(sequence(80, joins)) if family in (CYLINDER, CAPS))


def test_capsule_converges_spectrally_in_the_degree():
    """SPOM1 capsule of length 4 at P = 0.5: the enclosed volume and the hoop stretch at the middle at degrees 24,
    32, 48 and 64 (benchmarks/results/capsule_convergence.txt): λ2's changes fall more than 20× per step, V changes
    by less than 1e-12 from 48 to 64, and the tail estimate at 64 is within the default max_error 1e-9 (the
    Legendre series in x changed V by 2.8e-5 from 48 to 64, its tail estimate stalling at 4e-3)."""
    volumes, hoops = [], []
    for degree in (24, 32, 48, 64):
        eq, u = inflated(capsule_scene(4.0), degree, 0.5)
        volumes.append(2 * np.pi * eq.volume(u))
        hoops.append(float(eq.state_at(u, np.array([np.pi / 2]))[0][0]))
    changes = np.abs(np.diff(hoops))
    assert np.all(changes[1:] < changes[:-1] / 20)
    assert abs(volumes[-1] - volumes[-2]) < 1e-12 and eq.disc.tail(u) < 1e-9


def test_split_rule_integrates_a_kink_exactly():
    """The composite rule with joins at ±c integrates |x| − c piecewise polynomials exactly (1e-14); the single
    rule of as many nodes per piece does not (the kink costs it more than 1e-6). Its middle piece is Gauss in θ
    (∫f dx = ∫f sin θ dθ: exact for sin θ times a polynomial in θ, 1e-14), and an odd rule is mirror-symmetric to
    the last bit with its middle node at x = 0 (the equator-symmetric half rule counts it once: ``even_half``)."""
    c = np.cos(np.pi / 2.6)
    f = lambda x: np.maximum(np.abs(x), c) ** 3  # noqa: E731
    exact = 2 * (c**3 * c + (1 - c**4) / 4)
    nodes, weights = split_rule(20, (-c, c))
    assert abs(weights @ f(nodes) - exact) < 1e-14 and np.allclose(nodes, -nodes[::-1])
    plain, plain_weights = split_rule(20)
    assert abs(plain_weights @ f(plain) - exact) > 1e-6
    theta_c = np.arccos(c)
    middle = np.abs(nodes) < c
    theta = np.arccos(nodes[middle])
    g = lambda t: (t - 1) ** 7 + 3 * t**2  # noqa: E731
    t = sp.Symbol("t")
    exact_middle = float(sp.Integral(g(t) * sp.sin(t), (t, sp.Float(theta_c, 30), sp.pi - sp.Float(theta_c, 30)))
                         .evalf(30))
    assert abs(weights[middle] @ g(theta) - exact_middle) < 1e-14 * abs(exact_middle)
    odd, _ = split_rule(21, (-c, c))
    assert np.array_equal(odd, -odd[::-1]) and np.count_nonzero(odd == 0.0) == 1


def closed_end_tube(material):
    """(P(λθ, λz), N(λθ, λz)) of the uniform tube with closed sliding ends, from Φ(λ1 = λz, λ2 = λθ) of the Ogden
    material: the hoop balance P = Φ_2/(λθλz) and the axial balance N = Φ_1 − λθΦ_2/(2λz) = 0 (the wall's axial
    force 2πΦ_1 carries the pressure on the end caps πλθ²P, i.e. Φ_1 = Pλθ²λz/2)."""
    hoop, axial = sp.symbols("hoop axial", positive=True)
    terms = zip(map(lambda v: sp.Rational(repr(v)), material.mu), map(lambda v: sp.Rational(repr(v)), material.alpha))
    energy = sum(mu / a * (axial**a + hoop**a + (axial * hoop) ** -a - 3) for mu, a in terms)
    P = sp.diff(energy, hoop) / (hoop * axial)
    N = sp.diff(energy, axial) - hoop * sp.diff(energy, hoop) / (2 * axial)
    return sp.lambdify((hoop, axial), P), sp.lambdify((hoop, axial), N)


def test_middle_of_a_long_capsule_is_the_uniform_closed_tube():
    """SPOM1 capsules of length 10, 15 and 20 at P = 1.2 (below the tube's pressure maximum 1.4905), degree 96: at the
    middle (θ = π/2, L/2 radii from either cap) the hoop stretch λθ = λ2 and the axial stretch λz = λ1 make the
    closed-end tube's balances P = Φ_2/(λθλz) and N = 0 hold (derived here), ρ' = 0, and λθ is the closed-end
    path's at P (brentq on P along N = 0), up to the caps' influence, which decays exponentially with the distance:
    more than 30× per 5 radii (measured 8.4e-5, 1.2e-6, 1.7e-8; 6.9e-11 at L = 30), below 1e-7 at L = 20, where
    the state is converged in the degree (96 and 128 within 1e-2 of that gap in λθ: 5.8e-11)."""
    P_of, N_of = closed_end_tube(capsule_scene(20.0).material)
    axial_of = lambda h: brentq(lambda a: N_of(h, a), 0.5, 3.0)  # noqa: E731
    closed = brentq(lambda h: P_of(h, axial_of(h)) - 1.2, 1.01, 1.5883)
    middle = np.array([np.pi / 2])
    errors, hoops = [], []
    for length, degree in ((10.0, 96), (15.0, 96), (20.0, 96), (20.0, 128)):
        eq, u = inflated(capsule_scene(length), degree, 1.2)
        lam2, v, _, w = eq.state_at(u, middle)
        lam1 = meridian.meridional_stretch(eq.scene.geometry, np.cos(middle), np.sin(middle), lam2, v, w)
        hoop, axial = float(lam2[0]), float(lam1[0])
        assert abs(v[0]) < 1e-12  # ρ' = 0 at the middle: the mirror symmetry
        errors.append(max(abs(P_of(hoop, axial) - 1.2), abs(N_of(hoop, axial)), abs(hoop - closed)))
        hoops.append(hoop)
    assert errors[1] < errors[0] / 30 and errors[2] < errors[1] / 30 and errors[2] < 1e-7
    assert abs(hoops[3] - hoops[2]) < 1e-2 * errors[2]


def test_middle_of_a_long_capsule_has_the_closed_tubes_curvatures_and_stresses():
    """post/quantities on the SPOM1 capsule of length 20 at P = 1.2 (degree 96; the caps' influence at the middle is
    below 1e-7, test above): at θ = π/2 the curvatures are the cylinder's, k_m = 0 and k_p = 1/r (r = λ2), and the
    elastic stresses carry the pressure as a closed-end tube's wall does (thickness h = 1/(λ1λ2) in units of the
    reference one, stresses and P in the energy's units): the normal balance P = h(σ_θ k_m + σ_φ k_p) gives
    σ_φ = P λ1 λ2², and the axial force on the ends, 2π r h σ_θ = π r² P, gives σ_θ = P λ1 λ2²/2."""
    from balloon_cg.post.quantities import quantities

    scene = capsule_scene(20.0)
    eq, u = inflated(scene, 96, 1.2)
    q = quantities(scene, eq.disc, np.append(u, 1.2), np.array([np.pi / 2]))
    lam1, lam2 = q["lam1"][0, 0], q["lam2"][0, 0]
    assert abs(q["k_meridian"][0, 0]) < 1e-7
    assert abs(q["k_parallel"][0, 0] * lam2 - 1.0) < 1e-12
    hoop = 1.2 * lam1 * lam2**2
    assert abs(q["sigma_phi"][0, 0] / hoop - 1.0) < 1e-6
    assert abs(q["sigma_theta"][0, 0] / (hoop / 2) - 1.0) < 1e-6


@pytest.mark.parametrize("element", [None, 1.0])
def test_capsule_curvatures_are_the_deformed_meridians_everywhere(element):
    """The SPOM1 capsule of length 3 at P = 1.0 (degree 64), its cylinder one element or three (element_length 1):
    post/quantities.surface's curvatures, from each element's second derivatives, against a second method on every
    element: the tangent angle ψ = atan2(η', ρ') of the meridian ρ = λ2 R (R written here, ``capsule_radius``; λ2,
    η and their first θ-derivatives from the basis table of galerkin/elements.py) differentiated by central
    differences (step 1e-5), k_m = −ψ'/s', and k_p = −η'/(ρ s'), away from the joins (1e-8); at the poles
    k_p = k_m (isotropic, 1e-9), and ρ = λ2 R, λ1 = s'/κ."""
    from balloon_cg.post.quantities import surface

    scene = capsule_scene(3.0, element=element)
    kappa = 1 + 3.0 / np.pi
    eq, u = inflated(scene, 64, 1.0)
    X = np.append(u, 1.0)
    step = 1e-5
    bounds = np.concatenate([[0.0], np.arccos(meridian.joins(scene.geometry))[::-1], [np.pi]])
    assert len(bounds) == (6 if element else 4)
    for low, high in zip(bounds[:-1] + 0.02, bounds[1:] - 0.02):
        theta = np.linspace(low, high, 41)
        g = surface(eq.disc, X, theta, scene.geometry)

        def angle_and_speed(at):
            lam2, dlam2, _, w = eq.disc.evaluate(u, at)  # λ2, dλ2/dθ, η, dη/dθ
            R, dR = capsule_radius(at, kappa)
            drho = dlam2 * R + lam2 * dR
            return np.arctan2(w, drho), np.hypot(drho, w), lam2 * R

        psi_plus, _, _ = angle_and_speed(theta + step)
        psi_minus, _, _ = angle_and_speed(theta - step)
        _, speed, rho = angle_and_speed(theta)
        k_meridian = -(psi_plus - psi_minus) / (2 * step) / speed
        assert np.abs(g["k_meridian"][0] - k_meridian).max() < 1e-8  # measured 2.6e-10 (k_m from 0.02 to 0.94)
        assert np.abs(g["k_parallel"][0] + g["deta"][0] / (rho * speed)).max() < 1e-10
        assert np.abs(g["rho"][0] - rho).max() < 1e-12 and np.abs(g["lam1"][0] - speed / kappa).max() < 1e-12
    poles = surface(eq.disc, X, np.array([0.0, np.pi]), scene.geometry)
    assert np.abs(poles["k_parallel"] - poles["k_meridian"]).max() < 1e-9


def pressure_maximum(length: float, degree: int, element: float | None = None) -> float:
    """P at the capsule's located pressure fold (``analyse`` from ``degree``, m = 0 stability, under volume control
    to 3.5 V0, past the fold; the cylinder cut into elements of at most ``element`` radii if given)."""
    volume = 3.5 * (np.pi * length + 4 * np.pi / 3)
    scene = capsule_scene(length, f"[continuation]\nstop_stretch = 3.0\n[solver]\ndegree = {degree}\n"
                                  f"[loading]\ncontrol = \"volume\"\nstop_volume = {volume!r}\n", element)
    folds = [p.X[-1] for p in analyse(scene, pear=False).branches[0].special if p.kind.value == "LP"]
    return float(folds[0])


def shared_pressure_maximum(tmp_path_factory, length: float, degree: int, element: float | None = None) -> float:
    """``pressure_maximum`` once per test session (``shared_pictures.shared``): the fold at L = 10 from degree 40 is
    read by three tests in two files."""
    return shared(tmp_path_factory, f"capsule_fold_L{length:g}_degree{degree}_element{element}",
                  lambda: pressure_maximum(length, degree, element))


def test_a_long_capsule_starts_bulging_at_the_long_tubes_onset(tmp_path_factory):
    """SPOM1: the capsule's pressure maximum (where its middle starts to bulge: the caps hold the cylinder's ends
    as plugs do, so the bulge is the even mode, a fold in P) at L = 10, 20, 40, traced from degree 40 (the tracer
    refines each to max_error: the capsule's piecewise basis converges spectrally; at L = 10 the trace from degree
    64 lands on the same fold). It lies above the long tube's pressure maximum P* (model/tube, Yu & Fu's condition)
    and falls onto it faster than 1/L² (gap ratio > 5 per doubling of L); at L = 40 within 1e-3 of P* and of the
    onset of a sliding tube of length 40 (model/tube.bulge_onset, its dispersion relation). Measured: gaps 1.58e-2,
    2.18e-3, 2.22e-4; the two starts within 1e-13 at every L (1e-10 asserted; the Legendre basis in x at fixed
    degrees 64 and 96 differed by 4.7e-7)."""
    material = capsule_scene(0.0).material
    peak, onset = tube.pressure_maximum(material).pressure, tube.bulge_onset(material, 40.0).pressure
    gaps = [shared_pressure_maximum(tmp_path_factory, length, 40) - peak for length in (10.0, 20.0, 40.0)]
    assert abs(pressure_maximum(10.0, 64) - peak - gaps[0]) < 1e-10
    assert all(gap > 0 for gap in gaps) and gaps[0] / gaps[1] > 5 and gaps[1] / gaps[2] > 5
    assert gaps[2] < 1e-3 and abs(gaps[2] + peak - onset) < 1e-3


def test_split_capsule_folds_where_the_single_cylinder_element_does(tmp_path_factory):
    """SPOM1 capsule of length 10 with its cylinder cut into 3 elements (element_length 5: a middle element and a
    mirror pair), traced from degree 40 and refined to max_error: its pressure maximum is the single cylinder
    element's (another basis: the cylinder's polynomials in θ of degree up to ~3× higher, no inner boundaries) to
    1e-10 (measured: the same 13 digits, 1.5063197245255; at L = 20 with 3 and 5 elements and at L = 40 with 5, the
    same 13 digits too: docs/shapes.md)."""
    assert abs(pressure_maximum(10.0, 40, ELEMENT) - shared_pressure_maximum(tmp_path_factory, 10.0, 40)) < 1e-10


@pytest.mark.slow
def test_a_split_long_capsule_starts_bulging_at_the_long_tubes_onset(tmp_path_factory):
    """SPOM1 capsule of length 40, its cylinder cut into 5 elements (element_length 10), from degree 40: its
    pressure maximum within 1e-3 of the long tube's pressure maximum P* and of a sliding tube's onset at L = 40
    (model/tube), and equal to the single element's to 1e-10 (measured 1.4907571927638 on both, ~40 s loaded)."""
    material = capsule_scene(0.0).material
    split = pressure_maximum(40.0, 40, 10.0)
    assert abs(split - tube.pressure_maximum(material).pressure) < 1e-3
    assert abs(split - tube.bulge_onset(material, 40.0).pressure) < 1e-3
    assert abs(split - shared_pressure_maximum(tmp_path_factory, 40.0, 40)) < 1e-10


@pytest.mark.slow
def test_a_long_capsule_propagates_its_bulge_at_maxwells_pressure():
    """SPOM1 capsule of length 40 from degree DEGREE with max_error PLATEAU_ERROR (refined to 288), its primary branch
    under pressure control to pole stretch 3: past its fold the middle bulges and the bulge widens, its two fronts
    moving towards the caps. Where both fronts are far from the caps and from each other (200 ≤ V/V0 ≤ 600,
    V0 = 40π + 4π/3) P is within 1e-4 of Maxwell's pressure (model/tube.maxwell_pressure, checked against the
    equal-area rule in tests/test_tube.py), from V/V0 = 400 within 1e-7; beyond V/V0 ≈ 700 the fronts reach the caps
    and P rises (docs/shapes.md has the table). Measured 2.8e-5 and 2.0e-8; 400–700 s on the loaded machine."""
    scene = capsule_scene(40.0, "[continuation]\nstop_stretch = 3.0\nmax_points = 3000\nstep_max = 1.0\n"
                                f"[solver]\ndegree = {DEGREE}\nmax_error = {PLATEAU_ERROR}\n")
    branch = analyse(scene, pear=False).branches[0]
    fold = next(i for i, p in enumerate(branch.special) if p.kind.value == "LP")
    assert abs(branch.special[fold].X[-1] - tube.pressure_maximum(scene.material).pressure) < 1e-3
    maxwell, _, _ = tube.maxwell_pressure(scene.material)
    eq = Equilibrium(scene, branch.disc)
    volume = np.array([2 * np.pi * eq.volume(x[:-1]) for x in branch.X]) / (40 * np.pi + 4 * np.pi / 3)
    plateau = (volume >= 200) & (volume <= 600)
    assert plateau.sum() > 50 and np.all(np.diff(volume[plateau]) > 0)
    assert np.abs(branch.X[plateau, -1] - maxwell).max() <= 1e-4
    assert np.abs(branch.X[plateau & (volume >= 400), -1] - maxwell).max() <= 1e-7


def test_volume_control_measures_the_capsules_volume():
    """SPOM1 capsule of length 10 (degree 64) under volume control with stop_volume = 4 V0 (V0 = 10π + 4π/3): past
    its pressure fold the branch lands on the stop, where the enclosed volume written here, π∫ρ²(−η') dθ with
    ρ = λ2 R and the capsule's R(θ) written here (composite Gauss–Legendre in θ, 200 nodes on each cap and on the
    cylinder), is the stop to 1e-9; the sphere's volume formula (ρ = λ2 sin θ) misses it by more than 1 %. The
    pressure fold is no fold of V: the points beside it are stable under volume control."""
    V0 = 10 * np.pi + 4 * np.pi / 3
    scene = capsule_scene(10.0, f"[continuation]\nstop_stretch = 3.0\n[solver]\ndegree = 64\n"
                                f"[loading]\ncontrol = \"volume\"\nstop_volume = {4 * V0!r}\n")
    branch = analyse(scene, pear=False).branches[0]
    assert branch.stop_reason.startswith("up: reached stop_volume")
    kappa = 1 + 10 / np.pi
    joint = np.pi / (2 * kappa)
    nodes, weights = np.polynomial.legendre.leggauss(200)
    theta, dtheta = [], []
    for a, b in ((0.0, joint), (joint, np.pi - joint), (np.pi - joint, np.pi)):
        theta.append((b - a) / 2 * nodes + (a + b) / 2)
        dtheta.append((b - a) / 2 * weights)
    theta, dtheta = np.concatenate(theta), np.concatenate(dtheta)
    R = np.where(kappa * theta < np.pi / 2, np.sin(kappa * theta),
                 np.where(kappa * (np.pi - theta) < np.pi / 2, np.sin(kappa * (np.pi - theta)), 1.0))
    lam2, _, _, deta = branch.disc.evaluate(branch.X[-1, :-1], theta)
    volume = np.pi * dtheta @ ((lam2 * R) ** 2 * -deta)
    sphere_formula = np.pi * dtheta @ ((lam2 * np.sin(theta)) ** 2 * -deta)
    assert abs(volume - 4 * V0) <= 1e-9 * 4 * V0
    assert abs(sphere_formula - 4 * V0) > 1e-2 * 4 * V0
    fold = next(p for p in branch.special if p.kind.value == "LP")
    beside = [branch.stability[i] for i in (fold.index, fold.index + 1)]
    assert all(a.stable_volume for a in beside) and not all(a.stable_pressure for a in beside)


@pytest.fixture(scope="module")
def capsule_run(tmp_path_factory):
    """A run file of ``balloon-cg run`` on a capsule of length 10 (to pole stretch 1.05, before its fold, degree 64)."""
    from balloon_cg.app.cli import main

    folder = tmp_path_factory.mktemp("capsule_run")
    scene = folder / "capsule.toml"
    scene.write_text(CAPSULE.format(length=10.0, split="") + "[continuation]\nstop_stretch = 1.05\n[solver]\ndegree = 64\n")
    path = folder / "capsule.h5"
    assert main(["run", str(scene), "-o", str(path), "--quiet"]) == 0
    return path


def test_run_writes_the_capsules_profiles(capsule_run, capsys):
    """``balloon-cg run`` on a capsule of length 10 (to pole stretch 1.05, before its fold) writes a run file whose
    profiles measure from the capsule: ρ = λ2 R with R written here (1 on the cylinder, sin κθ on the caps), λ1
    finite on the whole θ grid and equal to λ2 at the poles (isotropic there), 1e-10; ``inspect`` (text and
    --json), ``bc.load`` and its xarray name the shape and its length."""
    import balloon_cg as bc
    from balloon_cg.app.cli import main
    from balloon_cg.io.run_file import read_run

    path = capsule_run
    capsys.readouterr()
    assert main(["inspect", str(path)]) == 0
    assert "shape          capsule of length 10\n" in capsys.readouterr().out
    assert main(["inspect", "--json", str(path)]) == 0
    assert json.loads(capsys.readouterr().out)["geometry"] == {"shape": "capsule", "length": 10.0}
    result = bc.load(path)
    assert result.geometry == {"shape": "capsule", "length": 10.0} and "capsule of length 10" in repr(result)
    for part in ("points", "special"):
        attrs = result.to_xarray(part=part).attrs
        assert attrs["shape"] == "capsule" and attrs["length"] == 10.0
    branch = read_run(path)["branches"]["primary"]
    profiles, theta = branch["profiles"], branch["theta"]
    kappa = 1 + 10 / np.pi
    R = np.where(kappa * theta < np.pi / 2, np.sin(kappa * theta),
                 np.where(kappa * (np.pi - theta) < np.pi / 2, np.sin(kappa * (np.pi - theta)), 1.0))
    assert np.abs(profiles["rho"] - profiles["lam2"] * R).max() < 1e-10
    assert np.all(np.isfinite(profiles["lam1"]))
    assert np.abs(profiles["lam1"][:, [0, -1]] - profiles["lam2"][:, [0, -1]]).max() < 1e-10


# what ``plot`` draws of the capsule's run file; every other kind is refused (a pressure-continued branch without
# coils, stability landscape, frequencies, curves or surface branches)
DRAWN = {"pressure-pole", "pressure-equator", "shapes", "stresses", "curvature"}


def test_plot_of_a_capsule_draws_or_refuses_every_kind(capsule_run, tmp_path, capsys):
    """``balloon-cg plot`` of the capsule's run file, every kind: the five of DRAWN write their image (exit 0; the
    curvatures and stresses are the capsule's, tests above), the others exit 2 with one line naming why."""
    from balloon_cg.app.cli import PLOT_KINDS, main

    capsys.readouterr()
    for kind in PLOT_KINDS:
        image = tmp_path / f"{kind}.png"
        code = main(["plot", str(capsule_run), "--what", kind, "-o", str(image)])
        err = capsys.readouterr().err
        if kind in DRAWN:
            assert code == 0 and image.stat().st_size > 0, (kind, err)
        else:
            assert code == 2 and not image.exists() and len(err.strip().splitlines()) == 1, (kind, code, err)
            assert err.startswith("balloon-cg: error: "), (kind, err)


def test_capsule_of_length_3_to_stretch_2_is_complete(tmp_path, capsys):
    """``balloon-cg run`` on a SPOM1 capsule of length 3 to pole stretch 2 (m = 0) exits 0: its pear branches, switched
    at the equator-breaking branch point, have no point whose stability flags change at the check degree (they
    did at degree 20, where their first point's pear eigenvalue read 2.6e-6 against its converged −1.2e-8:
    analysis/stability/axisymmetric.point_degrees assesses a capsule at its branch's degree). The branch point is
    where the primary branch traced from degree 64 has it (1e-10)."""
    from balloon_cg.app.cli import main
    from balloon_cg.io.run_file import read_run

    text = CAPSULE.format(length=3.0, split="") + "[continuation]\nstop_stretch = 2.0\n"
    scene = tmp_path / "capsule.toml"
    scene.write_text(text)
    path = tmp_path / "capsule.h5"
    assert main(["run", str(scene), "-o", str(path), "--quiet"]) == 0
    capsys.readouterr()
    branches = read_run(path)["branches"]
    assert {"primary", "pear_0", "pear_0_mirror"} <= set(branches)
    stored = [p["pressure"] for p in branches["primary"]["special_points"] if p["kind"] == "BP"]
    finer = analyse(parse_scene(text + "[solver]\ndegree = 64\n"), pear=False).branches[0]
    again = [p.X[-1] for p in finer.special if p.kind.value == "BP"]
    assert len(stored) == len(again) == 1 and abs(stored[0] - again[0]) < 1e-10


def test_capsule_table_errors_name_key_value_and_range():
    for extra, words in [
        ('[geometry]\nshape = "capsule"\n', "geometry.length: missing"),
        ('[geometry]\nshape = "capsule"\nlength = -1\n', "geometry.length = -1"),
        ('[geometry]\nshape = "capsule"\nlength = 5\naspect = 2\n', "geometry.aspect = 2"),
        ('[geometry]\nshape = "capsule"\nlength = 5\nends = "plugged"\n', "geometry.ends"),
        ('[geometry]\nshape = "spheroid"\naspect = 2\nlength = 5\n', "geometry.length = 5"),
        ('[geometry]\nshape = "capsule"\nlength = 5\n[stability]\nm_max = 0\n[field]\nM = 0.01\n'
         '[[field.coils]]\nradius = 0.8\nheight = 3.0\ncurrent = 1.0\n', "inside the reference capsule of length 5"),
        ('[geometry]\nshape = "capsule"\nlength = 5\n[stability]\nm_max = 0\n[field]\nM = 0.01\n'
         '[[field.coils]]\nradius = 2.0\ncentre = [0.5, 0.0, 0.0]\ncurrent = 1.0\n', "coils off the axis"),
        ('[geometry]\nshape = "spheroid"\naspect = 2\nelement_length = 5\n', "geometry.element_length = 5"),
        ('[geometry]\nshape = "capsule"\nlength = 5\nelement_length = 0.5\n', "geometry.element_length = 0.5"),
        ('[geometry]\nshape = "capsule"\nlength = 100\nelement_length = 2\n', "at most 41 elements"),
    ]:
        with pytest.raises(SceneError) as error:
            parse_scene('[material]\npreset = "SPOM1"\n' + extra)
        assert words in str(error.value) and "\n" not in str(error.value)
    scene = capsule_scene(5.0)
    assert scene.geometry.to_table() == {"shape": "capsule", "length": 5.0}
    assert scene.geometry.describe() == "capsule of length 5"
    split = capsule_scene(12.0, element=5.0)
    assert split.geometry.to_table() == {"shape": "capsule", "length": 12.0, "element_length": 5.0}
    assert parse_scene(split.to_toml()).geometry == split.geometry and len(meridian.joins(split.geometry)) == 4


COIL = '[field]\nM = {M}\n[[field.coils]]\nradius = 3.0\nheight = 0.0\ncurrent = 1.0\n'


def capsule_radius(theta, kappa):
    """(R, dR/dθ) of the capsule over θ = S/κ (module docstring), written here."""
    north, south = kappa * theta, kappa * (np.pi - theta)
    R = np.where(north < np.pi / 2, np.sin(north), np.where(south < np.pi / 2, np.sin(south), 1.0))
    dR = np.where(north < np.pi / 2, kappa * np.cos(north), np.where(south < np.pi / 2, -kappa * np.cos(south), 0.0))
    return R, dR


def energy_gradient(scene, branch, term):
    """∂E/∂u at the last point of a capsule's ``branch`` by central differences (step 1e-6) of the energy written
    here, E/2π = ∫ [Φ(λ1, λ2) + term(λ1, λ2, ρ, η)] R κ dθ + ½ P ∫ ρ² η' dθ, ρ = λ2 R, λ1 = |ρ', η'|/κ (Ogden, the
    capsule's R written here, Gauss–Legendre with 200 nodes on each cap and on the cylinder)."""
    from test_interval import ogden

    u, P, disc = branch.X[-1, :-1], branch.X[-1, -1], branch.disc
    kappa = 1 + scene.geometry.length / np.pi
    joint = np.pi / (2 * kappa)
    nodes, weights = legendre.leggauss(200)
    pieces = ((0.0, joint), (joint, np.pi - joint), (np.pi - joint, np.pi))
    theta = np.concatenate([(b - a) / 2 * nodes + (a + b) / 2 for a, b in pieces])
    dtheta = np.concatenate([(b - a) / 2 * weights for a, b in pieces])
    R, dR = capsule_radius(theta, kappa)

    def energy(unknowns):
        lam2, dlam2, eta, deta = disc.evaluate(unknowns, theta)
        rho, drho = lam2 * R, dlam2 * R + lam2 * dR
        lam1 = np.hypot(drho, deta) / kappa
        density = ogden(scene.material, lam1, lam2) + term(lam1, lam2, rho, eta)
        return dtheta @ (density * R * kappa + 0.5 * P * rho**2 * deta)

    return np.array([energy(u + 1e-6 * e) - energy(u - 1e-6 * e) for e in np.eye(disc.size)]) / 2e-6


def test_capsule_in_a_coil_field_is_stationary_for_the_energy_written_here():
    """SPOM1 capsule of length 3 in the field of a coil of radius 3 around its middle, M = 0.005 (the magnetic term's
    kernels on the capsule's meridian, generated on demand; the field at ρ = λ2 R): at the last point of its primary
    branch to pole stretch 1.05 the energy written here (``energy_gradient``) with the term −½ χ M H²(ρ, η) (H² by
    the Biot–Savart integral of tests/test_tube_field.py) is stationary along every basis direction (1e-8), and it
    is not without the field's term (> 1e-3)."""
    from test_tube_field import biot_savart_squared

    scene = capsule_scene(3.0, "[continuation]\nstop_stretch = 1.05\n" + COIL.format(M=0.005))
    branch = analyse(scene, pear=False).branches[0]
    assert branch.kernel_class.startswith("ogden_magnetic_capsule")
    coils = [(c.radius, c.height, c.current) for c in scene.field.coils]

    def field(M):
        return lambda lam1, lam2, rho, eta: -scene.field.chi * M * biot_savart_squared(rho, eta, coils) / 2

    assert np.abs(energy_gradient(scene, branch, field(scene.field.M))).max() < 1e-8
    assert np.abs(energy_gradient(scene, branch, field(0.0))).max() > 1e-3


def test_capsule_under_a_voltage_is_stationary_for_the_energy_written_here():
    """SPOM1 capsule of length 3 under the voltage Φ̄ = 0.1 ([electric]: its start inflated without it, then the
    voltage switched on at the start stretch; the dielectric term's kernels on the capsule's meridian): at the last
    point of its primary branch to pole stretch 1.05 the energy written here (``energy_gradient``) with the term
    −Φ̄² λ1² λ2² (MODEL.md §2) is stationary along every basis direction (1e-8), and it is not without it (> 1e-3).
    (Below the start the charged capsule nears compression and the trace needs max_degree: min_stretch 1.004.)"""
    scene = capsule_scene(3.0, "[continuation]\nstop_stretch = 1.05\nmin_stretch = 1.004\n"
                               "[electric]\nvoltage = 0.1\n")
    branch = analyse(scene, pear=False).branches[0]
    assert branch.kernel_class.startswith("ogden_dielectric_capsule") and branch.params.voltage == 0.1

    def dielectric(voltage):
        return lambda lam1, lam2, rho, eta: -voltage**2 * lam1**2 * lam2**2

    assert np.abs(energy_gradient(scene, branch, dielectric(0.1))).max() < 1e-8
    assert np.abs(energy_gradient(scene, branch, dielectric(0.0))).max() > 1e-3


@pytest.mark.parametrize("load", [COIL.format(M=0.005), "[electric]\nvoltage = 0.1\n"], ids=["coil", "voltage"])
def test_capsule_of_length_zero_in_a_field_or_under_a_voltage_is_the_sphere(load):
    """SPOM1 with the coil of radius 3 around the middle at M = 0.005, or under the voltage 0.1, to pole stretch 1.5:
    every point of the capsule of length 0 (its magnetic or dielectric kernels another module; under a voltage its
    start inflated, then charged, the sphere's in closed form) is the sphere's to 1e-10, the fold too."""
    text = ('[material]\npreset = "SPOM1"\n[stability]\nm_max = 0\n[continuation]\nstop_stretch = 1.5\n' + load)
    one, other = (analyse(parse_scene(text + extra), pear=False).branches[0]
                  for extra in ("", '[geometry]\nshape = "capsule"\nlength = 0\n'))
    assert other.kernel_class != one.kernel_class and one.X.shape == other.X.shape
    assert np.abs(one.X - other.X).max() <= 1e-10
    assert [p.kind for p in one.special] == [p.kind for p in other.special]


def test_capsule_of_length_zero_in_a_field_reads_its_m1_blocks_above_banded_from():
    """Above stability.banded_from the sphere reads its blocks on the banded sibling, whose m ≥ 1 blocks take the
    sphere's m ≥ 1 mass kernel; a capsule has none (its m ≥ 1 blocks have their own elements): the capsule of
    length 0 in a coil's field stopped with a KeyError there (the two-coil scene as a capsule of length 0, whose
    degree reaches 225). With banded_from = 20 (the branch at degree 40): the capsule's readings, on its own
    blocks, are the sphere's on the sibling (1e-8; measured 1.8e-10 in m1_held at degree 20), every flag alike."""
    text = ('[material]\npreset = "SPOM1"\n[stability]\nm_max = 1\nbanded_from = 20\n[continuation]\n'
            'stop_stretch = 1.5\n[surface]\nbranches = "none"\n' + COIL.format(M=0.005))
    sphere, capsule = (analyse(parse_scene(text + extra), pear=False).branches[0]
                       for extra in ("", '[geometry]\nshape = "capsule"\nlength = 0\n'))
    assert len(sphere.stability) == len(capsule.stability) > 5
    for a, b in zip(sphere.stability, capsule.stability):
        assert a.degree >= 20 and a.flags() == b.flags()
        for block in ("even", "m1_held", "m1_free"):
            assert abs(a.blocks[block][0] - b.blocks[block][0]) <= 1e-8 * max(1.0, abs(a.blocks[block][0])), block
