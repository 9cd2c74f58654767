"""A strain-energy formula from a scene file, parsed safely (never ``eval``/``sympify`` on the text).

The text is parsed by Python's ``ast`` in expression mode and every node is checked against a whitelist:
numbers, the named symbols, named parameters, ``+ − * / **`` (``^`` is read as ``**``), unary ±, and calls of
``FUNCTIONS`` by bare name with positional arguments. Anything else (attribute access, subscripts, lambdas,
comprehensions, keywords, strings, other names or calls) is rejected with the offending token named. Nothing
in the text is ever executed: the checked tree is only walked by ``fold``.

Symbols: the principal stretches ``lambda1``, ``lambda2``, ``lambda3`` (also ``λ1``, ``λ2``, ``λ3``;
λ3 = 1/(λ1 λ2)) and the invariants I1 = λ1² + λ2² + λ3², I2 = λ1⁻² + λ2⁻² + λ3⁻². The formula gives Φ(λ1, λ2)
of MODEL.md §2, moduli in units of μ/2 (``"I1 - 3"`` is the neo-Hookean preset).
"""
import ast
import cmath
import functools
import math
from dataclasses import dataclass

from .validation import SceneError, show

MAX_LENGTH = 2000
MAX_DEPTH = 60
# Bounds on what the kernels' derivation will face (docs/scenes.md, Bounds), checked on the tree before SymPy
# sees it: SymPy evaluates a power of numbers eagerly ((1/3)**(10**9) never returns), and the derivatives of deeply
# nested functions grow without bound (sinh nested 8 deep takes minutes).
MAX_NODES = 300  # numbers, names, operators and calls in the tree
MAX_CALL_DEPTH = 3  # functions nested in functions: exp(sinh(tanh(I1 - 3))) is 3
MAX_EXPONENT = 32  # |a constant exponent|, and the product of nested ones: (I1**8)**4 is 32
MAX_CONSTANT = 1e12  # |a number|, and |a subexpression of numbers only|
STRETCHES = ("lambda1", "lambda2", "lambda3")
INVARIANTS = ("I1", "I2")
SYMBOLS = STRETCHES + INVARIANTS
_ALIASES = {"λ1": "lambda1", "λ2": "lambda2", "λ3": "lambda3"}
FUNCTIONS = {"exp": 1, "log": 1, "sqrt": 1, "sinh": 1, "cosh": 1, "tanh": 1, "atan": 1}
_BINARY = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}
_UNARY = {ast.USub: "-", ast.UAdd: "+"}


@dataclass(frozen=True)
class Formula:
    """A checked formula: its canonical text (aliases resolved, ``ast.unparse`` of the checked tree), the
    parameter names it may use, in order, and the symbols it uses."""

    text: str
    parameters: tuple[str, ...]
    symbols: frozenset

    @property
    def invariant_only(self) -> bool:
        """True when the formula uses I1, I2 only (no stretch symbol)."""
        return not self.symbols & set(STRETCHES)

    def tree(self) -> ast.expr:
        """The checked expression tree of the canonical text (parsed once per text)."""
        return _checked_tree(self.text, self.parameters)


@functools.cache
def _checked_tree(text: str, parameters: tuple) -> ast.expr:
    return _check(text, parameters, "energy").body


def parse_formula(text, parameters=(), key: str = "material.energy") -> Formula:
    """The checked Formula of ``text`` with parameter names ``parameters``; SceneError naming the first
    offending token otherwise."""
    if not isinstance(text, str) or not text.strip():
        raise SceneError(f"{key} = {show(text)}: must be a non-empty string")
    if len(text) > MAX_LENGTH:
        raise SceneError(f"{key}: formula of {len(text)} characters; at most {MAX_LENGTH} allowed")
    parameters = tuple(parameters)
    for name in parameters:
        if not name.isidentifier() or name in SYMBOLS or name in _ALIASES or name in FUNCTIONS:
            raise SceneError(f"{key}: parameter name {show(name)} must be an identifier other than "
                             f"{', '.join(SYMBOLS + tuple(FUNCTIONS))}")
    source = text.replace("^", "**")
    tree = _check(source, parameters, key)
    canonical = ast.unparse(tree)
    _bound(tree.body, source, key)
    used = frozenset(n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and n.id in SYMBOLS)
    unused = [p for p in parameters if p not in {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}]
    if unused:
        table = key.removesuffix(".energy")  # material.energy's parameters are material.parameters
        raise SceneError(f"{table}.parameters.{unused[0]}: not used by the formula {show(canonical)}")
    return Formula(canonical, parameters, used)


