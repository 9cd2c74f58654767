"""Non-Ogden strain energies as SymPy expressions, from the checked formula tree of ``scene/formula.py``.

The formula text is never given to ``sympify``: the runtime's whitelist parser checks it and ``formula.fold``
maps each checked node to a SymPy constructor. Parameters become symbols ``par_NAME`` (rows of the kernels'
``material`` argument), floats become exact decimal rationals (as the Ogden classes' exponents).

The shear coefficient K = (φ̂_1 − φ̂_2)/(e1 − e2) of the m ≥ 1 second variation (codegen/second_variation.py,
φ̂(e1, e2) = Φ(√e1, √e2)) is regular in closed form for an energy W(I1, I2):

    K = W_1/(e1 e2)² + W_2 ((e1 + e2)/(e1 e2)² − 1),

since (∂I1/∂e1 − ∂I1/∂e2)/(e1 − e2) = 1/(e1e2)² and (∂I2/∂e1 − ∂I2/∂e2)/(e1 − e2) = (e1 + e2)/(e1e2)² − 1.
A formula in the stretches gets the closed form away from λ1 = λ2 and, where |λ1 − λ2| ≤ SWITCH·λ2, the even
Taylor series of K in d = (e1 − e2)/2 about the mean m = (e1 + e2)/2 (K(m + d, m − d) is even in d by the
symmetry of φ̂), to order d^(2·SERIES_TERMS − 2). ``stretch_series``: the even series of Φ((s + r)/2, (s − r)/2)
in r = λ1 − λ2, for the whole-sphere kernels of a formula in the stretches (codegen/surface.py).
"""
import functools

import sympy as sp

from balloon_cg.scene.formula import SYMBOLS, domain_conditions, fold, parse_formula

from .series import truncated_series

I1, I2 = sp.symbols("I1 I2", positive=True)
SWITCH = sp.Rational(1, 100)
SERIES_TERMS = 4

_FUNCTIONS = {"exp": sp.exp, "log": sp.log, "sqrt": sp.sqrt, "sinh": sp.sinh, "cosh": sp.cosh, "tanh": sp.tanh,
              "atan": sp.atan}
_BINARY = {"+": sp.Add, "-": lambda a, b: a - b, "*": sp.Mul, "/": lambda a, b: a / b, "**": sp.Pow}


def parameter_symbols(energy) -> tuple:
    """The symbols of the energy's parameters, in the order of the kernels' ``material`` argument."""
    _, names = energy
    return tuple(sp.Symbol(f"par_{name}", real=True) for name in names)


@functools.cache
def _formula(energy):
    text, names = energy
    return parse_formula(text, names)


def _expression(energy, symbols: dict, tree=None):
    """The SymPy form of the formula (or of its subtree ``tree``) with the given symbol values."""
    formula = _formula(energy)
    leaves = dict(zip(formula.parameters, parameter_symbols(energy))) | symbols
    number = lambda value: sp.Integer(value) if isinstance(value, int) else sp.Rational(repr(value))  # noqa: E731
    return fold(formula.tree() if tree is None else tree, leaves.__getitem__, number,
                lambda op, a, b: _BINARY[op](a, b), lambda op, a: -a if op == "-" else a,
                lambda name, a: _FUNCTIONS[name](a))


def _stretch_symbols(l1, l2) -> dict:
    i1, i2 = invariants(l1, l2)
    return dict(zip(SYMBOLS, (l1, l2, 1 / (l1 * l2), i1, i2)))


def invariants(l1, l2):
    l3 = 1 / (l1 * l2)
    return l1**2 + l2**2 + l3**2, l1**-2 + l2**-2 + l3**-2


def energy_in_invariants(energy):
    """W(I1, I2) of an invariant-only formula (None for a formula in the stretches)."""
    if not _formula(energy).invariant_only:
        return None
    return _expression(energy, {"I1": I1, "I2": I2})


def membrane_energy(energy, l1, l2):
    """Φ(λ1, λ2) with λ3 = 1/(λ1 λ2) and the invariants eliminated."""
    return _expression(energy, _stretch_symbols(l1, l2))


