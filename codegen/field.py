"""Applied field of one coaxial current loop from its Stokes stream function (MODEL.md §3).

Units: lengths in R0, field per unit signed current with the factor I/(4π R0) removed, so that the loop of
radius a at height h gives H = 2π/a at its centre. With ζ = z − h,

    S² = (a + ρ)² + ζ²,   m = 4aρ/S²,   ψ(ρ, ζ) = 32 a² ρ² G(m) / S³,
    h_ρ = −(1/ρ) ∂ψ/∂ζ,   h_z = (1/ρ) ∂ψ/∂ρ,
    G(m) = ((1 − m/2) K(m) − E(m)) / m²  (K, E complete elliptic integrals of parameter m),

which is the textbook A_φ = (μI/π k) √(a/ρ) [(1 − k²/2) K − E], ψ = ρ A_φ, rescaled. G is analytic at m = 0
(G(0) = π/32), so ψ = ρ² × smooth and the 1/ρ cancels symbolically: writing F = G(m)/S³,
h_ρ = −32a² ρ F_ζ and h_z = 32a² (2F + ρ F_ρ). Differentiating with 1/S and 1/S² as stage symbols leaves
every output a polynomial in ρ, ζ, a, 1/S, 1/S², G0..G3: no division by ρ anywhere (exact on the axis).

Kernels:
- ``coil_field(rho, zeta, a, G0, G1, G2, G3)``: h_ρ, h_z and their first and second (ρ, ζ) derivatives,
  with G0..G3 = G, G', G'', G''' at m supplied by the runtime.
- ``stream_shape_closed(m, m1, K, N)``: G, G', G'', G''' in closed form. SymPy differentiates elliptic_k and
  elliptic_e; then E = (1 − m/2) K − N, with N = (1 − m/2) K − E supplied cancellation-free by the AGM
  (balloon_cg.model.elliptic.loop_elliptic), and every factor m − 1 becomes −m1, m1 = 1 − m also supplied exactly
  (m → 1 near a wire). In the (K, E) basis the numerator of G''' cancels ~850-fold at m = 1/2 (~2e-12 error
  from a few-ulp E); in the (K, N) basis at most 26-fold for m ≥ 1/2, the branch this kernel serves near a wire.
- ``STREAM_PIECES``: Taylor coefficients a_k = G^(k)(c)/k! of G about the centre c of each piece of
  2^-PIECE_OCTAVES ≤ m1 = 1 − m ≤ 1: octave o (2^-(o+1) ≤ m1 ≤ 2^-o) cut into PIECES_PER_OCTAVE equal pieces,
  centre c1 = 1 − c and half-width w, listed by (o, i), PIECE_TERMS + 3 coefficients each (each derivative
  G^(j), j ≤ 3, summed to PIECE_TERMS terms); ``STREAM_PIECE_CENTRES`` the c1, exact dyadic numbers.
  G = π/32 ₂F₁(3/2, 3/2; 3; m) is analytic but at m = 1, so about c the terms fall like (w/(1 − c))^k
  ≤ (2·PIECES_PER_OCTAVE + 1)^-k in every octave alike; the dropped tail of each G^(j) on its piece is at most
  PIECE_TAIL of min G^(j) there (``piece_tail``).
"""
import mpmath
import sympy as sp

from .kernels import Arg, Kernel

STREAM_CONSTANT = 32
PIECES_PER_OCTAVE = 8
PIECE_OCTAVES = 12  # pieces cover 2^-12 ≤ m1 ≤ 1 (m ≤ 0.99976); the AGM closer to a wire
PIECE_TERMS = 20  # terms per derivative: 17 meet PIECE_TAIL; a multiple of 4 for the runtime's four Horner chains
PIECE_TAIL = mpmath.mpf(2) ** -60
_TAIL_TERMS = 60  # terms of the dropped tail summed (beyond them < 17^-60 of the first dropped one)
_DIGITS = 40

rho, zeta = sp.symbols("rho zeta", real=True)
a = sp.Symbol("a", positive=True)
m, m1, K, N = sp.symbols("m m1 K N", positive=True)
G = sp.symbols("G0:4", real=True)
inv_s2, inv_s = sp.symbols("inv_s2 inv_s", positive=True)  # 1/S², 1/S: kernel stages
_half_ds2 = {rho: a + rho, zeta: zeta}  # ½ ∂(S²)/∂var

