"""Pole limits of the Euler–Lagrange equations by truncated Taylor series (MODEL.md §4).

At a smooth pole λ2 and η are even in the distance t from it: λ2 = c0 + c2 t² + …, η = e0 + e2 t² + …,
so v = O(t²), w = O(t), and f = (v/s, F1, w, F2) is 0/0 there. Substituting the series into the
Euler–Lagrange equations (in the singularity-free Lagrangian form d/dθ L_p = L_λ2, d/dθ L_q = L_η with
p = λ2', q = η') and expanding in t, the lowest non-trivial orders are linear in (c2, e2):

    O(t)  of the η equation  ->  e2,        O(t³) of the λ2 equation  ->  c2.

The energy enters through the derivatives φ_ij = ∂^{i+j}Φ/∂λ1^i∂λ2^j at λ1 = λ2 = c0 and the other terms
through their pole Lagrangians (``Term.pole``: the pressure, the field's H²_η and H²_ρρ on the axis), so the
series is derived once for an abstract symmetric Φ and every known term (``classes.KNOWN_TERMS``, plus any other
term of the class), and specialised per class by differentiating the class's Φ and switching the absent terms
off (``Term.off``; deriving without them would print the same limits differently). The limits of f at the
pole follow: λ2' = v' = η' = 0 and w' = ±2 e2 (in θ; the sign is + at θ = 0 and, since d/dθ = −d/dt there, the
Taylor start at θ = π − t is λ2 = c0 + c2 t², v = −2 c2 t sin t, η = e0 + e2 t², w = −2 e2 t).
"""
import functools

import sympy as sp

from . import functional as fn
from .classes import KNOWN_TERMS
from .equations import kernel_args
from .functional import SceneClass
from .kernels import Kernel
from .meridian import SPHERE, Meridian
from .series import derivative, truncated_series

c0, c2, e0, e2 = sp.symbols("c0 c2 e0 e2", positive=True)
_t = sp.Symbol("t", positive=True)
_TAYLOR_ORDER = 3


def _phi_symbol(i, j):
    i, j = sorted((i, j))
    return sp.Symbol(f"phi{i}{j}")


def _abstract_energy(l1, l2):
    """Symmetric Taylor polynomial of Φ about (c0, c0)."""
    return sum(
        _phi_symbol(i, j) * (l1 - c0) ** i * (l2 - c0) ** j / (sp.factorial(i) * sp.factorial(j))
        for i in range(_TAYLOR_ORDER + 1)
        for j in range(_TAYLOR_ORDER + 1 - i)
    )


@functools.cache
def pole_coefficients(pole: str, terms: tuple = KNOWN_TERMS, meridian: Meridian = SPHERE):
    """(c2, e2) at the 'north' (θ = t) or 'south' (θ = π − t) pole, for abstract Φ and the pole Lagrangians of
    ``terms``, on the reference ``meridian`` (λ1 = |x'|/S', Φ per reference area: Φ S' sin θ)."""
    lam, p, z, q = sp.symbols("lam p z q", real=True)
    sign = 1 if pole == "north" else -1
    s, c = sp.sin(_t), sign * sp.cos(_t)
    metric = meridian.metric(c, s)
    l1 = sp.sqrt((lam * c + p * s) ** 2 + q**2) / metric
    L = _abstract_energy(l1, lam) * s * metric + sum(term.pole(lam, z, q, s, e0, metric) for term in terms)
    lam_t = [c0, 0, c2]
    eta_t = [e0, 0, e2]
    known = {lam: lam_t, z: eta_t, p: [sign * x for x in derivative(lam_t)], q: [sign * x for x in derivative(eta_t)]}

    def euler_lagrange(momentum_var, state_var, order):
        momentum = truncated_series(sp.diff(L, momentum_var), _t, known, order + 1)
        force = truncated_series(sp.diff(L, state_var), _t, known, order)
        return [sp.expand(sign * dm - f) for dm, f in zip(derivative(momentum), force)]

    el_eta = euler_lagrange(q, z, 1)
    el_lam = euler_lagrange(p, lam, 3)
    e2_value = sp.solve(el_eta[1], e2)[0]
    c2_value = sp.solve(el_lam[3].subs(e2, e2_value), c2)[0]
    return sp.simplify(c2_value), sp.simplify(e2_value), el_eta, el_lam


def pole_kernel(cls: SceneClass) -> Kernel:
    """``pole_series(lam0, P, [M, chi], [voltage], mu, [alpha], [pole_field]) -> (c2_N, e2_N, c2_S, e2_S)``, the
    terms' pole arguments last (the field's pole_field = (Q_z_N, Q_rr_N, Q_z_S, Q_rr_S): H²_z and H²_ρρ on the
    axis at each pole, rows 'NAME_N' / 'NAME_S' of FIELD)."""
    l1, l2 = sp.symbols("l1 l2", positive=True)
    energy = fn.membrane_energy(cls, l1, l2)
    lam0 = sp.Symbol("lam0", positive=True)
    derived = KNOWN_TERMS + tuple(t for t in cls.terms if t not in KNOWN_TERMS)
    off = {}
    for term in derived:
        if term not in cls.terms:
            off.update(term.off())
    phis = {_phi_symbol(i, j): sp.diff(energy, l1, i, l2, j).subs({l1: lam0, l2: lam0})
            for i in range(_TAYLOR_ORDER + 1) for j in range(_TAYLOR_ORDER + 1 - i)}  # the same at both poles
    outputs = []
    for pole in ("north", "south"):
        c2_value, e2_value, _, _ = pole_coefficients(pole, derived, cls.meridian)
        subs = {**phis, c0: lam0}
        for term in cls.terms:
            subs.update(term.pole_values(pole[0].upper()))
        outputs += [c2_value.subs(subs).subs(off), e2_value.subs(subs).subs(off)]
    args = kernel_args(cls, (lam0,), rows=lambda term: term.pole_rows())
    return Kernel(
        "pole_series",
        "Taylor coefficients (c2, e2) of λ2 = λ0 + c2 t², η = η0 + e2 t² at the north and south poles.",
        args,
        tuple(outputs),
        ("c2_N", "e2_N", "c2_S", "e2_S"),
        vectorise=False,
    )