def _check(text: str, parameters: tuple, key: str) -> ast.Expression:
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as e:
        raise SceneError(f"{key} = {show(text)}: not a formula (syntax error at column {e.offset})") from None
    names = set(SYMBOLS) | set(parameters)

    def visit(node, depth):
        if depth > MAX_DEPTH:
            raise SceneError(f"{key}: formula nested deeper than {MAX_DEPTH} levels")
        if isinstance(node, ast.Expression):
            return visit(node.body, depth + 1)
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                raise SceneError(f"{key}: {_token(text, node)!r} is not allowed (only real numbers)")
            return
        if isinstance(node, ast.Name):
            if node.id in _ALIASES:
                node.id = _ALIASES[node.id]
            if node.id not in names:
                raise SceneError(f"{key}: unknown name {node.id!r}; allowed: {', '.join(SYMBOLS)}, λ1, λ2, λ3, "
                                 f"the parameters ({', '.join(parameters) or 'none'}), functions "
                                 f"{', '.join(FUNCTIONS)}")
            return
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            visit(node.left, depth + 1)
            return visit(node.right, depth + 1)
        if isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
            return visit(node.operand, depth + 1)
        if isinstance(node, ast.Call):
            name = node.func.id if isinstance(node.func, ast.Name) else None
            if name not in FUNCTIONS:
                raise SceneError(f"{key}: call {_token(text, node.func)!r} is not allowed; "
                                 f"functions: {', '.join(FUNCTIONS)}")
            if node.keywords or len(node.args) != FUNCTIONS[name] or any(
                    isinstance(a, ast.Starred) for a in node.args):
                raise SceneError(f"{key}: {_token(text, node)!r}: {name} takes {FUNCTIONS[name]} plain argument")
            return visit(node.args[0], depth + 1)
        raise SceneError(f"{key}: {_token(text, node)!r} is not allowed ({type(node).__name__}); only numbers, "
                         "symbols, parameters, + - * / ** and the listed functions")

    visit(tree, 0)
    return tree


def _bound(tree: ast.expr, text: str, key: str) -> None:
    """SceneError naming the formula when the checked tree exceeds a bound above (MAX_NODES, MAX_CALL_DEPTH,
    MAX_EXPONENT, MAX_CONSTANT), or when a subexpression of numbers only has no finite value (1/0, exp(1e6)).
    Numbers are combined in complex floating point, each exponent checked before its power is taken: nothing
    here can be slow."""
    def refuse(what: str):
        raise SceneError(f"{key} = {show(text if len(text) <= 120 else text[:117] + '...')}: {what}")

    nodes = sum(1 for n in ast.walk(tree) if isinstance(n, (ast.Constant, ast.Name, ast.BinOp, ast.UnaryOp,
                                                              ast.Call)))
    if nodes > MAX_NODES:
        refuse(f"{nodes} terms (numbers, names, operations); at most {MAX_NODES}")

    def value(node, calls: int, power: float):
        """The number ``node`` stands for (complex), or None when it holds a symbol or parameter."""
        if isinstance(node, ast.Constant):
            try:
                number = complex(node.value)
            except OverflowError:
                number = complex(math.inf)
            if not abs(number) <= MAX_CONSTANT:
                refuse(f"the number {_token(text, node)} is beyond ±{MAX_CONSTANT:g}")
            return number
        if isinstance(node, ast.Name):
            return None
        if isinstance(node, ast.UnaryOp):
            inner = value(node.operand, calls, power)
            return None if inner is None else (-inner if isinstance(node.op, ast.USub) else inner)
        if isinstance(node, ast.Call):
            if calls + 1 > MAX_CALL_DEPTH:
                refuse(f"functions nested {calls + 1} deep; at most {MAX_CALL_DEPTH}")
            inner = value(node.args[0], calls + 1, 1.0)
            return None if inner is None else _constant(refuse, node, text,
                                                        lambda: getattr(cmath, node.func.id)(inner))
        if isinstance(node.op, ast.Pow):
            exponent = value(node.right, calls, 1.0)
            if exponent is not None:
                if not abs(exponent) <= MAX_EXPONENT:
                    refuse(f"the exponent {_token(text, node.right)} is beyond ±{MAX_EXPONENT}")
                power *= max(abs(exponent), 1.0)
                if power > MAX_EXPONENT:
                    refuse(f"nested powers multiply to an exponent of {power:g}; at most {MAX_EXPONENT}")
            base = value(node.left, calls, power)
            if base is None or exponent is None:
                return None
            if base == 0 and exponent.real <= 0:
                refuse(f"{_token(text, node)}: zero to a power ≤ 0")
            return _constant(refuse, node, text, lambda: base**exponent)
        left, right = value(node.left, calls, power), value(node.right, calls, power)
        if left is None or right is None:
            return None
        if isinstance(node.op, ast.Div) and right == 0:
            refuse(f"{_token(text, node)}: division by zero")
        return _constant(refuse, node, text, lambda: _OPS[_BINARY[type(node.op)]](left, right))

    value(tree, 0, 1.0)


