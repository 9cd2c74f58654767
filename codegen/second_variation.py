"""Second variation of the energy for non-axisymmetric perturbations cos(mφ)/sin(mφ), m ≥ 1 (MODEL.md §5).

Derivation (docs/second_variation.md has the full account). In the local frame (e_ρ(φ), e_φ(φ), e_z) the
perturbed mid-surface is the straight line in Cartesian space

    x = (ρ0 + ε R cos mφ) e_ρ + ε T sin mφ e_φ + (η0 + ε Z cos mφ) e_z,

R = a sin θ (a: the λ2 perturbation), T the azimuthal displacement (T = ρ0 B to first order in the angle form
β = φ + ε B sin mφ), Z the axial one. With ' = d/dθ, ∂_φ e_ρ = e_φ, ∂_φ e_φ = −e_ρ:

    x_θ = (ρ0' + ε R' c, ε T' s, η0' + ε Z' c),
    x_φ = (−ε (mR + T) s, ρ0 + ε (R + mT) c, −ε m Z s),      c = cos mφ, s = sin mφ,

and C = G⁻¹g, G = diag(S'², sin²θ), in the orthonormal reference frame: c11 = |x_θ|²/S'², c22 = |x_φ|²/sin²θ,
c12 = x_θ·x_φ / (S' sin θ) (c12 = O(ε)); S' = dS/dθ of the reference meridian (codegen/meridian.py: 1 on the
sphere), which also multiplies the elastic density per d(cos θ). The principal stretches squared are the
eigenvalues e1, e2 of that matrix; with φ̂(e1, e2) = Φ(√e1, √e2) and c12 = O(ε), to second order

    Φ(Λ1, Λ2) = φ̂(c11, c22) + K c12²,      K = (φ̂_1 − φ̂_2)/(λ1² − λ2²)   (the shear coefficient),

where λ1² = c11|0, λ2² = c22|0. K has a removable singularity at λ1 = λ2; its limit is φ̂_11 − φ̂_12.
The field enters through H²(|x_h|, z) with |x_h| = ρ0 + ε R c + ε² T² s²/(2ρ0) + …, the pressure through
−P V, V = (1/3) ∮ x·(x_θ × x_φ) dθ dφ. Averaging the ε² coefficient over φ (⟨c²⟩ = ⟨s²⟩ = ½, ⟨cs⟩ = 0 for
m ≥ 1) and dividing by sin θ (integration in x = cos θ) gives E₂(θ), a quadratic form in
y = (R, R', Z, Z', T, T'); the kernel returns h = ∂²E₂/∂y², so that with E per 2π (MODEL.md §2)

    d²E/dε² = ∫_{-1}^{1} yᵀ h y d(cos θ).

Why (R, T) and a straight Cartesian line rather than (a, B) and the angle β: for m = 1 a regular perturbation
(the rigid translation, R = 1, T = −1 at the poles) has a = R/sin θ and B = T/ρ0 unbounded at the poles, and the
angle form's second-order displacement ~ T²/ρ0 is singular there, which adds a spurious pole term to the
second variation (the translation is then not a zero mode). Along the straight line d²E/dε² is the Hessian
E''[x1, x1] itself, at any state. The kernel is written per scene class; m is a runtime argument.

On a tube (codegen/meridian.py: t = S, R = 1, R' = 0, S' = 1) the same expressions hold with (cos θ, sin θ) → (R', R)
= (0, 1): ' = d/dS, and E₂ is per dS; the tube's kernel takes no node coordinate. On a capsule (θ = S/κ, R piecewise:
codegen/meridian.py) (cos θ, sin θ) → (R', R) at the node gives E₂ per dθ over R, turned into the Galerkin density
per d(cos θ) as its energy is (× R/sin θ, v → v R/sin θ: ``Meridian.on_meridian``). Its pressure term is the volume
between the end planes, ½ x_h · (x_S × x_φ) with x_h the horizontal part of x (the end planes add nothing: x_h is
parallel to them), not the cone form, whose flux through the end planes changes with the end sections' areas at
O(ε²) (codegen/terms/pressure.py).
"""
import functools

