"""The membrane energy of a general deformed surface at one quadrature node (MODEL.md §8), for the 2D engine.

Node variables q = (x, y, z, xt, yt, zt, xp, yp, zp): the deformed point x = X + u, a_θ = ∂x/∂θ and
a_φ = (1/sin θ) ∂x/∂φ. Density per unit reference area (E per 2π = (1/2π) ∫∫ π sin θ dθ dφ):

    π = Φ(I, J) + (the terms' densities),   I = |a_θ|² + |a_φ|² = tr C,   J = |a_θ × a_φ| = λ1 λ2 = √det C,

λ3 = 1/J; for the full set of terms (codegen/terms/: ``Term.surface``) π = Φ(I, J) − ½ χ M H²(x) −
(P/3) x · (a_θ × a_φ) − Φ̄² J², with H² the Taylor proxy in (x, y, z) of terms/magnetic.py (field rows Q, Q_x, …,
Q_zz supplied by the runtime).

Φ is abstract in the derivatives: π carries the Taylor proxy
Φ + Φ_I δI + Φ_J δJ + ½(Φ_II δI² + Φ_JJ δJ²) + Φ_IJ δI δJ about (I, J) of the node, so SymPy's chain rule gives
the gradient and Hessian in q with the six numbers Φ, Φ_I, …, Φ_JJ as stage symbols, computed in an earlier
kernel stage from (I, J, D) with D = m² − J² = ((c11 − c22)/2)² + c12², m = I/2 (a sum of squares: no
cancellation, D ≥ 0; the principal stretches squared are m ± √D):

- invariant energies (``energies.energy_in_invariants``): W(I1, I2), I1 = I + J⁻², I2 = J² + I J⁻², smooth;
- Ogden terms (μ/α)(λ1^α + λ2^α + J^−α − 3) with S = λ1^α + λ2^α = (m + d)^a + (m − d)^a, a = α/2, d = √D:
  for integer a an exact polynomial in (m, D) (over J^(2|a|) for a < 0); otherwise the closed form with
  m − d = J²/(m + d) where d > SWITCH·m, else the series 2 m^a Σ_{j<SERIES_TERMS} C(a, 2j) t^j, t = D/m²
  (the closed form's D is guarded so that the unused branch never divides by zero after CSE);
- a formula Φ(λ1, λ2) in the stretches (symmetric: scene/energies.py checks it), a smooth function of
  s = λ1 + λ2 = √(I + 2J) and q = (λ1 − λ2)² = 4D/s² but not as written: the closed form Φ(√(m + d), J/√(m + d))
  where d > SWITCH·m (the same switch and guard as the Ogden terms), else the series Σ_{j<STRETCH_TERMS} c_j(s) q^j
  of Φ((s + r)/2, (s − r)/2) in r = √q, whose odd powers vanish (codegen/energies.py: stretch_series, by the
  truncated-series engine with exp, log, … expanded about their arguments' constant terms). s and q are stage
  symbols: the series is a polynomial in q with coefficients in s alone, differentiated once per pair of (s, q)
  and chained to (I, J) (``_chain_derivatives``).

Derivatives in (I, J) of a function F(I, J, D, t, s, q) with D = I²/4 − J², t = 4D/I², s = √(I + 2J), q = 4D/s² use
the total derivatives ∂_I = ∂/∂I + (I/2) ∂/∂D + 2(1 − t)/I ∂/∂t + 1/(2s) ∂/∂s + (2I − q)/s² ∂/∂q and
∂_J = ∂/∂J − 2J ∂/∂D − 8J/I² ∂/∂t + 1/s ∂/∂s − (8J + 2q)/s² ∂/∂q.

Switch (measured, see the surface-kernels report): SWITCH = 0.3 and SERIES_TERMS = 20 keep both branches of
S, S_I, …, S_JJ within ~6e-13 (closed form, cancellation ~ε (m/d)³) and ~2e-14 (series, truncation
~t^(SERIES_TERMS − 2)) of the exact value at d/m = 0.3 for a = 0.65, 0.865, −1.25. A stretch formula's series
converges faster: q/s² = ((λ1 − λ2)/(λ1 + λ2))² ≤ 0.0236 at d/m = SWITCH, and STRETCH_TERMS = 12 keeps the
kernels of neo-Hookean, Mooney–Rivlin, Gent, an exponential (Fung) energy and the SPOM1 sum written in the
stretches within 3e-14 relative (value, gradient, Hessian) of the same energies in invariants or as Ogden terms, at
d/m = 0, 1e-8, 1e-4, 0.1, 0.29, 0.3 ± 1e-7, 0.31, 0.5, 0.8 and λ2 = 0.7, 1.1, 2.5 (tests/test_surface_stretch.py);
generating such a module takes 10–70 s on one core (SymPy: series, chain rule, CSE).
"""
import functools

