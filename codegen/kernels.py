"""Kernel IR: a named list of outputs over typed arguments, lowered to CSE'd assignments.

A kernel is pointwise: it maps scalars at one quadrature node (``node`` arguments, or rows of a ``node_rows``
matrix) and branch parameters (``param`` scalars, ``param_array`` vectors) to a tuple of outputs. ``stages``
are earlier definitions (symbol = expression) that later stages and the outputs may use; each stage is CSE'd
on its own so that a definition never appears after its first use (a stage's definitions may only use
symbols defined in earlier stages).

``convention`` is the calling convention as plain data, emitted into every module (``KERNELS``) so that the
runtime binds arguments by name and reads output layouts instead of keeping copies of them.
"""
import functools
from dataclasses import dataclass, field

import sympy as sp


@dataclass(frozen=True)
class Arg:
    """One argument: kind is 'node', 'param', 'node_rows' (matrix, one row per symbol) or 'param_array'."""

    kind: str
    name: str
    symbols: tuple

    @staticmethod
    def node(symbol):
        return Arg("node", str(symbol), (symbol,))

    @staticmethod
    def param(symbol):
        return Arg("param", str(symbol), (symbol,))

    @staticmethod
    def node_rows(name, symbols):
        return Arg("node_rows", name, tuple(symbols))

    @staticmethod
    def param_array(name, symbols):
        return Arg("param_array", name, tuple(symbols))


@dataclass(frozen=True)
class Kernel:
    """``labels`` name the outputs in order (the row layout of ``NAME_nodes``' out)."""

    name: str
    doc: str
    args: tuple
    outputs: tuple
    labels: tuple
    stages: tuple = field(default=())  # tuple of tuples of (symbol, expr)
    vectorise: bool = True

    def __post_init__(self):
        if len(self.labels) != len(self.outputs):
            raise ValueError(f"{self.name}: {len(self.labels)} labels for {len(self.outputs)} outputs")


def convention(kernel: Kernel) -> dict:
    """{'args': ((name, kind, rows), ...), 'outputs': labels, 'nodes': has NAME_nodes} of one kernel; rows name
    the entries of a 'param_array' or the rows of a 'node_rows' argument (empty for scalars)."""
    args = tuple(
        (arg.name, arg.kind, tuple(map(str, arg.symbols)) if arg.kind in ("param_array", "node_rows") else ())
        for arg in kernel.args
    )
    return {"args": args, "outputs": tuple(kernel.labels), "nodes": kernel.vectorise}


@dataclass(frozen=True)
class LoweredKernel:
    kernel: Kernel
    assignments: tuple  # ((symbol, expr), ...) in evaluation order
    results: tuple


@functools.lru_cache(maxsize=64)
def lowered_stage(index: int, stage: tuple) -> tuple:
    """The CSE'd assignments of stage ``index`` (its subexpressions named s{index}_k, then its definitions): the
    same for every kernel that shares the stage (a class's rhs kernels, its surface kernels), so done once."""
    replacements, reduced = sp.cse([expr for _, expr in stage], symbols=sp.numbered_symbols(f"s{index}_"))
    return (*replacements, *zip((sym for sym, _ in stage), reduced))


def lower(kernel: Kernel) -> LoweredKernel:
    """Common-subexpression elimination, stage by stage (definitions before uses)."""
    assignments = []
    for index, stage in enumerate(kernel.stages):
        assignments.extend(lowered_stage(index, stage))
    replacements, results = sp.cse(list(kernel.outputs), symbols=sp.numbered_symbols("t"))
    assignments.extend(replacements)
    return LoweredKernel(kernel, tuple(assignments), tuple(results))