import sympy as sp
from sympy.codegen.cfunctions import expm1, log1p

from . import energies, functional as fn
from .functional import SceneClass, cos_theta, eta, lam2, sin_theta, v, w
from .equations import kernel_args, pair_labels
from .kernels import Arg, Kernel

m = sp.Symbol("m", real=True)
R, R1, Z, Z1, T, T1 = sp.symbols("R R1 Z Z1 T T1", real=True)
PERTURBATION = (R, R1, Z, Z1, T, T1)
PAIRS = tuple((i, j) for i in range(6) for j in range(i, 6))  # upper triangle row by row

eps, _c, _s = sp.symbols("epsilon cm sm", real=True)
_l2 = sp.Symbol("l2", positive=True)
_h = sp.Symbol("h", real=True)
# material stage symbols: φ̂ derivatives in e = λ² and the shear coefficient, at (λ1, λ2) of the state
p1, p2, p11, p12, p22, shear = sp.symbols("p1 p2 p11 p12 p22 K", real=True)
l1 = sp.Symbol("lam1", positive=True)

# removable-singularity switch: closed form when |λ1 − λ2| > SWITCH·λ2, else Taylor in h = λ1/λ2 − 1 of this order
SWITCH = sp.Rational(1, 100)
TAYLOR_ORDER = 8


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def surface():
    """(x, x_θ, x_φ) in the local frame (e_ρ, e_φ, e_z), polynomial in ε, cm, sm (see module docstring)."""
    rho0, drho0 = lam2 * sin_theta, lam2 * cos_theta + v
    x = (rho0 + eps * R * _c, eps * T * _s, eta + eps * Z * _c)
    x_t = (drho0 + eps * R1 * _c, eps * T1 * _s, w + eps * Z1 * _c)
    x_p = (-eps * (m * R + T) * _s, rho0 + eps * (R + m * T) * _c, -eps * m * Z * _s)
    return x, x_t, x_p


def epsilon_order(expr, k):
    """Coefficient of ε^k."""
    return sp.expand(expr).coeff(eps, k)


def phi_average(expr):
    """(1/2π)∫ dφ of a polynomial in cm = cos mφ, sm = sin mφ of degree ≤ 2 (m ≥ 1)."""
    poly = sp.Poly(sp.expand(expr), _c, _s)
    mean = {(0, 0): sp.S.One, (2, 0): sp.S.Half, (0, 2): sp.S.Half, (1, 0): 0, (0, 1): 0, (1, 1): 0}
    out = sp.S.Zero
    for (i, j), coeff in poly.terms():
        if (i, j) not in mean:
            raise ValueError(f"unexpected φ dependence cm^{i} sm^{j}")
        out += coeff * mean[(i, j)]
    return sp.expand(out)


def second_order_density(cls: SceneClass):
    """E₂: the φ-averaged ε² coefficient of the energy per d(cos θ), per 2π, in the stage symbols
    (λ1 = lam1, p1, p2, p11, p12, p22, K) and the node/state/field symbols; quadratic in PERTURBATION. The
    material stage carries Φ (every term of the stretches); the other terms add their own (``Term.second_order``)."""
    x, x_t, x_p = surface()
    meridian = cls.meridian
    metric = meridian.metric(cos_theta, sin_theta)
    c11 = dot(x_t, x_t) / metric**2
    c22 = dot(x_p, x_p) / sin_theta**2
    c12 = dot(x_t, x_p) / (sin_theta * metric)
    a1, a2 = epsilon_order(c11, 1), epsilon_order(c22, 1)
    elastic = p1 * epsilon_order(c11, 2) + p2 * epsilon_order(c22, 2)
    elastic += p11 * a1**2 / 2 + p12 * a1 * a2 + p22 * a2**2 / 2
    elastic += shear * epsilon_order(c12, 1) ** 2
    density = phi_average(elastic) * metric
    density += sum(term.second_order(x, x_t, x_p, metric, meridian.poles) for term in cls.terms)
    # a tube, a capsule: the node's (cos θ, sin θ) are their (R', R) (module docstring)
    return meridian.on_meridian(density)