import sympy as sp

from . import energies, functional as fn
from .equations import pair_labels
from .kernels import Arg, Kernel
from .second_variation import cross, dot
from .terms.magnetic import SURFACE_FIELD

x, y, z, xt, yt, zt, xp, yp, zp = STATE = sp.symbols("x y z xt yt zt xp yp zp", real=True)
PAIRS = tuple((i, j) for i in range(9) for j in range(i, 9))  # upper triangle row by row

# stage symbols: the node's invariants, then Φ and its derivatives in (I, J)
inv_I, inv_J, inv_D = sp.symbols("inv_I inv_J inv_D", positive=True)
inv_t = sp.Symbol("inv_t", nonnegative=True)  # t = D/m² = (d/m)², the series variable
# a stretch formula's series: s = λ1 + λ2 = √(I + 2J) and q = (λ1 − λ2)² = 4D/s²
inv_s, inv_q = sp.Symbol("inv_s", positive=True), sp.Symbol("inv_q", nonnegative=True)
PHI = sp.symbols("phi phi_I phi_J phi_II phi_IJ phi_JJ", real=True)
_I0, _J0 = sp.symbols("I0 J0", positive=True)

# closed form where d/m > SWITCH, else SERIES_TERMS terms of the even series in d (measured: docs in report)
SWITCH = sp.Rational(3, 10)
SERIES_TERMS = 20
STRETCH_TERMS = 12  # terms of a stretch formula's series in q = (λ1 − λ2)², q/s² ≤ 0.0236 at d/m = SWITCH


def geometry():
    """(I, J², D) of the node as polynomials (J² = |a_θ × a_φ|²)."""
    a_t, a_p = STATE[3:6], STATE[6:]
    c11, c22, c12 = dot(a_t, a_t), dot(a_p, a_p), dot(a_t, a_p)
    normal = cross(a_t, a_p)
    return c11 + c22, dot(normal, normal), ((c11 - c22) / 2) ** 2 + c12**2


def density(cls: fn.SceneClass):
    """π at the node with the Φ proxy about (I0, J0) and the terms' proxies left unevaluated; the dielectric term,
    a function of J alone (smooth), is one of the terms, outside the Φ stage of the elastic energy."""
    invariant, normal_sq, _ = geometry()
    areal = sp.sqrt(normal_sq)
    dI, dJ = invariant - _I0, areal - _J0
    phi, phi_I, phi_J, phi_II, phi_IJ, phi_JJ = PHI
    pi = phi + phi_I * dI + phi_J * dJ + (phi_II * dI**2 + phi_JJ * dJ**2) / 2 + phi_IJ * dI * dJ
    return pi + sum(term.surface(STATE[:3], STATE[3:6], STATE[6:], areal) for term in cls.terms)


def at_node(cls: fn.SceneClass, expr, normal_sq, invariant):
    """Put the proxies' expansion points back (after differentiation) and name J = inv_J."""
    expansion = {_I0: invariant, _J0: sp.sqrt(normal_sq)}
    for term in cls.terms:
        expansion.update(term.surface_expansion(STATE[:3]))
    return expr.xreplace(expansion).xreplace({normal_sq: inv_J**2})


def _total(expr, wrt):
    """∂_I or ∂_J of F(I, J, D, t, s, q) with D = I²/4 − J², t = 4D/I², s = √(I + 2J), q = 4D/s² (module
    docstring): ∂_I t = 2(1 − t)/I, ∂_J t = −8J/I², ∂_I s = 1/(2s), ∂_J s = 1/s, ∂_I q = (2I − q)/s²,
    ∂_J q = −(8J + 2q)/s²."""
    if wrt == "I":
        return (sp.diff(expr, inv_I) + sp.diff(expr, inv_D) * inv_I / 2 + sp.diff(expr, inv_t) * 2 * (1 - inv_t) / inv_I
                + sp.diff(expr, inv_s) / (2 * inv_s) + sp.diff(expr, inv_q) * (2 * inv_I - inv_q) / inv_s**2)
    return (sp.diff(expr, inv_J) - 2 * inv_J * sp.diff(expr, inv_D) - sp.diff(expr, inv_t) * 8 * inv_J / inv_I**2
            + sp.diff(expr, inv_s) / inv_s - sp.diff(expr, inv_q) * (8 * inv_J + 2 * inv_q) / inv_s**2)


