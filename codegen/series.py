"""Truncated power series in one variable, for the pole limits.

SymPy's ``series`` is far too slow on the membrane energy (minutes per term), so the pole expansions use this
small engine: every expression is mapped to its coefficient list [a0, …, a_n] in the small variable t,
products are truncated at order n and non-integer powers use the binomial series about the constant term.
With ``calls``, a one-argument function f (exp, log, tanh, …) of a series a0 + h(t) is expanded by its Taylor
series about a0, Σ_k f⁽ᵏ⁾(a0) h^k/k! (the whole-sphere kernels of a formula in the stretches, codegen/surface.py).
"""
import sympy as sp


def _mul(a, b, order):
    out = [sp.S.Zero] * (order + 1)
    for i, ai in enumerate(a):
        if ai == 0:
            continue
        for j in range(order + 1 - i):
            if b[j] != 0:
                out[i + j] += ai * b[j]
    return [sp.expand(c) for c in out]


def _power(base, exponent, order):
    if exponent.is_Integer and exponent >= 0:
        out = [sp.S.One] + [sp.S.Zero] * order
        for _ in range(int(exponent)):
            out = _mul(out, base, order)
        return out
    b0 = base[0]
    if b0 == 0:
        raise ValueError("series of a power about a zero constant term (a pole of the expression)")
    ratio = [sp.S.Zero] + [sp.expand(c / b0) for c in base[1:]]
    out = [sp.S.One] + [sp.S.Zero] * order
    term = [sp.S.One] + [sp.S.Zero] * order
    for k in range(1, order + 1):
        term = _mul(term, ratio, order)
        coeff = sp.binomial(exponent, k)
        out = [o + coeff * t for o, t in zip(out, term)]
    return [sp.expand(b0**exponent * c) for c in out]


def _call(function, argument, order, constants: list):
    """f(a0 + h) = Σ_k f⁽ᵏ⁾(a0) h^k/k!, h the argument's series without its constant term; f⁽ᵏ⁾ is taken at a
    symbol A standing for a0, appended to ``constants`` as (A, a0) (expanding 1/a0^k of a sum a0 would multiply
    its terms out)."""
    a0, h = sp.Dummy("a0"), [sp.S.Zero] + argument[1:]
    constants.append((a0, argument[0]))
    x = sp.Dummy("x")
    derivative_at, power = function(x), [sp.S.One] + [sp.S.Zero] * order
    out = [function(a0)] + [sp.S.Zero] * order
    for k in range(1, order + 1):
        power = _mul(power, h, order)
        derivative_at = sp.diff(derivative_at, x)
        coeff = derivative_at.subs(x, a0) / sp.factorial(k)
        out = [o + coeff * p for o, p in zip(out, power)]
    return [sp.expand(c) for c in out]


def truncated_series(expr, t, known, order, calls=False):
    """Coefficients [a0..a_order] of ``expr`` in powers of ``t``.

    ``known`` maps symbols to their own coefficient lists; sin(t) and cos(t) are expanded directly; ``calls``:
    any other one-argument function by its Taylor series about the argument's constant term (module docstring).
    """

    def walk(e):
        if e in known:
            return list(known[e]) + [sp.S.Zero] * (order + 1 - len(known[e]))
        if e == t:
            return [sp.S.Zero, sp.S.One] + [sp.S.Zero] * (order - 1)
        if not e.has(t) and not any(e.has(k) for k in known):
            return [e] + [sp.S.Zero] * order
        if e.is_Add:
            parts = [walk(a) for a in e.args]
            return [sp.expand(sum(c)) for c in zip(*parts)]
        if e.is_Mul:
            out = walk(e.args[0])
            for a in e.args[1:]:
                out = _mul(out, walk(a), order)
            return out
        if e.is_Pow:
            return _power(walk(e.base), e.exp, order)
        if isinstance(e, (sp.sin, sp.cos)) and e.args[0] == t:
            taylor = sp.series(e, t, 0, order + 1).removeO()
            return [taylor.coeff(t, k) for k in range(order + 1)]
        if calls and isinstance(e, sp.Function) and len(e.args) == 1:
            return _call(e.func, walk(e.args[0]), order, constants)
        raise NotImplementedError(f"truncated_series: cannot expand {e.func}")

    constants = []
    coefficients = walk(sp.sympify(expr))
    for symbol, value in reversed(constants):  # a call's constant term may hold those of the calls inside it
        coefficients = [c.xreplace({symbol: value}) for c in coefficients]
    return coefficients


def derivative(coeffs):
    """Coefficients of d/dt of a truncated series (one order shorter)."""
    return [k * c for k, c in enumerate(coeffs)][1:]