def domain_margins(energy, l1, l2) -> tuple:
    """The arguments of the formula's log (must be > 0) and sqrt (≥ 0) calls as functions of (λ1, λ2), in the
    order of scene/formula.domain_conditions."""
    return tuple(_expression(energy, _stretch_symbols(l1, l2), tree)
                 for _, tree, _ in domain_conditions(_formula(energy)))


def stretch_series(energy, s, r, terms: int) -> list:
    """c_0(s), …, c_{terms−1}(s) of Φ((s + r)/2, (s − r)/2) = Σ_j c_j(s) r^(2j) + O(r^(2·terms)): Φ at λ1,2 =
    (s ± r)/2, even in r = λ1 − λ2 by the symmetry of Φ (its odd coefficients vanish and are dropped), by the
    truncated-series engine with the formula's functions expanded about their arguments' constant terms
    (codegen/series.py; binomial(a, k) of a symbolic exponent as a product, as in ``_odd_coefficients``)."""
    phi = membrane_energy(energy, (s + r) / 2, (s - r) / 2)
    return [sp.expand_func(c) for c in truncated_series(phi, r, {}, 2 * terms - 2, calls=True)[::2]]


def shear_coefficient(energy, lam1, lam2):
    """K(λ1, λ2) finite at λ1 = λ2 (module docstring) and its limit there (as λ1 → λ2)."""
    e1, e2 = lam1**2, lam2**2
    W = energy_in_invariants(energy)
    if W is not None:
        i1, i2 = invariants(lam1, lam2)
        at = {I1: i1, I2: i2}
        K = sp.diff(W, I1).subs(at) / (e1 * e2) ** 2 + sp.diff(W, I2).subs(at) * ((e1 + e2) / (e1 * e2) ** 2 - 1)
        return K, K.subs(lam1, lam2)
    a, b, d, mean = sp.symbols("a b d mean", positive=True)
    phi = membrane_energy(energy, sp.sqrt(a), sp.sqrt(b))
    numerator = (sp.diff(phi, a) - sp.diff(phi, b)).subs({a: mean + d, b: mean - d}, simultaneous=True)
    # K = numerator/(2d) = Σ_j c_j d^(2j), c_j = (coefficient of d^(2j+1) in the numerator)/2
    odd = _odd_coefficients(numerator, d)
    series = sum(c / 2 * d ** (2 * j) for j, c in enumerate(odd))
    far = sp.Abs(lam1 - lam2) > SWITCH * lam2
    # the closed form at guarded e1 (2 e2 in the series range): no branch divides by zero after CSE
    guarded = sp.Piecewise((e1, far), (2 * e2, True))
    closed = (numerator / (2 * d)).subs({mean: (guarded + e2) / 2, d: (guarded - e2) / 2}, simultaneous=True)
    at = {mean: (e1 + e2) / 2, d: (e1 - e2) / 2}
    K = sp.Piecewise((closed, far), (series.subs(at, simultaneous=True), True))
    return K, series.subs({d: 0, mean: e2}).subs(e2, lam2**2)


def _odd_coefficients(numerator, d) -> list:
    """Coefficients of d, d³, …, d^(2·SERIES_TERMS − 1) in the numerator: by the truncated-series engine of the
    pole limits (codegen/series.py: powers with symbolic exponents by the binomial series, seconds), or, for a
    formula with other functions of the stretches (exp, log, …) that it does not expand, by repeated
    differentiation at d = 0 (minutes for long formulas)."""
    order = 2 * SERIES_TERMS - 1
    try:
        # binomial(a, k) of a symbolic exponent as the product a(a − 1)…(a − k + 1)/k! (SymPy would print it as a
        # gamma ratio, 0/0 at the integer exponents a runtime parameter may take)
        coefficients = [sp.expand_func(c) for c in truncated_series(numerator, d, {}, order)]
    except NotImplementedError:
        coefficients, derivative = [], numerator
        for k in range(order + 1):
            coefficients.append(derivative.subs(d, 0) / sp.factorial(k))
            derivative = sp.diff(derivative, d)
    return coefficients[1::2]
