"""Applied coil field (MODEL.md §3): closed form vs Biot–Savart quadrature, derivatives, axis, wires, codegen.

Reference: the trapezoid rule in ψ over the Biot–Savart integrand and its (ρ, ζ) derivatives (differentiated
by SymPy), spectrally accurate for this periodic integrand away from the wire. Errors of order-k derivatives
are measured relative to max(|order-k entries|, |h| / d^k), d the distance to the wire (the local length scale).
"""
import math
from pathlib import Path

import mpmath
import numpy as np
import pytest
import scipy.special
import sympy as sp

from balloon_cg.model.elliptic import complete_elliptic, loop_elliptic
from balloon_cg.model.field import (
    WIRE_TOLERANCE,
    FieldError,
    coil_field_unit,
    field_components,
    field_squared,
    field_squared_nodes,
    stream_shape,
    wire_distance,
)
from balloon_cg.model import field
from balloon_cg.generated.coil_field import stream_shape_closed
from codegen import field as field_codegen
from codegen.emit import module_text
from codegen.kernels import lower

GENERATED = Path(__file__).resolve().parent.parent / "generated" / "coil_field.py"
PAPER_COILS = np.array([[1.7321, 1.0, 1.0], [1.7321, -1.0, -1.0]])
MIXED_COILS = np.array([[1.7321, 1.0, 1.0], [1.7321, -1.0, -1.0], [0.8, 0.25, 0.5], [2.5, -0.4, -2.0]])


def _integrands():
    rho, zeta, a, psi = sp.symbols("rho zeta a psi", real=True)
    cube = (rho**2 + zeta**2 + a**2 - 2 * rho * a * sp.cos(psi)) ** sp.Rational(3, 2)
    h = [zeta * a * sp.cos(psi) / cube, (a**2 - rho * a * sp.cos(psi)) / cube]
    first = [sp.diff(c, v) for c in h for v in (rho, zeta)]
    second = [sp.diff(c, u, v) for c in h for u, v in ((rho, rho), (rho, zeta), (zeta, zeta))]
    return sp.lambdify((rho, zeta, a, psi), [*h, *first, *second], "numpy")


INTEGRANDS = _integrands()


def quadrature(rho, zeta, a, nodes=4096):
    """The 12 numbers of coil_field_unit by the trapezoid rule in ψ."""
    psi = 2.0 * np.pi * np.arange(nodes) / nodes
    return np.array([2.0 * np.pi * np.mean(np.broadcast_to(v, psi.shape)) for v in INTEGRANDS(rho, zeta, a, psi)])


def quadrature_sum(rho, z, coils):
    return sum(s * quadrature(rho, z - h, a) for a, h, s in coils)


def squared_from(t):
    """(Q, Q_ρ, Q_z, Q_ρρ, Q_ρz, Q_zz) from the 12 numbers, by the product rule."""
    f, g, f_r, f_z, g_r, g_z, f_rr, f_rz, f_zz, g_rr, g_rz, g_zz = t
    return np.array([
        f * f + g * g, 2 * (f * f_r + g * g_r), 2 * (f * f_z + g * g_z),
        2 * (f_r**2 + f * f_rr + g_r**2 + g * g_rr), 2 * (f_r * f_z + f * f_rz + g_r * g_z + g * g_rz),
        2 * (f_z**2 + f * f_zz + g_z**2 + g * g_zz),
    ])  # fmt: skip