@functools.cache
def material_stage(cls: SceneClass):
    """(p1, p2, p11, p12, p22) = derivatives of φ̂(e1, e2) = Φ(√e1, √e2) at (λ1², λ2²), as functions of (λ1, λ2)."""
    e1, e2 = sp.symbols("e1 e2", positive=True)
    phi = fn.membrane_energy(cls, sp.sqrt(e1), sp.sqrt(e2))
    at = {e1: l1**2, e2: _l2**2}  # positive λ2 while deriving (no |λ2|), the state's lam2 afterwards
    d = lambda *xs: sp.diff(phi, *xs).subs(at).subs(_l2, lam2)  # noqa: E731
    return d(e1), d(e2), d(e1, e1), d(e1, e2), d(e2, e2)


def _divided_difference_terms(cls: SceneClass, a, b):
    """K(λ1 = a, λ2 = b) term by term: (μ/2)[(e1^p − e2^p)/(e1 − e2) + (e1 e2)^(−α/2−1)], p = α/2 − 1.

    Returns (regular part, list of (μ, p) for the divided differences that are not polynomial)."""
    e1, e2 = a**2, b**2
    regular, singular = sp.S.Zero, []
    for mu, alpha in zip(cls.elastic.moduli(), cls.elastic.exponents()):
        p = alpha / 2 - 1
        regular += mu / 2 * (e1 * e2) ** (-alpha / 2 - 1)
        if p.is_Integer:  # (e1^p − e2^p)/(e1 − e2) is a polynomial in e1, e2, 1/e1, 1/e2: regular form
            regular += mu / 2 * sp.cancel((e1**p - e2**p) / (e1 - e2))
        else:
            singular.append((mu, p))
    return regular, singular


@functools.cache
def shear_coefficient(cls: SceneClass):
    """K(λ1, λ2) in a form finite at λ1 = λ2: (expression in lam1, lam2 with a Piecewise switch, its limit at
    λ1 = λ2, the plain closed form (φ̂_1 − φ̂_2)/(λ1² − λ2²)).

    Per Ogden term K = (μ/2)[(e1^p − e2^p)/(e1 − e2) + (e1 e2)^(−α/2−1)], e = λ², p = α/2 − 1. Where p is an
    integer the divided difference is cancelled exactly (a polynomial in e1^±1, e2^±1: regular). Otherwise: the
    Taylor series in h = λ1/λ2 − 1 (order TAYLOR_ORDER, truncation ~|h|^9) where |λ1 − λ2| ≤ SWITCH·λ2, and the
    expm1/log1p form (no cancellation) elsewhere."""
    p1_, p2_, p11_, p12_, _ = material_stage(cls)
    closed = (p1_ - p2_) / (l1**2 - lam2**2)
    # the other terms of the stretches add their divided differences, cancelled exactly (the dielectric −Φ̄² e1 e2:
    # the constant Φ̄²)
    others = sum(_divided_difference(term) for term in cls.terms)
    if cls.elastic.energy is not None:
        expr, limit = energies.shear_coefficient(cls.elastic.energy, l1, lam2)
        return expr + others, limit + others, closed
    limit = sp.simplify((p11_ - p12_).subs(l1, lam2))
    regular, singular = _divided_difference_terms(cls, l1, _l2)
    regular = regular.subs(_l2, lam2) + others
    if not singular:
        return regular, limit, closed
    far = sp.Abs(l1 - lam2) > SWITCH * lam2
    # closed form without cancellation: (e1^p − e2^p)/(e1 − e2) = e2^(p−1) expm1(p L)/expm1(L), L = 2 log1p(h),
    # h = (λ1 − λ2)/λ2 (exact difference); h is guarded (= 1 in the Taylor range) so that no branch divides by 0
    h_far = sp.Piecewise(((l1 - lam2) / lam2, far), (1, True))
    L = 2 * log1p(h_far)
    closed_part = sum(mu / 2 * lam2 ** (2 * p - 2) * expm1(p * L) / expm1(L) for mu, p in singular)
    # Taylor of (e1^p − e2^p)/(e1 − e2) with e1 = e2 (1+h)²: e2^(p−1) ((1+h)^(2p) − 1)/((1+h)² − 1)
    taylor_part = sp.S.Zero
    for mu, p in singular:
        g = ((1 + _h) ** (2 * p) - 1) / (_h * (2 + _h))
        series = sp.series(g, _h, 0, TAYLOR_ORDER + 1).removeO()
        taylor_part += mu / 2 * lam2 ** (2 * p - 2) * series
    taylor_part = taylor_part.subs(_h, l1 / lam2 - 1)
    expr = regular + sp.Piecewise((closed_part, far), (taylor_part, True))
    return expr, limit, closed