FIELD_NAMES = (
    "h_rho", "h_z",
    "h_rho_r", "h_rho_z", "h_z_r", "h_z_z",
    "h_rho_rr", "h_rho_rz", "h_rho_zz", "h_z_rr", "h_z_rz", "h_z_zz",
)  # fmt: skip


def _d(expr, var):
    """Total ρ- or ζ-derivative of an expression in (ρ, ζ, a, 1/S², 1/S, G0..G3), with dG_k = G_{k+1} dm."""
    m_expr = 4 * a * rho * inv_s2
    chain = {inv_s2: -2 * _half_ds2[var] * inv_s2**2, inv_s: -_half_ds2[var] * inv_s2 * inv_s}
    m_var = sp.diff(m_expr, var) + sp.diff(m_expr, inv_s2) * chain[inv_s2]
    total = sp.diff(expr, var) + sum(sp.diff(expr, s) * ds for s, ds in chain.items())
    return sp.expand(total + sum(sp.diff(expr, G[k]) * G[k + 1] * m_var for k in range(3)))


def field_expressions():
    """The 12 per-unit-current numbers of FIELD_NAMES: polynomials in ρ, ζ, a, 1/S, 1/S², G0..G3 (no 1/ρ)."""
    shape = G[0] * inv_s * inv_s2  # F = G(m)/S³
    c = STREAM_CONSTANT * a**2
    h_rho = -c * rho * _d(shape, zeta)
    h_z = c * (2 * shape + rho * _d(shape, rho))
    first = [_d(h, v) for h in (h_rho, h_z) for v in (rho, zeta)]
    second = [_d(_d(h, u), v) for h in (h_rho, h_z) for u, v in ((rho, rho), (rho, zeta), (zeta, zeta))]
    return tuple(sp.collect(sp.expand(e), G, sp.factor) for e in [h_rho, h_z, *first, *second])


def stream_shape_expressions():
    """G, G', G'', G''' from m, m1 = 1 − m, K(m) and N = (1 − m/2) K − E: numerator collected on K, N over a
    factored denominator, each factor m − 1 written −m1."""
    g = ((1 - m / 2) * sp.elliptic_k(m) - sp.elliptic_e(m)) / m**2
    elliptic = {sp.elliptic_k(m): K, sp.elliptic_e(m): (1 - m / 2) * K - N}
    complement = {m - 1: -m1, 1 - m: m1}
    out = []
    for _ in range(4):
        numerator, denominator = sp.fraction(sp.together(g.subs(elliptic)))
        expr = sp.collect(sp.expand(numerator), [K, N], sp.factor) / sp.factor(denominator)
        out.append(expr.replace(lambda e: e in complement, lambda e: complement[e]))
        g = sp.diff(g, m)
    return tuple(out)


def pieces():
    """(c1, w) of every piece, by octave o and index i: c1 = 2^-(o+1) (1 + (i + ½)/P), w = 2^-(o+1)/(2P)."""
    out = []
    for octave in range(PIECE_OCTAVES):
        low = sp.Rational(1, 2 ** (octave + 1))
        out += [(low * (1 + sp.Rational(2 * i + 1, 2 * PIECES_PER_OCTAVE)), low / (2 * PIECES_PER_OCTAVE))
                for i in range(PIECES_PER_OCTAVE)]
    return out


def _dyadic(x):
    """The rational x = p/2^n as an mpf (exact)."""
    return mpmath.mpf(x.p) / x.q


def stream_taylor(c1, terms):
    """a_k = G^(k)(c)/k!, k < terms, c = 1 − c1 (mpf, working precision _DIGITS), from the hypergeometric
    equation of G = π/32 ₂F₁(3/2, 3/2; 3; m): m(1 − m) G'' + (3 − 4m) G' − 9/4 G = 0 at m = c + t gives
    a_{k+2} = ((k + 3/2)² a_k − ((1 − 2c) k + 3 − 4c)(k + 1) a_{k+1}) / (c(1 − c)(k + 1)(k + 2)),
    from a_0, a_1 by ₂F₁ (G' = 3π/128 ₂F₁(5/2, 5/2; 4; m)). G is the dominant solution about c > 1/2; below,
    the recurrence amplifies the other one by up to ((1 − c)/c)^k, so it runs with that many more digits."""
    c1 = _dyadic(c1)
    c = 1 - c1
    growth = max(0.0, float(mpmath.log10(c1 / c)))
    with mpmath.workdps(_DIGITS + int(terms * growth) + 10):
        q, p, r = c * c1, 1 - 2 * c, 3 - 4 * c
        a = [mpmath.pi / 32 * mpmath.hyp2f1(1.5, 1.5, 3, c), 3 * mpmath.pi / 128 * mpmath.hyp2f1(2.5, 2.5, 4, c)]
        for k in range(terms - 2):
            a.append(((k + 1.5) ** 2 * a[k] - (p * k + r) * (k + 1) * a[k + 1]) / (q * (k + 1) * (k + 2)))
    with mpmath.workdps(_DIGITS):
        return [+x for x in a[:terms]]


