"""The pencil (K, M) of small oscillations about one equilibrium and its units (MODEL.md §11, docs/dynamics.md).

With the loaded energy (2π T0 R0² μ/2) ½ qᵀKq (E per 2π, moduli over μ/2: MODEL.md §2) and the membrane's kinetic
energy (2π ρ T0 R0⁴) ½ q̇ᵀMq̇ (M from generated/inertia.py), q = q̂ e^{iωt} solves K q̂ = ν M q̂ with
ω² = (μ/2) ν/(ρ R0²): the dimensionless frequency Ω = ω R0 √(ρ/μ) (μ the initial shear modulus) has Ω² = ν/2.
K and M are the SecondVariation's Hessian and Gram matrix with the norm "displacement", which is M.
"""
import numpy as np

from ..analysis.results import Kind
from ..analysis.stability.axisymmetric import SecondVariation

PER_EIGENVALUE = 0.5  # Ω² per eigenvalue ν of K q = ν M q
MASS_NORM = "displacement"  # the SecondVariation norm whose Gram matrix is the mass matrix
FOLD_CONTROL = {Kind.LP: "", Kind.LV: "_volume", Kind.LN: "_gas"}  # the control whose Hessian a fold makes singular


def mass_variation(equilibrium, degree: int) -> SecondVariation:
    """The second variation of ``equilibrium`` at perturbation ``degree`` with the mass matrix as its Gram matrix."""
    return SecondVariation(equilibrium, int(degree), norm=MASS_NORM)


def table_of(rows: list, names: list, count: int) -> dict:
    """{block: (rows × count) Ω²} from per-row dicts {block: values}, NaN where a row has fewer values (or not the
    block)."""
    table = {name: np.full((len(rows), count), np.nan) for name in names}
    for n, row in enumerate(rows):
        for name, values in row.items():
            table[name][n, :values.size] = values
    return table