def _divided_difference(term):
    """(φ̂_1 − φ̂_2)/(e1 − e2) of a term's part of Φ, φ̂(e1, e2) = Φ(√e1, √e2), cancelled (a term smooth at e1 = e2)."""
    e1, e2 = sp.symbols("e1 e2", positive=True)
    phi = term.membrane(sp.sqrt(e1), sp.sqrt(e2))
    return sp.cancel((sp.diff(phi, e1) - sp.diff(phi, e2)) / (e1 - e2))


def _kernel_args(cls: SceneClass):
    return kernel_args(cls, (*cls.meridian.node_symbols, lam2, v, eta, w), leading_params=(m,))


def azimuthal_hessian_kernel(cls: SceneClass) -> Kernel:
    density = second_order_density(cls)
    outputs = tuple(sp.diff(density, PERTURBATION[i], PERTURBATION[j]) for i, j in PAIRS)
    material = material_stage(cls)
    stages = (
        ((l1, fn.meridional_stretch(cls.meridian.hoop_rate(cos_theta, sin_theta),
                                    cls.meridian.rate(cos_theta, sin_theta), w)
          / cls.meridian.metric(cos_theta, sin_theta)),),
        tuple(zip((p1, p2, p11, p12, p22), material)) + ((shear, shear_coefficient(cls)[0]),),
    )
    return Kernel(
        "azimuthal_hessian",
        "Second variation for perturbations cos(mφ), m ≥ 1 (MODEL.md §5): the 6×6 matrix h with "
        "d²E/dε² = ∫ yᵀ h y d(cos θ), y = (R, R', Z, Z', T, T'), R, Z the radial/axial displacement amplitudes "
        "(cos mφ), T the azimuthal one (sin mφ); upper triangle row by row (codegen/second_variation.py).",
        _kernel_args(cls),
        outputs,
        pair_labels(PERTURBATION, PAIRS),
        stages,
    )


def shear_kernel(cls: SceneClass) -> Kernel:
    """K(λ1, λ2) of the class; its runtime scalars are those it depends on (the dielectric voltage)."""
    coefficient = shear_coefficient(cls)[0]
    parameters = [p for p in fn.runtime_args(cls) if coefficient.has(p)]
    return Kernel(
        "shear_coefficient",
        "K = (φ̂_1 − φ̂_2)/(λ1² − λ2²), φ̂(e1, e2) = Φ(√e1, √e2), finite at λ1 = λ2 (limit φ̂_11 − φ̂_12).",
        (Arg.node(l1), Arg.node(lam2), *map(Arg.param, parameters), *cls.elastic.arguments()),
        (coefficient,),
        ("K",),
    )


def second_variation_kernels(cls: SceneClass) -> list[Kernel]:
    return [azimuthal_hessian_kernel(cls), shear_kernel(cls)]