def piece_tail(c1, w, terms=PIECE_TERMS):
    """max over j ≤ 3 of the dropped tail Σ_{k ≥ terms} a_{k+j} (k + j)!/k! w^k of G^(j) about the piece's centre,
    relative to min G^(j) on the piece, G^(j)(c − w) (every a_k > 0, so G^(j) grows with m)."""
    a = stream_taylor(c1, terms + _TAIL_TERMS + 3)
    w = _dyadic(w)
    worst = mpmath.mpf(0)
    with mpmath.workdps(_DIGITS):
        for j in range(4):
            row = [a[k + j] * mpmath.ff(k + j, j) for k in range(terms + _TAIL_TERMS)]
            low = mpmath.fsum(x * (-w) ** k for k, x in enumerate(row))
            worst = max(worst, mpmath.fsum(x * w**k for k, x in enumerate(row) if k >= terms) / low)
    return worst


def stream_pieces():
    """STREAM_PIECE_CENTRES and STREAM_PIECES (module docstring); ValueError unless every piece's tail is within
    PIECE_TAIL at PIECE_TERMS terms."""
    centres, coefficients = [], []
    for c1, w in pieces():
        tail = piece_tail(c1, w)
        if not tail <= PIECE_TAIL:
            raise ValueError(f"piece at 1 - m = {c1}: tail {mpmath.nstr(tail, 3)} > 2^-60 with {PIECE_TERMS} terms")
        centres.append(float(c1))
        coefficients += [float(x) for x in stream_taylor(c1, PIECE_TERMS + 3)]
    return tuple(centres), tuple(coefficients)


def field_module():
    """(title, inputs, kernels, constants, layout) for ``generated/coil_field.py``."""
    coil_field = Kernel(
        name="coil_field",
        doc="Per-unit-current field of the loop of radius a at (rho, zeta = z - h), G0..G3 = G^(k)(m): "
        + ", ".join(FIELD_NAMES)
        + ".",
        args=tuple(Arg.node(s) for s in (rho, zeta, a, *G)),
        outputs=field_expressions(),
        labels=FIELD_NAMES,
        stages=(((inv_s2, 1 / ((a + rho) ** 2 + zeta**2)),), ((inv_s, sp.sqrt(inv_s2)),)),
        vectorise=False,
    )
    stream_shape_closed = Kernel(
        name="stream_shape_closed",
        doc="G, G', G'', G''' of G(m) = ((1 - m/2) K - E)/m^2 from m, m1 = 1 - m, K(m), N = (1 - m/2) K - E "
        "(for m > 1/2).",
        args=tuple(Arg.node(s) for s in (m, m1, K, N)),
        outputs=stream_shape_expressions(),
        labels=tuple(map(str, G)),
        vectorise=False,
    )
    centres, coefficients = stream_pieces()
    constants = {"STREAM_PIECE_CENTRES": centres, "STREAM_PIECES": coefficients}
    layout = {"STREAM_PIECE_GRID": (PIECES_PER_OCTAVE, PIECE_OCTAVES, PIECE_TERMS)}  # per octave, octaves, terms
    inputs = {
        "stream_function": f"psi = {STREAM_CONSTANT} a^2 rho^2 G(m) / S^3, m = 4 a rho / S^2",
        "stream_pieces": f"{PIECES_PER_OCTAVE} per octave of 1 - m, {PIECE_OCTAVES} octaves, {PIECE_TERMS} terms, "
        "tail 2^-60",
    }
    title = "Applied field of one coaxial current loop: stream-function field, derivatives and G(m) (MODEL.md §3)."
    return title, inputs, [coil_field, stream_shape_closed], constants, layout
