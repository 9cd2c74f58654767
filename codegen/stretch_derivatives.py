"""Pointwise kernels in (λ1, λ2) of a strain-energy class.

``membrane_derivatives``: Φ and its first and second derivatives (the elastic energy: a dielectric class's
term −Φ̄² λ1² λ2² is added where the runtime needs it, model/sphere.py); the runtime's sphere closed forms
(P = 2Φ_1/λ², the sphere's bifurcation conditions, model/sphere_modes.py) and the elastic stresses
σ_i = λ_i Φ_i (MODEL.md §6) need them for energies that are not Ogden sums.
``domain_margins`` (only for a formula with log or sqrt): the arguments of those calls, which must be > 0 (log)
or ≥ 0 (sqrt) (galerkin/equilibrium.py checks them at every node).
"""
import sympy as sp

from .energies import domain_margins
from .functional import SceneClass
from .kernels import Arg, Kernel

lam1, lam2 = sp.symbols("lam1 lam2", positive=True)
LABELS = ("phi", "phi_1", "phi_2", "phi_11", "phi_12", "phi_22")


def derivatives_kernel(cls: SceneClass) -> Kernel:
    phi = cls.elastic.membrane(lam1, lam2)
    d1, d2 = sp.diff(phi, lam1), sp.diff(phi, lam2)
    outputs = (phi, d1, d2, sp.diff(d1, lam1), sp.diff(d1, lam2), sp.diff(d2, lam2))
    return Kernel("membrane_derivatives", "Φ, Φ_1, Φ_2, Φ_11, Φ_12, Φ_22 at (λ1, λ2) (Φ_i = ∂Φ/∂λ_i).",
                  (Arg.node(lam1), Arg.node(lam2), *cls.elastic.arguments()), outputs, LABELS)


def domain_kernels(cls: SceneClass) -> list[Kernel]:
    margins = domain_margins(cls.elastic.energy, lam1, lam2)
    if not margins:
        return []
    return [Kernel("domain_margins", "Arguments of the energy's log (> 0) and sqrt (≥ 0) calls at (λ1, λ2).",
                   (Arg.node(lam1), Arg.node(lam2), *cls.elastic.arguments()), margins,
                   tuple(f"margin{k}" for k in range(len(margins))))]
