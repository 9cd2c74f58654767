"""Isotropic incompressible strain energies beyond Ogden: named families and user formulas.

Every energy is a formula (``scene/formula.py``) Φ(λ1, λ2) in the units of MODEL.md §2 (moduli in units of μ/2;
the initial shear modulus is μ0 = (Φ11 − Φ12)/2 at λ1 = λ2 = 1, 2 for the neo-Hookean Φ = I1 − 3) with named
parameters that the kernels take at run time. A family's formula is fixed and its kernels are committed in
generated/; a user formula (``[material] energy = "..."``) gets its kernels generated on first use
(model/kernel_cache.py). The formulas are in docs/scenes.md.
"""
import cmath
from dataclasses import dataclass

import numpy as np

from .formula import Formula, domain_conditions, evaluate, parse_formula
from .validation import SceneError, show


@dataclass(frozen=True)
class Family:
    """A named energy: its formula, parameter names (in kernel order) and the parameters that must be > 0."""

    key: str
    formula: str
    parameters: tuple[str, ...]
    positive: tuple[str, ...]


FAMILIES = {
    f.key: f
    for f in (
        # Rivlin polynomial Σ C_ij (I1 − 3)^i (I2 − 3)^j: Mooney–Rivlin (C10, C01), Yeoh (C10, C20, C30)
        Family("rivlin", "C10*(I1 - 3) + C01*(I2 - 3) + C20*(I1 - 3)**2 + C11*(I1 - 3)*(I2 - 3)"
                         " + C02*(I2 - 3)**2 + C30*(I1 - 3)**3",
               ("C10", "C01", "C20", "C11", "C02", "C30"), ()),
        # Gent (1996): limiting chain extensibility I1 − 3 < Jm
        Family("gent", "-(mu*Jm/2)*log(1 - (I1 - 3)/Jm)", ("mu", "Jm"), ("mu", "Jm")),
        # Gent–Gent (Pucci & Saccomandi 2002): Gent plus C2 ln(I2/3)
        Family("gent_gent", "-(mu*Jm/2)*log(1 - (I1 - 3)/Jm) + C2*log(I2/3)", ("mu", "Jm", "C2"),
               ("mu", "Jm")),
        # Arruda–Boyce 8-chain, inverse Langevin by Cohen's rounded Padé L⁻¹(x) ≈ x(3 − x²)/(1 − x²):
        # Φ = μN ∫ L⁻¹(x) dx = μN (x²/2 − ln(1 − x²)) + const with x² = I1/(3N) (chain stretch²/N)
        Family("arruda_boyce", "mu*(I1 - 3)/6 - mu*N*log((3*N - I1)/(3*N - 3))", ("mu", "N"), ("mu",)),
    )
}


@dataclass(frozen=True)
class StrainEnergy:
    """A non-Ogden material: ``family`` (a FAMILIES key) or None for a user formula, the checked formula and
    its parameter values (in the order of ``formula.parameters``)."""

    name: str
    family: str | None
    formula: Formula
    values: tuple[float, ...]

    @property
    def parameters(self) -> dict:
        return dict(zip(self.formula.parameters, self.values))

    @property
    def shear_modulus(self) -> float:
        """μ0 = (Φ11 − Φ12)/2 at λ1 = λ2 = 1 (2 for neo-Hookean), by central differences of complex-step Φ1."""
        step = 1e-4
        return (_phi1(self, 1 + step, 1 - step) - _phi1(self, 1 - step, 1 + step)) / (4 * step)

    def domain_violation(self, margins: np.ndarray, lam1: np.ndarray, lam2: np.ndarray) -> tuple[int, str] | None:
        """None if every state is in the energy's domain, else the first failing state i and what fails there
        ('log argument <text> = <value> (λ1 = …, λ2 = …)'); ``margins`` row k is the argument of
        formula.domain_conditions entry k at the states (λ1[i], λ2[i]) (the class's domain_margins kernel)."""
        for (function, _, text), argument in zip(domain_conditions(self.formula), margins):
            bad = ~(argument > 0) if function == "log" else ~(argument >= 0)
            if np.any(bad):
                i = int(np.argmax(bad))
                return i, f"{function} argument {text} = {argument[i]:.6g} (λ1 = {lam1[i]:.6g}, λ2 = {lam2[i]:.6g})"
        return None

    def to_table(self) -> dict:
        """The ``[material]`` table that gives this energy back (family or formula, with its parameters)."""
        source = {"energy": self.formula.text} if self.family is None else {"family": self.family}
        return {"name": self.name, **source, "parameters": self.parameters}

    def phi(self, lam1, lam2) -> complex:
        return evaluate(self.formula, self.parameters, lam1, lam2)


