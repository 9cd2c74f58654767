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
- a formula in the stretches: not supported yet (NotImplementedError).

Derivatives in (I, J) of a function F(I, J, D, t) with D = I²/4 − J², t = 4D/I² use the total derivatives
∂_I = ∂/∂I + (I/2) ∂/∂D + 2(1 − t)/I ∂/∂t and ∂_J = ∂/∂J − 2J ∂/∂D − 8J/I² ∂/∂t.

Switch (measured, see the surface-kernels report): SWITCH = 0.3 and SERIES_TERMS = 20 keep both branches of
S, S_I, …, S_JJ within ~6e-13 (closed form, cancellation ~ε (m/d)³) and ~2e-14 (series, truncation
~t^(SERIES_TERMS − 2)) of the exact value at d/m = 0.3 for a = 0.65, 0.865, −1.25.
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
PHI = sp.symbols("phi phi_I phi_J phi_II phi_IJ phi_JJ", real=True)
_I0, _J0 = sp.symbols("I0 J0", positive=True)

# closed form where d/m > SWITCH, else SERIES_TERMS terms of the even series in d (measured: docs in report)
SWITCH = sp.Rational(3, 10)
SERIES_TERMS = 20


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
    return expr.subs(expansion).xreplace({normal_sq: inv_J**2})


def _total(expr, wrt):
    """∂_I or ∂_J of F(I, J, D, t) with D = I²/4 − J², t = 4D/I² (module docstring): ∂_I t = 2(1 − t)/I,
    ∂_J t = −8J/I²."""
    if wrt == "I":
        return sp.diff(expr, inv_I) + sp.diff(expr, inv_D) * inv_I / 2 + sp.diff(expr, inv_t) * 2 * (1 - inv_t) / inv_I
    return sp.diff(expr, inv_J) - 2 * inv_J * sp.diff(expr, inv_D) - sp.diff(expr, inv_t) * 8 * inv_J / inv_I**2


def _derivatives(expr) -> tuple:
    """(F, F_I, F_J, F_II, F_IJ, F_JJ)."""
    f_I, f_J = _total(expr, "I"), _total(expr, "J")
    return expr, f_I, f_J, _total(f_I, "I"), _total(f_I, "J"), _total(f_J, "J")


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
            raise NotImplementedError(
                f"surface kernels for the strain energy {energy[0]!r}: a formula in the stretches needs the "
                "even-in-d series of φ̂(m ± d), not implemented yet; write it in I1, I2 if it is invariant-based")
        at = {energies.I1: inv_I + inv_J**-2, energies.I2: inv_J**2 + inv_I * inv_J**-2}
        return _derivatives(W.subs(at, simultaneous=True))
    exact, closed, series = sp.S.Zero, sp.S.Zero, sp.S.Zero
    for mu, alpha in zip(cls.elastic.moduli(), cls.elastic.exponents()):
        e, c, s = _stretch_power_sum(alpha / 2)
        exact += mu / alpha * (e + inv_J**-alpha - 3)
        closed += mu / alpha * c
        series += mu / alpha * s
    exact_d = _derivatives(exact)
    if closed == 0:
        return exact_d
    far = inv_D > SWITCH**2 * inv_I**2 / 4
    guard = {inv_D: sp.Piecewise((inv_D, far), (inv_I**2 / 16, True))}  # d = m/2 in the series range
    closed_d = [c.xreplace(guard) for c in _derivatives(closed)]
    return tuple(e + sp.Piecewise((c, far), (s, True)) for e, c, s in zip(exact_d, closed_d, _derivatives(series)))


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
    # the series variable t = D/m² where an Ogden term needs it
    earlier = (geometry_stage,)
    if any(e.has(inv_t) for e in material.values()):
        earlier += (((inv_t, 4 * inv_D / inv_I**2),),)
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