def _derivatives(expr) -> tuple:
    """(F, F_I, F_J, F_II, F_IJ, F_JJ)."""
    f_I, f_J = _total(expr, "I"), _total(expr, "J")
    return expr, f_I, f_J, _total(f_I, "I"), _total(f_I, "J"), _total(f_J, "J")


def _chain_derivatives(series) -> tuple:
    """(F, F_I, …, F_JJ) of F = G(s, q) by the chain rule, G differentiated once per pair of (s, q) (SymPy's
    repeated ∂_I, ∂_J of a long series would differentiate every term again per pair): F_XY = G_ss s_X s_Y +
    G_sq (s_X q_Y + s_Y q_X) + G_qq q_X q_Y + G_s s_XY + G_q q_XY."""
    G_s, G_q = sp.diff(series, inv_s), sp.diff(series, inv_q)
    G_ss, G_sq, G_qq = sp.diff(G_s, inv_s), sp.diff(G_s, inv_q), sp.diff(G_q, inv_q)
    first = {X: (_total(inv_s, X), _total(inv_q, X)) for X in "IJ"}

    def second(X, Y):
        (s_X, q_X), (s_Y, q_Y) = first[X], first[Y]
        return (G_ss * s_X * s_Y + G_sq * (s_X * q_Y + s_Y * q_X) + G_qq * q_X * q_Y + G_s * _total(s_X, Y)
                + G_q * _total(q_X, Y))

    gradient = [G_s * s_X + G_q * q_X for s_X, q_X in first.values()]
    return series, *gradient, second("I", "I"), second("I", "J"), second("J", "J")


def _stretch_power_sum(a):
    """(exact part, closed form, series) of (m + d)^a + (m − d)^a in (inv_I, inv_J, inv_D), m = I/2, d = √D:
    an integer a gives (exact, 0, 0)."""
    m, d = inv_I / 2, sp.Symbol("d", positive=True)
    if a.is_Integer:
        k = abs(int(a))
        even = sp.expand((m + d) ** k + (m - d) ** k).subs(d, sp.sqrt(inv_D))
        return (sp.expand(even) if a >= 0 else sp.expand(even) / inv_J ** (2 * k)), sp.S.Zero, sp.S.Zero
    root = sp.sqrt(inv_D)
    closed = (m + root) ** a + (inv_J**2 / (m + root)) ** a
    # 2 m^a Σ_j C(a, 2j) t^j, t = D/m²: one power of m, a polynomial in t ≤ SWITCH² (binomial(a, k) of a symbolic
    # exponent as a product, codegen/energies.py: _odd_coefficients)
    series = 2 * m**a * sum(sp.expand_func(sp.binomial(a, 2 * j)) * inv_t**j for j in range(SERIES_TERMS))
    return sp.S.Zero, closed, series


@functools.cache
def material_stage(cls: fn.SceneClass) -> tuple:
    """(Φ, Φ_I, Φ_J, Φ_II, Φ_IJ, Φ_JJ) of the elastic energy as expressions in (inv_I, inv_J, inv_D)."""
    energy = cls.elastic.energy
    if energy is not None:
        W = energies.energy_in_invariants(energy)
        if W is None:
            closed, series = _stretch_formula(energy)
            return _switched(sp.S.Zero, closed, _chain_derivatives(series))
        at = {energies.I1: inv_I + inv_J**-2, energies.I2: inv_J**2 + inv_I * inv_J**-2}
        return _derivatives(W.subs(at, simultaneous=True))
    exact, closed, series = sp.S.Zero, sp.S.Zero, sp.S.Zero
    for mu, alpha in zip(cls.elastic.moduli(), cls.elastic.exponents()):
        e, c, s = _stretch_power_sum(alpha / 2)
        exact += mu / alpha * (e + inv_J**-alpha - 3)
        closed += mu / alpha * c
        series += mu / alpha * s
    return _switched(exact, closed, _derivatives(series))