# Presets: moduli in units of μ/2 with initial shear modulus μ0 = 2 (as every Ogden preset).
_JM_GENT = 97.2  # Gent (1996): Jm = 97.2 fits Treloar's natural-rubber data
_N_AB = 26.5  # Arruda & Boyce (1993): √N = 5.15 for Treloar's data
PRESET_VALUES = {
    # Mooney–Rivlin in invariants, the same material as the Ogden preset "Mooney-Rivlin": C2/C1 = 0.1
    "Mooney-Rivlin-I": ("rivlin", (1 / 1.1, 0.1 / 1.1, 0.0, 0.0, 0.0, 0.0)),
    # Yeoh cubic in I1 − 3 (illustrative ratios C20/C10 = −0.01, C30/C10 = 3e-4: softening then stiffening)
    "Yeoh": ("rivlin", (1.0, 0.0, -0.01, 0.0, 0.0, 3e-4)),
    "Gent": ("gent", (2.0, _JM_GENT)),
    # Gent–Gent with the Gent preset's Jm and the Mooney–Rivlin preset's small-strain ratio (2C2/3)/mu = 0.1
    "Gent-Gent": ("gent_gent", (2 / 1.1, _JM_GENT, 0.3 / 1.1)),
    # μ0 = mu (3N − 1)/(3N − 3) for the Padé energy: mu chosen so that μ0 = 2
    "Arruda-Boyce": ("arruda_boyce", (2 * (3 * _N_AB - 3) / (3 * _N_AB - 1), _N_AB)),
}

_CHECK_POINTS = ((1.1, 0.95), (1.3, 1.05))
_TOLERANCE = 1e-10


def family_energy(family: str, values, name: str, key: str = "material") -> StrainEnergy:
    """The StrainEnergy of FAMILIES[family] with parameter ``values`` (dict or tuple in order), checked."""
    spec = FAMILIES[family]
    if isinstance(values, dict):
        missing = [p for p in spec.parameters if p not in values]
        if missing:
            raise SceneError(f"{key}.parameters.{missing[0]} is missing; family {family} takes "
                             f"{', '.join(spec.parameters)}")
        values = tuple(values[p] for p in spec.parameters)
    energy = StrainEnergy(name, family, parse_formula(spec.formula, spec.parameters), tuple(map(float, values)))
    for p in spec.positive:
        if not energy.parameters[p] > 0:
            raise SceneError(f"{key}.parameters.{p} = {show(energy.parameters[p])}: must be > 0")
    if family == "arruda_boyce" and not energy.parameters["N"] > 1:
        raise SceneError(f"{key}.parameters.N = {show(energy.parameters['N'])}: must be > 1 (chain stretch "
                         "1/√N < 1 in the reference state)")
    return check_reference_state(energy, key)


def formula_energy(text, parameters: dict, name: str, key: str = "material") -> StrainEnergy:
    """A user formula with named parameter values, checked."""
    formula = parse_formula(text, tuple(parameters), f"{key}.energy")
    return check_reference_state(StrainEnergy(name, None, formula, tuple(parameters.values())), key)


def _phi1(energy: StrainEnergy, lam1, lam2, step=1e-20) -> float:
    """∂Φ/∂λ1 by the complex step (exact to rounding for analytic Φ)."""
    return energy.phi(complex(lam1, step), lam2).imag / step


def check_reference_state(energy: StrainEnergy, key: str) -> StrainEnergy:
    """SceneError naming the failed check unless Φ(1, 1) = 0, ∂Φ/∂λ1(1, 1) = 0 (stress-free), μ0 > 0 and Φ is
    isotropic (symmetric in λ1, λ2, λ3 = 1/(λ1λ2)) at two sample states."""
    where = f"{key}.energy = {show(energy.formula.text)}"
    try:
        w0, s0, mu0 = energy.phi(1.0, 1.0), _phi1(energy, 1.0, 1.0), energy.shear_modulus
        samples = [(energy.phi(a, b), energy.phi(b, a), energy.phi(a, 1 / (a * b))) for a, b in _CHECK_POINTS]
    except (ArithmeticError, ValueError) as e:
        raise SceneError(f"{where}: cannot be evaluated near λ1 = λ2 = 1 ({e})") from None
    scale = max(1.0, abs(mu0))
    if not (cmath.isfinite(w0) and abs(w0) <= _TOLERANCE * scale):
        raise SceneError(f"{where}: W(1, 1) = {w0.real:.3g}, must be 0 in the reference state")
    if not abs(s0) <= _TOLERANCE * scale:
        raise SceneError(f"{where}: ∂W/∂λ1(1, 1) = {s0:.3g}, must be 0 (stress-free reference state)")
    if not mu0 > 0:
        raise SceneError(f"{where}: initial shear modulus (Φ11 − Φ12)/2 = {mu0:.3g} at λ = 1, must be > 0")
    for (a, b), (w, swapped, third) in zip(_CHECK_POINTS, samples):
        if abs(w - swapped) > 1e-9 * max(1.0, abs(w)) or abs(w - third) > 1e-9 * max(1.0, abs(w)):
            raise SceneError(f"{where}: not isotropic: W changes when λ1 = {a}, λ2 = {b}, λ3 = 1/(λ1λ2) are "
                             "permuted; write it in I1, I2 or symmetrically in λ1, λ2, λ3")
    return energy


def preset_energy(name: str) -> StrainEnergy:
    family, values = PRESET_VALUES[name]
    return family_energy(family, values, name)
