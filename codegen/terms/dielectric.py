"""The dielectric term of an ideal dielectric elastomer under the voltage Φ_e across its thickness H (MODEL.md §2):

    Φ += −Φ̄² λ1² λ2² = −Φ̄² J²,

the free energy −(ε/2)(Φ_e/H)² λ1² λ2² per reference volume in units of μ/2, with the nondimensional voltage
Φ̄ = (Φ_e/H) √(ε/μ) (the runtime parameter ``voltage``; docs/scenes.md). A function of the stretches, it enters
every kernel through Φ (pole series, second variation: the shear coefficient gains Φ̄²); on the whole sphere it is
smooth in J and stays outside the Φ(I, J) stage. Continued in Φ̄: voltage_gradient, rhs_voltage,
surface_voltage_gradient.
"""
from dataclasses import dataclass

import sympy as sp

from . import Term

voltage = sp.Symbol("voltage", real=True)


@dataclass(frozen=True)
class Dielectric(Term):
    name = "dielectric"
    parameters = (voltage,)
    continuation = (voltage, "voltage", "Φ̄")

    def membrane(self, l1, l2):
        return -voltage**2 * l1**2 * l2**2

    def surface(self, point, a_t, a_p, areal):
        return self.membrane(areal, sp.S.One)

    def inputs(self) -> dict:
        return {"electric": True}

    def title(self, surface: bool) -> str:
        return f"dielectric term -voltage^2 {'J^2' if surface else 'lam1^2 lam2^2'}"


DIELECTRIC = Dielectric()
