"""The energy functional of MODEL.md §2 for one scene class.

Π(θ, λ2, v, η, w) = Φ(λ1, λ2) sin θ − ½ χ M H²(ρ, η) sin θ + ½ P λ2² w sin² θ,
λ1 = sqrt((λ2 cos θ + v)² + w²), ρ = λ2 sin θ,
Φ = Σ_i (μ_i/α_i)(λ1^α_i + λ2^α_i + (λ1 λ2)^(−α_i) − 3), or another strain energy (codegen/energies.py),
and for a dielectric class (an ideal dielectric elastomer under the voltage Φ_e across its thickness H)
Φ = Φ_elastic − Φ̄² λ1² λ2²: the free energy W − (ε/2)(Φ_e/H)² λ1² λ2² per reference volume in units of μ/2,
with the nondimensional voltage Φ̄ = (Φ_e/H) √(ε/μ) (the runtime parameter ``voltage``; docs/scenes.md).

H² is not symbolic: the field kernels supply its value and derivatives at the node, so Π carries a second-order
Taylor proxy of H² about (ρ0, η0) and ``field_values`` puts ρ0 = ρ, η0 = η back after differentiation. This is
exact for every derivative of order ≤ 2, which is all the equations and Hessians use.
"""
from dataclasses import dataclass

import sympy as sp

from . import energies

theta = sp.Symbol("theta", real=True)
cos_theta, sin_theta = sp.symbols("cos_theta sin_theta", real=True)
lam2, v, eta, w = sp.symbols("lam2 v eta w", real=True)
P, M, chi = sp.symbols("P M chi", real=True)
voltage = sp.Symbol("voltage", real=True)
STATE = (lam2, v, eta, w)

# H² and its derivatives in (ρ, η) at the node
Q, Q_r, Q_z, Q_rr, Q_rz, Q_zz = sp.symbols("Q Q_r Q_z Q_rr Q_rz Q_zz", real=True)
FIELD = (Q, Q_r, Q_z, Q_rr, Q_rz, Q_zz)
_rho0, _eta0 = sp.symbols("rho0 eta0", real=True)

GENERAL_TERMS = 3


@dataclass(frozen=True)
class SceneClass:
    """What a kernel module is specialised to: Ogden exponents (None: runtime exponents) and field presence,
    or instead of Ogden a strain energy ``energy`` = (canonical formula, parameter names) (codegen/energies.py)
    whose parameters the kernels take at run time; ``electric``: the dielectric term (module docstring)."""

    name: str
    alphas: tuple | None
    field: bool
    energy: tuple | None = None
    electric: bool = False

    @property
    def n_terms(self) -> int:
        return GENERAL_TERMS if self.alphas is None else len(self.alphas)

    def inputs(self) -> dict:
        """What the module is generated from (its header); 'electric' only where the term is present."""
        electric = {"electric": True} if self.electric else {}
        if self.energy is not None:
            return {"class": self.name, "energy": self.energy[0], "parameters": tuple(self.energy[1]),
                    "field": self.field, **electric}
        alphas = "runtime" if self.alphas is None else tuple(str(a) for a in self.alphas)
        return {"class": self.name, "alphas": alphas, "field": self.field, **electric}


def moduli(cls: SceneClass):
    return sp.symbols(f"mu0:{cls.n_terms}", real=True)


def exponents(cls: SceneClass):
    if cls.alphas is None:
        return sp.symbols(f"alpha0:{cls.n_terms}", real=True)
    return tuple(sp.Rational(a) for a in cls.alphas)


def ogden(cls: SceneClass, l1, l2):
    """Φ(λ1, λ2) with λ3 = 1/(λ1 λ2) eliminated."""
    return sum(
        (m / a) * (l1**a + l2**a + (l1 * l2) ** (-a) - 3) for m, a in zip(moduli(cls), exponents(cls))
    )


def elastic_energy(cls: SceneClass, l1, l2):
    """Φ_elastic(λ1, λ2) of the class: Ogden, or its strain energy formula."""
    if cls.energy is not None:
        return energies.membrane_energy(cls.energy, l1, l2)
    return ogden(cls, l1, l2)


def electric_energy(cls: SceneClass, l1, l2):
    """−Φ̄² λ1² λ2² for a dielectric class, else 0 (module docstring)."""
    return -voltage**2 * l1**2 * l2**2 if cls.electric else sp.S.Zero


def membrane_energy(cls: SceneClass, l1, l2):
    """Φ(λ1, λ2) = Φ_elastic + the dielectric term: what the equations, pole limits and second variation use."""
    return elastic_energy(cls, l1, l2) + electric_energy(cls, l1, l2)


def electric_args(cls: SceneClass) -> list:
    """[Φ̄] for a dielectric class, else []: the runtime parameters of the membrane energy."""
    return [voltage] if cls.electric else []


def meridional_stretch(c, vv, ww, l2=lam2):
    return sp.sqrt((l2 * c + vv) ** 2 + ww**2)


def _field_proxy(rho, z):
    dr, dz = rho - _rho0, z - _eta0
    return Q + Q_r * dr + Q_z * dz + (Q_rr * dr**2 + Q_zz * dz**2) / 2 + Q_rz * dr * dz


def field_values(expr, rho):
    """Evaluate the H² proxy at its own expansion point (after all differentiation)."""
    return expr.subs({_rho0: rho, _eta0: eta})


def energy_density(cls: SceneClass, c=cos_theta, s=sin_theta):
    """π̂ = Π / sin θ (the integrand per d(cos θ)), as a function of the node's (cos θ, sin θ) and state."""
    l1 = meridional_stretch(c, v, w)
    density = membrane_energy(cls, l1, lam2) + P * lam2**2 * w * s / 2
    if cls.field:
        density -= chi * M * _field_proxy(lam2 * s, eta) / 2
    return density


def lagrangian(cls: SceneClass):
    """Π(θ, λ2, v, η, w) per dθ with explicit sin θ, cos θ (for the Euler–Lagrange equations)."""
    return energy_density(cls, sp.cos(theta), sp.sin(theta)) * sp.sin(theta)


def runtime_args(cls: SceneClass):
    """Branch-parameter symbols a kernel of this class takes, in order."""
    params = [P]
    if cls.field:
        params += [M, chi]
    return params + electric_args(cls)