def _constant(refuse, node, text: str, compute) -> complex:
    """``compute()``, a subexpression of numbers, if finite and within ±MAX_CONSTANT (else ``refuse``)."""
    try:
        number = complex(compute())
    except (OverflowError, ZeroDivisionError, ValueError):
        number = complex(math.inf)
    if not (math.isfinite(number.real) and math.isfinite(number.imag) and abs(number) <= MAX_CONSTANT):
        refuse(f"{_token(text, node)} is not a finite number within ±{MAX_CONSTANT:g}")
    return number


def _token(text: str, node) -> str:
    segment = ast.get_source_segment(text, node)
    return segment if segment is not None and len(segment) <= 60 else type(node).__name__


def fold(tree, leaf, number, binary, unary, call):
    """Walk a checked tree bottom-up: ``leaf(name)``, ``number(value)``, ``binary(op, a, b)`` with op in
    '+ - * / **', ``unary(op, a)``, ``call(function name, a)``."""
    if isinstance(tree, ast.Constant):
        return number(tree.value)
    if isinstance(tree, ast.Name):
        return leaf(tree.id)
    args = (leaf, number, binary, unary, call)
    if isinstance(tree, ast.BinOp):
        return binary(_BINARY[type(tree.op)], fold(tree.left, *args), fold(tree.right, *args))
    if isinstance(tree, ast.UnaryOp):
        return unary(_UNARY[type(tree.op)], fold(tree.operand, *args))
    return call(tree.func.id, fold(tree.args[0], *args))


@functools.cache
def domain_conditions(formula: Formula) -> tuple:
    """(function, argument tree, argument text) of every ``log`` (argument > 0) and ``sqrt`` (argument ≥ 0) in
    the formula: its admissible domain (Gent's I1 − 3 < Jm, Arruda–Boyce's I1 < 3N)."""
    return tuple((node.func.id, node.args[0], ast.unparse(node.args[0])) for node in ast.walk(formula.tree())
                 if isinstance(node, ast.Call) and node.func.id in ("log", "sqrt"))


_OPS = {"+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b, "/": lambda a, b: a / b,
        "**": lambda a, b: a**b}


def evaluate(formula: Formula, values: dict, lam1, lam2):
    """Φ(λ1, λ2) of the formula with parameter ``values``, in complex arithmetic (``cmath``; for the complex-step
    derivatives of the reference-state checks)."""
    lam3 = 1 / (lam1 * lam2)
    symbols = {"lambda1": lam1, "lambda2": lam2, "lambda3": lam3, "I1": lam1**2 + lam2**2 + lam3**2,
               "I2": lam1**-2 + lam2**-2 + lam3**-2, **values}
    return fold(formula.tree(), symbols.__getitem__, complex, lambda op, a, b: _OPS[op](a, b),
                lambda op, a: -a if op == "-" else a, lambda name, a: getattr(cmath, name)(a))
