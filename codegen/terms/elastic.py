"""The elastic term: the strain energy Φ(λ1, λ2) of the material with λ3 = 1/(λ1 λ2) eliminated (MODEL.md §1),

    Φ = Σ_i (μ_i/α_i)(λ1^α_i + λ2^α_i + (λ1 λ2)^(−α_i) − 3)   (Ogden: exponents baked in, or runtime exponents),

or another strain energy written as a formula (codegen/energies.py), its parameters at run time. Every class has
one; the stages that need the material itself (the surface Φ(I, J) stage, the shear coefficient's removable
singularity, the stretch derivatives) read it as ``SceneClass.elastic``.
"""
from dataclasses import dataclass

import sympy as sp

from .. import energies
from ..kernels import Arg

GENERAL_TERMS = 3  # Ogden terms of the class with runtime exponents


@dataclass(frozen=True)
class Elastic:
    """Ogden exponents ``alphas`` (strings; None: runtime exponents), or instead a strain energy ``energy`` =
    (canonical formula, parameter names)."""

    alphas: tuple | None = None
    energy: tuple | None = None

    @property
    def n_terms(self) -> int:
        return GENERAL_TERMS if self.alphas is None else len(self.alphas)

    def moduli(self):
        return sp.symbols(f"mu0:{self.n_terms}", real=True)

    def exponents(self):
        if self.alphas is None:
            return sp.symbols(f"alpha0:{self.n_terms}", real=True)
        return tuple(sp.Rational(a) for a in self.alphas)

    def membrane(self, l1, l2):
        """Φ(λ1, λ2): the Ogden sum, or the strain energy formula."""
        if self.energy is not None:
            return energies.membrane_energy(self.energy, l1, l2)
        return sum((m / a) * (l1**a + l2**a + (l1 * l2) ** (-a) - 3) for m, a in zip(self.moduli(), self.exponents()))

    def arguments(self) -> list:
        """μ, and α for runtime exponents; a strain energy's parameters as ``material``: the kernels' material
        arguments, after the runtime scalars."""
        if self.energy is not None:
            return [Arg.param_array("material", energies.parameter_symbols(self.energy))]
        args = [Arg.param_array("mu", self.moduli())]
        if self.alphas is None:
            args.append(Arg.param_array("alpha", self.exponents()))
        return args

    def inputs(self) -> dict:
        if self.energy is not None:
            return {"energy": self.energy[0], "parameters": tuple(self.energy[1])}
        return {"alphas": "runtime" if self.alphas is None else tuple(str(a) for a in self.alphas)}

    def title(self) -> str:
        if self.energy is not None:
            return f"strain energy {self.energy[0]}"
        return f"Ogden exponents {self.inputs()['alphas']}"