def field_errors(got, want, distance):
    """Scaled errors of the order-0, -1, -2 groups of the 12 numbers."""
    got, want = np.asarray(got), np.asarray(want)
    size = np.max(np.abs(want[:2]))
    groups = (slice(0, 2), slice(2, 6), slice(6, 12))[: len(want) // 4 + 1]  # 2 or 12 numbers
    return [
        np.max(np.abs(got[g] - want[g])) / max(np.max(np.abs(want[g])), size / distance**k)
        for k, g in enumerate(groups)
    ]


def squared_errors(got, want, distance):
    got, want = np.asarray(got), np.asarray(want)
    groups = (slice(0, 1), slice(1, 3), slice(3, 6))
    return [
        np.max(np.abs(got[g] - want[g])) / max(np.max(np.abs(want[g])), want[0] / distance**k)
        for k, g in enumerate(groups)
    ]


def random_points(count, seed):
    """(ρ, ζ, a) with ρ = 0 exactly, ρ tiny (near the axis) or generic, at least 0.15 a from the wire."""
    rng = np.random.default_rng(seed)
    points = []
    while len(points) < count:
        a = rng.uniform(0.3, 3.0)
        rho = [0.0, 10.0 ** rng.uniform(-9, -3), rng.uniform(0.0, 4.0 * a)][len(points) % 3]
        zeta = rng.uniform(-3.0, 3.0) * a
        if math.hypot(rho - a, zeta) > 0.15 * a:
            points.append((rho, zeta, a))
    return points


SPECIAL_POINTS = [
    (0.0, 0.0, 1.0),  # loop centre
    (0.0, 0.0, 2.7),
    (1e-300, 0.4, 1.0),
    (3.0 - 2.0 * math.sqrt(2.0), 0.0, 1.0),  # m = 1/2 (the series/closed-form switch) up to rounding
    (np.nextafter(3.0 - 2.0 * math.sqrt(2.0), 1.0), 0.0, 1.0),
    (np.nextafter(3.0 - 2.0 * math.sqrt(2.0), 0.0), 0.0, 1.0),
    (0.25, 0.3, 1.0),
    (1.0, 0.2, 1.0),  # m ≈ 0.99
    (1.3, -0.25, 1.0),
    (30.0, 40.0, 1.0),  # far field
    (0.3, -80.0, 2.0),
]


@pytest.mark.parametrize("rho, zeta, a", random_points(45, seed=3) + SPECIAL_POINTS)
def test_single_coil_matches_quadrature(rho, zeta, a):
    distance = math.hypot(rho - a, zeta)
    errors = field_errors(coil_field_unit(rho, zeta, a), quadrature(rho, zeta, a), distance)
    assert max(errors) < 1e-12, errors


def test_several_coils_with_signs_match_quadrature():
    points = [(rho, z) for rho, z, _ in random_points(40, seed=11)] + [(0.0, 0.0), (0.0, 0.63), (1.2, 0.1)]
    for rho, z in points:
        distance = wire_distance(rho, z, MIXED_COILS)
        if distance < 0.15:
            continue
        want = quadrature_sum(rho, z, MIXED_COILS)
        h_rho, h_z = field_components(rho, z, MIXED_COILS)
        assert max(field_errors([h_rho, h_z], want[:2], distance)) < 1e-12
        assert max(squared_errors(field_squared(rho, z, MIXED_COILS), squared_from(want), distance)) < 1e-12


def test_field_at_loop_centre_is_two_pi_over_radius():
    for a, height in [(1.0, 0.0), (1.7321, 1.0), (0.4, -2.5)]:
        coils = np.array([[a, height, 1.0]])
        h_rho, h_z = field_components(0.0, height, coils)
        assert h_rho == 0.0
        assert h_z == pytest.approx(2.0 * math.pi / a, rel=1e-15)
        assert field_squared(0.0, height, coils)[0] == pytest.approx((2.0 * math.pi / a) ** 2, rel=1e-15)
        reversed_current = coils * [1.0, 1.0, -1.0]
        assert field_squared(0.0, height, reversed_current)[0] == pytest.approx((2.0 * math.pi / a) ** 2, rel=1e-15)


def test_maxwell_identities():
    """div h = ∂_ρh_ρ + h_ρ/ρ + ∂_ζh_z = 0 and curl h = ∂_ζh_ρ − ∂_ρh_z = 0, away from the axis."""
    for rho, zeta, a in random_points(30, seed=5):
        if rho < 1e-2:
            continue
        h = coil_field_unit(rho, zeta, a)
        scale = max(abs(x) for x in h[2:6])
        assert abs(h[2] + h[0] / rho + h[5]) < 1e-13 * (scale + abs(h[0]) / rho)
        assert abs(h[3] - h[4]) < 1e-13 * scale


@pytest.mark.parametrize("coils", [PAPER_COILS, MIXED_COILS], ids=["paper", "mixed"])
def test_squared_derivatives_match_finite_differences(coils):
    rng = np.random.default_rng(7)
    step = 1e-4
    for rho, z in zip(rng.uniform(0.05, 1.5, 25), rng.uniform(-1.5, 1.5, 25)):
        distance = wire_distance(rho, z, coils)
        q = np.array(field_squared(rho, z, coils))
        at = lambda dr, dz: np.array(field_squared(rho + dr * step, z + dz * step, coils))  # noqa: E731
        r_plus, r_minus, z_plus, z_minus = at(1, 0), at(-1, 0), at(0, 1), at(0, -1)
        first = [(r_plus[0] - r_minus[0]) / (2 * step), (z_plus[0] - z_minus[0]) / (2 * step)]
        second = [
            (r_plus[1] - r_minus[1]) / (2 * step),
            (z_plus[1] - z_minus[1]) / (2 * step),
            (r_plus[2] - r_minus[2]) / (2 * step),
            (z_plus[2] - z_minus[2]) / (2 * step),
        ]
        want = np.array([q[0], *first, second[0], second[1], second[3]])
        assert max(squared_errors(q, want, distance)) < 1e-6
        assert abs(second[1] - second[2]) < 1e-6 * max(abs(q[4]), q[0] / distance**2)
        # Second difference of Q itself, Richardson-extrapolated (truncation ~ h⁴, rounding ~ eps/h²).
        second_difference = lambda h: (at(h / step, 0)[0] - 2 * q[0] + at(-h / step, 0)[0]) / h**2  # noqa: E731
        q_rr = (4 * second_difference(1e-3) - second_difference(2e-3)) / 3
        assert q_rr == pytest.approx(q[3], rel=1e-6, abs=1e-6 * q[0] / distance**2)


@pytest.mark.parametrize("z", [0.0, 0.37, -1.4, 2.5])
@pytest.mark.parametrize("coils", [PAPER_COILS, MIXED_COILS], ids=["paper", "mixed"])
def test_exact_and_smooth_on_the_axis(coils, z):
    q = field_squared(0.0, z, coils)
    assert np.all(np.isfinite(q))
    assert q[1] == 0.0 and q[4] == 0.0
    assert field_components(0.0, z, coils)[0] == 0.0
    # Q is even in ρ: Q(δ) = Q(0) + Q_ρρ(0) δ²/2 + O(δ⁴); ρ < 0 is the mirror point.
    delta = 1e-3
    q_delta = field_squared(delta, z, coils)
    assert field_squared(-delta, z, coils) == pytest.approx(q_delta * np.array([1, -1, 1, 1, -1, 1]), rel=1e-15)
    scale = q[0] + abs(q[3])
    assert 2.0 * (q_delta[0] - q[0]) / delta**2 == pytest.approx(q[3], abs=1e-5 * scale)
    for tiny in (1e-300, 1e-12):
        assert np.allclose(field_squared(tiny, z, coils), q, rtol=1e-12, atol=1e-11 * scale)
    q_tiny = field_squared(1e-8, z, coils)  # Q_ρ ≈ Q_ρρ(0) ρ, no 1/ρ blow-up
    assert q_tiny[1] / 1e-8 == pytest.approx(q[3], abs=1e-6 * scale)


def test_nodes_match_scalar():
    rho = np.array([0.0, 0.3, 1.2, 2.2])
    z = np.array([0.1, -0.5, 0.9, 0.0])
    out = np.empty((6, rho.size))
    field_squared_nodes(rho, z, MIXED_COILS, out)
    for i in range(rho.size):
        assert np.array_equal(out[:, i], field_squared(rho[i], z[i], MIXED_COILS))


def _hypergeometric_shape(m, k):
    """G^(k)(m) = π/32 · (3/2)_k² / (3)_k · ₂F₁(3/2 + k, 3/2 + k; 3 + k; m), since G = π/32 ₂F₁(3/2, 3/2; 3; m)."""
    factor = mpmath.pi / 32 * mpmath.rf(1.5, k) ** 2 / mpmath.rf(3, k)
    return float(factor * mpmath.hyp2f1(1.5 + k, 1.5 + k, 3 + k, m))


def test_stream_shape_accuracy_and_continuity_at_switch():
    mpmath.mp.dps = 40
    for m in [0.0, 1e-12, 1e-4, 0.1, 0.3, 0.49, 0.5, 0.51, 0.7, 0.9, 0.99, 0.9999]:
        got = stream_shape(m, 1.0 - m)
        want = [_hypergeometric_shape(mpmath.mpf(m), k) for k in range(4)]
        assert got == pytest.approx(want, rel=1e-13)
    m1 = field.PIECE_FLOOR  # the last piece's lower end against the closed form (the AGM just below it)
    k, n = loop_elliptic(1.0 - m1, m1)
    piece, closed = np.array(stream_shape(1.0 - m1, m1)), np.array(stream_shape_closed(1.0 - m1, m1, k, n))
    assert np.max(np.abs(closed / piece - 1.0)) < 1e-14
    below = np.array(stream_shape(1.0 - m1, np.nextafter(m1, 0.0)))
    assert np.max(np.abs(below / piece - 1.0)) < 1e-13


def _mpmath_shape(m1):
    """G^(j)(m), j ≤ 3, at m = 1 − m1 (m1 a float, taken exactly): mpmath's K and E in the closed form
    ((1 − m/2) K − E)/m², differentiated by mpmath.diff, at 90 digits (the closed form cancels ~m² of them)."""
    def shape(m):
        return ((1 - m / 2) * mpmath.ellipk(m) - mpmath.ellipe(m)) / m**2

    with mpmath.workdps(90):
        m = 1 - mpmath.mpf(m1)
        if m == 0:  # G = π/32 ₂F₁(3/2, 3/2; 3; m): G^(j)(0) = π/32 (3/2)_j² / (3)_j
            return [float(mpmath.pi / 32 * mpmath.rf(1.5, j) ** 2 / mpmath.rf(3, j)) for j in range(4)]
        return [float(mpmath.diff(shape, m, j)) for j in range(4)]


def test_stream_shape_pieces_against_mpmath():
    """Every piece at its ends (and one ulp inside and outside them), its centre and random points, m1 = 1 − m
    given exactly: G..G''' within 3 ulp of mpmath's K, E closed form (the input is exact: condition 1)."""
    per_octave, octaves, _ = field.STREAM_PIECE_GRID
    ends = np.concatenate([2.0 ** -(o + 1) * (1.0 + np.arange(per_octave + 1) / per_octave) for o in range(octaves)])
    ends = np.unique(ends)
    m1 = np.concatenate([ends, np.nextafter(ends, 0.0), np.nextafter(ends, 2.0)[:-1], field._CENTRES,
                         2.0 ** np.random.default_rng(11).uniform(-octaves, 0.0, 200)])
    m1 = m1[m1 >= field.PIECE_FLOOR]
    got = np.array([stream_shape(1.0 - x, x) for x in m1])
    want = np.array([_mpmath_shape(x) for x in m1])
    assert np.abs(got / want - 1.0).max() <= 3 * np.finfo(float).eps


def test_stream_shape_pieces_match_the_agm_closed_form():
    """Above m = 1/2 the pieces against the AGM and the generated closed form they replace there (which the
    test above does not use): agreement to the closed form's own error (it cancels ≤ 26-fold in G''')."""
    m1 = np.concatenate([np.linspace(field.PIECE_FLOOR, 0.5, 2001), 2.0 ** np.linspace(-12.0, -1.0, 2001)])
    got = np.array([stream_shape(1.0 - x, x) for x in m1])
    closed = np.array([stream_shape_closed(1.0 - x, x, *loop_elliptic(1.0 - x, x)) for x in m1])
    assert np.abs(got / closed - 1.0).max() < 5e-14


def test_complete_elliptic_matches_scipy():
    m = np.concatenate([np.linspace(0.0, 0.999, 200), 1.0 - np.logspace(-4, -12, 9)])
    for value in m:
        k, e = complete_elliptic(value)
        assert k == pytest.approx(scipy.special.ellipk(value), rel=2e-15)
        assert e == pytest.approx(scipy.special.ellipe(value), rel=1e-15 * (1.0 + k))
    for m1 in (1e-20, 1e-100, 1e-300):  # the complement given exactly: K = ln(4/√m1) + O(m1 ln m1)
        k, e = complete_elliptic(1.0, m1)
        assert k == pytest.approx(scipy.special.ellipkm1(m1), rel=2e-15)
        assert e == pytest.approx(1.0, rel=1e-15 * k)
    for bad in (1.0, 1.5, -0.1, math.nan):
        assert all(math.isnan(x) for x in complete_elliptic(bad))


def test_loop_elliptic_numerator_has_no_cancellation():
    mpmath.mp.dps = 40
    for m in (1e-12, 1e-6, 0.01, 0.5, 0.9):
        k, n = loop_elliptic(m, 1.0 - m)
        want = (1 - mpmath.mpf(m) / 2) * mpmath.ellipk(mpmath.mpf(m)) - mpmath.ellipe(mpmath.mpf(m))
        assert n == pytest.approx(float(want), rel=2e-15)


def test_point_on_a_wire_is_an_error():
    a, height = MIXED_COILS[2, :2]
    for rho, z in [(a, height), (a + 0.5e-12 * a, height), (-a, height)]:
        with pytest.raises(FieldError, match=r"coil 2 \(radius 0\.8, height 0\.25\)") as info:
            field_components(np.array([0.1, rho]), np.array([0.0, z]), MIXED_COILS)
        assert repr(float(z)) in str(info.value)
        assert all(math.isnan(x) for x in field_squared(rho, z, MIXED_COILS))
    out = np.empty((6, 2))
    field_squared_nodes(np.array([0.1, a]), np.array([0.0, height]), MIXED_COILS, out)
    assert np.all(np.isfinite(out[:, 0])) and np.all(np.isnan(out[:, 1]))
    close = a + 100 * WIRE_TOLERANCE * a  # close to, but not on, the wire: finite and huge
    assert np.all(np.isfinite(field_squared(close, height, MIXED_COILS)))
    assert np.all(np.isfinite(field_components(close, height, MIXED_COILS)))


def test_wire_distance_and_coil_validation():
    assert wire_distance(0.0, 0.0, PAPER_COILS) == pytest.approx(2.0, rel=1e-4)
    distances = wire_distance(np.array([[1.7321], [0.0]]), np.array([1.0, 0.5]), PAPER_COILS)
    assert distances.shape == (2, 2)
    assert distances[0, 0] == 0.0 and distances[1, 1] == pytest.approx(math.hypot(1.7321, 0.5))
    with pytest.raises(FieldError, match="shape"):
        field_components(0.0, 0.0, np.array([1.0, 0.0, 1.0]))
    with pytest.raises(FieldError, match="coil 1"):
        wire_distance(0.0, 0.0, np.array([[1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]]))


@pytest.fixture(scope="module")
def module_parts():
    return field_codegen.field_module()


def test_field_expressions_never_divide_by_rho(module_parts):
    _, _, kernels, _, _ = module_parts
    coil_field = next(k for k in kernels if k.name == "coil_field")
    assert len(coil_field.outputs) == len(field_codegen.FIELD_NAMES) == 12
    for expr in coil_field.outputs:
        assert expr.is_polynomial(field_codegen.rho)
    (inv_s2, expr), = coil_field.stages[0]
    assert inv_s2 == field_codegen.inv_s2 and sp.denom(expr).subs(field_codegen.rho, 0) != 0


def test_piece_coefficients_are_the_taylor_coefficients():
    """The recurrence's a_k = G^(k)(c)/k! against the Maclaurin series of G = π/32 ₂F₁(3/2, 3/2; 3; m) re-expanded
    about c (c ≤ 1/2: a_k = Σ_n g_n C(n, k) c^(n−k)) and, near a wire, against mpmath.diff of the K, E closed form."""
    pieces = field_codegen.pieces()
    with mpmath.workdps(50):
        g = [mpmath.pi / 32 * mpmath.rf(1.5, n) ** 2 / (mpmath.rf(3, n) * mpmath.factorial(n)) for n in range(400)]
        for c1, _ in (pieces[0], pieces[7]):  # c = 15/32 and 1/32
            c = 1 - field_codegen._dyadic(c1)
            want = [mpmath.fsum(g[n] * mpmath.binomial(n, k) * c ** (n - k) for n in range(k, 400)) for k in range(12)]
            got = field_codegen.stream_taylor(c1, 12)
            assert max(abs(x / y - 1) for x, y in zip(got, want)) < 1e-30
    with mpmath.workdps(60):
        c1 = pieces[-1][0]
        c = 1 - field_codegen._dyadic(c1)
        got = field_codegen.stream_taylor(c1, 5)
        want = [mpmath.diff(lambda m: ((1 - m / 2) * mpmath.ellipk(m) - mpmath.ellipe(m)) / m**2, c, k)
                / mpmath.factorial(k) for k in range(5)]
        assert max(abs(x / y - 1) for x, y in zip(got, want)) < 1e-30


def test_piece_tails_meet_the_bound():
    """The dropped tails (piece_tail) of the lowest piece of an octave (the largest w/(1 − c)) and of the top one
    (m near 0): within 2^-60 at the generated length; 16 terms would not be (so the bound sets the length)."""
    pieces = field_codegen.pieces()
    per_octave = field_codegen.PIECES_PER_OCTAVE
    assert field.STREAM_PIECE_GRID == (per_octave, field_codegen.PIECE_OCTAVES, field_codegen.PIECE_TERMS)
    for c1, w in (pieces[0], pieces[per_octave - 1], pieces[-per_octave]):
        assert field_codegen.piece_tail(c1, w) <= field_codegen.PIECE_TAIL
    assert field_codegen.piece_tail(*pieces[0], terms=16) > field_codegen.PIECE_TAIL
    assert len(field.STREAM_PIECES) == len(pieces) * (field_codegen.PIECE_TERMS + 3)


def test_generated_module_is_up_to_date(module_parts):
    title, inputs, kernels, constants, layout = module_parts
    text = module_text(title, inputs, [lower(k) for k in kernels], "codegen/field.py", constants, layout)
    assert GENERATED.read_text() == text, "generated/coil_field.py is stale: regenerate it from codegen.field"
