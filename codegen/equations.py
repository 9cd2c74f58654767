"""Equations from the functional: energy gradient/Hessian (Ritz–Galerkin) and the first-order EL system.

Galerkin form: E = ∫_{-1}^{1} π̂ d(cos θ); its first variation needs ∂π̂/∂(λ2, v, η, w) at a node, its Jacobian
(= the axisymmetric second variation) the 4×4 Hessian of π̂, and continuation the derivative of the gradient in
each parameter the class's terms are continued in (∂/∂P; ∂/∂M with the magnetic term, ∂/∂Φ̄ with the dielectric).

First-order form (MODEL.md §4): with L(θ, λ2, λ2', η, η') = Π(θ, λ2, λ2' sin θ, η, η'), the EL equations
d/dθ(Π_v sin θ) = Π_λ2 and d/dθ Π_w = Π_η are linear in (v', w'):
    [Π_vv Π_vw; Π_wv Π_ww] (v', w') = b,
    b1 = Π_λ2/s − c Π_v/s − ∂_θΠ_v − Π_vλ2 v/s − Π_vη w,
    b2 = Π_η − ∂_θΠ_w − Π_wλ2 v/s − Π_wη w,
(∂_θ the explicit θ-derivative) so y = (λ2, v, η, w) obeys y' = f = (v/s, F1, w, F2). The 2×2 matrix is
singular when the membrane is unstretched (its determinant is proportional to the tension Φ_1).
"""
import sympy as sp

from . import functional as fn
from .functional import STATE, SceneClass, cos_theta, eta, lam2, sin_theta, theta, v, w
from .kernels import Arg, Kernel

HESSIAN_PAIRS = tuple((i, j) for i in range(4) for j in range(i, 4))  # upper triangle row by row
STATE_LABELS = tuple(map(str, STATE))


def pair_labels(symbols, pairs) -> tuple:
    """'a_b' for each (i, j) of ``pairs``: the output labels of a matrix stored as the listed entries."""
    return tuple(f"{symbols[i]}_{symbols[j]}" for i, j in pairs)


def kernel_args(cls: SceneClass, node_symbols, leading_params=(), rows=lambda term: term.rows()):
    """The calling convention of a pointwise kernel: node values, then (leading_params, the terms' runtime
    scalars: P, [M, χ], [Φ̄]), the material's arrays (μ, [α] or ``material``), then ``rows(term)`` of every term
    (default its node rows, e.g. the field's H² and derivatives)."""
    args = [Arg.node(s) for s in node_symbols]
    args += [Arg.param(p) for p in (*leading_params, *fn.runtime_args(cls))]
    args += cls.elastic.arguments()
    args += [arg for term in cls.terms for arg in rows(term)]
    return tuple(args)


def energy_kernels(cls: SceneClass) -> list[Kernel]:
    density = fn.energy_density(cls)
    gradient = [sp.diff(density, x) for x in STATE]
    hessian = [sp.diff(gradient[i], STATE[j]) for i, j in HESSIAN_PAIRS]
    at_node = lambda exprs: tuple(fn.at_node(cls, e) for e in exprs)  # noqa: E731
    args = kernel_args(cls, cls.meridian.node_symbols + STATE)
    kernels = [
        Kernel("energy_density", "π̂ = Π/sin θ at a node (MODEL.md §2).", args, at_node([density]), ("pi_hat",)),
        Kernel("energy_gradient", "∂π̂/∂(λ2, v, η, w).", args, at_node(gradient), STATE_LABELS),
        Kernel(
            "energy_hessian",
            "∂²π̂/∂(λ2, v, η, w)², upper triangle row by row (the axisymmetric second variation).",
            args,
            at_node(hessian),
            pair_labels(STATE, HESSIAN_PAIRS),
        ),
    ]
    kernels += [Kernel(f"{word}_gradient", f"∂²π̂/∂{shown}∂(λ2, v, η, w).", args,
                       at_node([sp.diff(g, symbol) for g in gradient]), STATE_LABELS)
                for symbol, word, shown in fn.continuations(cls)]
    return kernels


def linear_system(cls: SceneClass):
    """(A, b) of A (v', w') = b with node symbols for sin θ, cos θ; the H² proxy is left unevaluated."""
    Pi = fn.lagrangian(cls)
    s, c = sp.sin(theta), sp.cos(theta)
    Pi_v, Pi_w = sp.diff(Pi, v), sp.diff(Pi, w)
    A = [[sp.diff(Pi_v, v), sp.diff(Pi_v, w)], [sp.diff(Pi_w, v), sp.diff(Pi_w, w)]]
    b1 = (sp.diff(Pi, lam2) - c * Pi_v) / s - sp.diff(Pi_v, theta) - sp.diff(Pi_v, lam2) * v / s - sp.diff(Pi_v, eta) * w
    b2 = sp.diff(Pi, eta) - sp.diff(Pi_w, theta) - sp.diff(Pi_w, lam2) * v / s - sp.diff(Pi_w, eta) * w
    node = {s: sin_theta, c: cos_theta}
    return [[a.subs(node) for a in row] for row in A], [b1.subs(node), b2.subs(node)]


def first_order_kernels(cls: SceneClass) -> list[Kernel]:
    """f, ∂f/∂y and ∂f/∂(each continuation parameter: P, [M], [Φ̄]), with F = A⁻¹ b and
    ∂F/∂x = A⁻¹(∂b/∂x − ∂A/∂x F)."""
    A, b = linear_system(cls)
    at_node = lambda e: fn.at_node(cls, e)  # noqa: E731
    a11, a12, a21, a22, b1, b2, det, F1, F2 = sp.symbols("a11 a12 a21 a22 b1 b2 det F1 F2")
    base = tuple(zip((a11, a12, a21, a22, b1, b2), map(at_node, (A[0][0], A[0][1], A[1][0], A[1][1], b[0], b[1]))))
    stages = (base, ((det, a11 * a22 - a12 * a21),), ((F1, (a22 * b1 - a12 * b2) / det), (F2, (a11 * b2 - a21 * b1) / det)))

    def dF(x):
        r1 = at_node(sp.diff(b[0], x) - sp.diff(A[0][0], x) * F1 - sp.diff(A[0][1], x) * F2)
        r2 = at_node(sp.diff(b[1], x) - sp.diff(A[1][0], x) * F1 - sp.diff(A[1][1], x) * F2)
        return (a22 * r1 - a12 * r2) / det, (a11 * r2 - a21 * r1) / det

    args = kernel_args(cls, (theta, cos_theta, sin_theta) + STATE)
    columns = [dF(x) for x in STATE]
    jacobian = [0, 1 / sin_theta, 0, 0] + [col[0] for col in columns] + [0, 0, 0, 1] + [col[1] for col in columns]
    row_major = pair_labels(STATE, [(i, j) for i in range(4) for j in range(4)])
    kernels = [
        Kernel("rhs", "y' = f(θ, y): (λ2', v', η', w') of the EL equations (MODEL.md §4).", args,
               (v / sin_theta, F1, w, F2), STATE_LABELS, stages),
        Kernel("rhs_jacobian", "∂f/∂(λ2, v, η, w), row-major 4×4.", args, tuple(map(sp.sympify, jacobian)),
               row_major, stages),
    ]
    for symbol, word, shown in fn.continuations(cls):
        d1, d2 = dF(symbol)
        kernels.append(Kernel(f"rhs_{word}", f"∂f/∂{shown}.", args, (sp.S.Zero, d1, sp.S.Zero, d2), STATE_LABELS,
                              stages))
    return kernels
