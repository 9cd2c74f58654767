"""Numba-flavoured Python printer: integer powers become products, half powers become ``math.sqrt``."""
import functools

from sympy.printing.pycode import PythonCodePrinter
import sympy as sp


class NumbaPrinter(PythonCodePrinter):
    """SymPy printer for jitted scalar code (cf. Devito's ``CodePrinter`` subclass)."""

    _kf = {**PythonCodePrinter._kf}

    def _print_Pow(self, expr, rational=False):
        base, exponent = expr.base, expr.exp
        if exponent.is_Integer:
            n = int(exponent)
            if n == 0:
                return "1.0"
            factor = "*".join([self.parenthesize(base, 100)] * abs(n))
            if n == 1:
                return factor
            return f"({factor})" if n > 0 else f"(1.0/({factor}))"
        if exponent == sp.S.Half:
            return f"math.sqrt({self._print(base)})"
        if exponent == -sp.S.Half:
            return f"(1.0/math.sqrt({self._print(base)}))"
        if exponent.is_Rational and exponent.q == 2:
            whole = self._print(sp.Pow(base, exponent - sp.S.Half, evaluate=False))
            return f"({whole}*math.sqrt({self._print(base)}))"
        return f"{self.parenthesize(base, 100)}**{self._print_exponent(exponent)}"

    def _print_exponent(self, exponent):
        if exponent.is_Number:
            return f"({float(exponent)!r})"
        return self.parenthesize(exponent, 100)

    def _print_Rational(self, expr):
        return repr(float(expr))

    def _print_Half(self, expr):
        return "0.5"

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Integer(self, expr):
        return f"{int(expr)}.0" if abs(int(expr)) < 2**53 else repr(float(expr))


@functools.lru_cache(maxsize=4096)
def print_expr(expr) -> str:
    """The expression's text (memoised: kernels that share a stage print its assignments once)."""
    return NumbaPrinter({"fully_qualified_modules": True, "standard": "python3"}).doprint(expr)
