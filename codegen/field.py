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
  from a few-ulp E); in the (K, N) basis at most 26-fold for m ≥ 1/2, the branch this kernel serves.
- ``STREAM_SERIES``: Maclaurin coefficients of G from K = π/2 ₂F₁(½,½;1;m), E = π/2 ₂F₁(−½,½;1;m).
"""
import sympy as sp

from .kernels import Arg, Kernel

STREAM_CONSTANT = 32
SERIES_TERMS = 70

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


def stream_series(terms=SERIES_TERMS):
    """Exact Maclaurin coefficients g_n/π of G(m) = π Σ g_n m^n (g_0 = 1/32)."""
    half = sp.Rational(1, 2)
    k = [sp.rf(half, n) ** 2 / sp.factorial(n) ** 2 for n in range(terms + 2)]
    e = [sp.rf(-half, n) * sp.rf(half, n) / sp.factorial(n) ** 2 for n in range(terms + 2)]
    # (1 − m/2) K − E = π/2 Σ_n (k_n − e_n − k_{n−1}/2) m^n; the n = 0, 1 terms vanish.
    return tuple((k[n] - e[n] - k[n - 1] / 2) / 2 for n in range(2, terms + 2))


def field_module():
    """(title, inputs, kernels, constants) for ``generated/coil_field.py``."""
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
    constants = {"STREAM_SERIES": tuple(float(sp.N(sp.pi * g, 40)) for g in stream_series())}
    inputs = {
        "stream_function": f"psi = {STREAM_CONSTANT} a^2 rho^2 G(m) / S^3, m = 4 a rho / S^2",
        "series_terms": SERIES_TERMS,
    }
    title = "Applied field of one coaxial current loop: stream-function field, derivatives and G(m) (MODEL.md §3)."
    return title, inputs, [coil_field, stream_shape_closed], constants
