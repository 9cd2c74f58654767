"""Differentiation for the stages: SymPy's own rule at every node, without the checks ``Derivative`` wraps it in.

``expr.diff(x)`` descends the tree by building a ``Derivative`` at every node, and each of them takes the node's
free symbols, asks whether the node's derivative is zero (an assumptions query over the whole subtree), and walks
the result for unevaluated ``Derivative`` objects: most of the time codegen spent in ``diff`` (issue 37). Inside
``lean()`` the derivative of a node in one symbol x is

    0                                       if x is not among the node's free symbols,
    node._eval_derivative_n_times(x, 1)     otherwise (the node's own rule: sum, product, chain rule),

memoised per (node, x) for the duration, which is what ``Derivative`` returns for it; a node without a rule or
whose rule leaves an unevaluated ``Derivative`` (or none), and every other call (several symbols, keyword
arguments) go to SymPy's ``diff`` as before. The kernels are byte for byte those of plain SymPy
(tests/test_codegen.py: the staleness test).
"""
import contextlib

import sympy as sp
from sympy.core.expr import Expr

_SYMPY_DIFF = Expr.diff


def _order(variable):
    """(x, n) of a single derivative variable: a Symbol (n = 1) or the pair (x, n) with n 0 or 1 that a product's
    rule passes its factors; None for anything else."""
    if isinstance(variable, sp.Symbol):
        return variable, sp.S.One
    if (isinstance(variable, tuple) and len(variable) == 2 and isinstance(variable[0], sp.Symbol)
            and isinstance(variable[1], (int, sp.Integer)) and variable[1] in (0, 1)):
        return variable[0], sp.Integer(variable[1])
    return None


@contextlib.contextmanager
def lean():
    """Within: ``Expr.diff`` of one symbol by the node's rule, memoised (the module docstring)."""
    if Expr.diff is not _SYMPY_DIFF:  # nested: the outer one's memo serves
        yield
        return
    memo = {}

    def diff(expr, *variables, **options):
        order = _order(variables[0]) if len(variables) == 1 and not options else None
        if order is None:
            return _SYMPY_DIFF(expr, *variables, **options)
        x, n = order
        if n == 0:  # Derivative(expr, (x, 0)) is expr
            return expr
        key = (expr, x)
        if key not in memo:
            if x not in expr.free_symbols:
                memo[key] = sp.S.Zero
            elif not hasattr(expr, "_eval_derivative"):  # Derivative leaves it unevaluated
                memo[key] = _SYMPY_DIFF(expr, x)
            else:
                derivative = expr._eval_derivative_n_times(x, n)
                if derivative is None or derivative.has(sp.Derivative):
                    derivative = _SYMPY_DIFF(expr, x)
                memo[key] = derivative
        return memo[key]

    Expr.diff = diff
    try:
        yield
    finally:
        Expr.diff = _SYMPY_DIFF