def _stretch_formula(energy) -> tuple:
    """(closed form, series) of a formula Φ(λ1, λ2) in the stretches, in (inv_I, inv_J, inv_D): the closed form at
    λ1 = √(m + d), λ2 = J/λ1 (no cancellation), the series Σ_j c_j(s) q^j (codegen/energies.py: stretch_series) at
    s = λ1 + λ2, q = (λ1 − λ2)² = 4D/s² (D without cancellation, not I − 2J), both stage symbols: the series is a
    polynomial in q with coefficients in s alone, whose derivatives stay small."""
    lam1 = sp.sqrt(inv_I / 2 + sp.sqrt(inv_D))
    closed = energies.membrane_energy(energy, lam1, inv_J / lam1)
    coefficients = energies.stretch_series(energy, inv_s, sp.Symbol("r", positive=True), STRETCH_TERMS)
    series = sum(c * inv_q**j for j, c in enumerate(coefficients))
    return closed, series


def _switched(exact, closed, series_derivatives) -> tuple:
    """(F, F_I, …, F_JJ) of exact + (closed where d/m > SWITCH, else the series, given by its derivatives); the
    closed form's D is guarded so that the unused branch never divides by zero after CSE."""
    exact_d = _derivatives(exact)
    if closed == 0:
        return exact_d
    far = inv_D > SWITCH**2 * inv_I**2 / 4
    guard = {inv_D: sp.Piecewise((inv_D, far), (inv_I**2 / 16, True))}  # d = m/2 in the series range
    closed_d = [c.xreplace(guard) for c in _derivatives(closed)]
    return tuple(e + sp.Piecewise((c, far), (s, True)) for e, c, s in zip(exact_d, closed_d, series_derivatives))


def _args(cls: fn.SceneClass) -> tuple:
    args = [Arg.node_rows("state", STATE), *map(Arg.param, fn.runtime_args(cls)), *cls.elastic.arguments()]
    return tuple(args + [arg for term in cls.terms for arg in term.surface_rows()])


def surface_kernels(cls: fn.SceneClass) -> list[Kernel]:
    """surface_energy, _gradient, _hessian and surface_WORD_gradient per continuation parameter (P, [M], [Φ̄])."""
    invariant, normal_sq, spread = geometry()
    pi = density(cls)
    gradient = [sp.diff(pi, q) for q in STATE]
    hessian = [sp.diff(gradient[i], STATE[j]) for i, j in PAIRS]
    node = lambda exprs: tuple(at_node(cls, e, normal_sq, invariant) for e in exprs)  # noqa: E731
    geometry_stage = ((inv_I, invariant), (inv_J, sp.sqrt(normal_sq)), (inv_D, spread))
    material = dict(zip(PHI, material_stage(cls)))
    # the series variables where a material needs them: t = D/m² (Ogden terms), s and q (a stretch formula)
    earlier = (geometry_stage,)
    variables = ((inv_t, 4 * inv_D / inv_I**2), (inv_s, sp.sqrt(inv_I + 2 * inv_J)),
                 (inv_q, 4 * inv_D / (inv_I + 2 * inv_J)))
    series_variables = tuple((v, e) for v, e in variables if any(m.has(v) for m in material.values()))
    if series_variables:
        earlier += (series_variables,)
    stages = lambda *names: (*earlier, tuple((p, material[p]) for p in names))  # noqa: E731
    phi, phi_I, phi_J, phi_II, phi_IJ, phi_JJ = PHI
    args = _args(cls)
    labels = tuple(map(str, STATE))
    kernels = [
        Kernel("surface_energy", "π per unit reference area at a node (MODEL.md §8; codegen/surface.py).", args,
               node([pi]), ("pi",), stages(phi)),
        Kernel("surface_gradient", "∂π/∂(x, a_θ, a_φ) at a node.", args, node(gradient), labels,
               stages(phi_I, phi_J)),
        Kernel("surface_hessian", "∂²π/∂(x, a_θ, a_φ)², upper triangle row by row (SURFACE_PAIRS).", args,
               node(hessian), pair_labels(STATE, PAIRS), stages(phi_I, phi_J, phi_II, phi_IJ, phi_JJ)),
    ]
    kernels += [Kernel(f"surface_{word}_gradient", f"∂²π/∂{shown}∂(x, a_θ, a_φ).", args,
                       node([sp.diff(g, symbol) for g in gradient]), labels)
                for symbol, word, shown in fn.continuations(cls)]
    return kernels


def layout() -> dict:
    """Row layouts of every surface module: the node variables, the Hessian pairs, the field rows."""
    return {"SURFACE_STATE": tuple(map(str, STATE)), "SURFACE_PAIRS": PAIRS,
            "SURFACE_FIELD_ROWS": tuple(map(str, SURFACE_FIELD))}
