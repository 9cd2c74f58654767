"""Incompressible Ogden materials.

Φ = Σ_i (μ_i/α_i)(λ1^α_i + λ2^α_i + λ3^α_i − 3) with moduli in units of μ/2, so that Σ μ_i α_i = 4
(initial shear modulus 2). The presets are the paper's Table 1 plus two classical special cases.
"""

from dataclasses import dataclass, replace

from ..generated import CLASSES, GENERAL_TERMS
from .energies import FAMILIES, PRESET_VALUES, StrainEnergy, family_energy, formula_energy, preset_energy
from .validation import SceneError, did_you_mean, number, show, table

MAX_TERMS = max([GENERAL_TERMS] + [len(a) for a, _ in CLASSES.values() if a is not None])  # generated kernels


@dataclass(frozen=True)
class Material:
    """An Ogden material: terms (μ_i, α_i), i = 1..len(mu)."""

    name: str
    mu: tuple[float, ...]
    alpha: tuple[float, ...]

    @property
    def shear_modulus_sum(self) -> float:
        """Σ μ_i α_i: twice the initial shear modulus (4 for every preset)."""
        return sum(m * a for m, a in zip(self.mu, self.alpha))


ALPHA1 = "alpha1"  # the scene key of the Ogden family α1 (``alpha1_terms``): --set, sweep --vary, critical


def alpha1_terms(mu, alpha, alpha1: float) -> tuple[tuple, tuple]:
    """(μ, α) with α1 replaced and μ1 = (4 − Σ_{i≥2} μ_i α_i)/α1, so that Σ μ_i α_i = 4 stays true: the one-parameter
    family ``alpha1`` names (a sweep's and a critical curve's alike)."""
    rest = sum(m * a for m, a in zip(mu[1:], alpha[1:]))
    return ((4.0 - rest) / alpha1,) + tuple(mu[1:]), (alpha1,) + tuple(alpha[1:])


# Named materials (SPOM/FPOM/TPOM: six-, four-, two-parameter Ogden fits, the paper's Table 1).
PRESETS: dict[str, Material] = {
    m.name: m
    for m in (
        Material("SPOM1", (3.00508, 0.0145, -0.0177), (1.3, 4.0, -2.0)),
        Material("SPOM2", (2.25815, 0.0145, -0.0177), (1.73, 4.0, -2.0)),
        Material("FPOM1", (3.04969, -0.0177), (1.3, -2.0)),
        Material("FPOM2", (2.29168, -0.0177), (1.73, -2.0)),
        Material("TPOM1", (3.07692,), (1.3,)),
        Material("TPOM2", (2.0202,), (1.98,)),
        # Φ = C1 (I1 − 3) with C1 = μ/2 = 1.
        Material("neo-Hookean", (2.0,), (2.0,)),
        # Φ = C1 (I1 − 3) + C2 (I2 − 3) with C1 = μ1/2, C2 = −μ2/2 and C2/C1 = 0.1:
        # μ1 α1 = 4/1.1, μ2 α2 = 0.4/1.1, i.e. μ1 = 1.8181818181818181, μ2 = −0.18181818181818182.
        Material("Mooney-Rivlin", (2 / 1.1, -0.2 / 1.1), (2.0, -2.0)),
    )
}

# Named non-Ogden materials (scene/energies.py: families and their preset parameters).
ENERGY_PRESETS: dict[str, StrainEnergy] = {name: preset_energy(name) for name in PRESET_VALUES}

_KEYS = ("preset", "mu", "alpha", "name", "family", "energy", "parameters")


def get_preset(name: str) -> Material | StrainEnergy:
    """The preset called ``name`` (Ogden or another family), matched case-insensitively; KeyError if none."""
    for key, material in (PRESETS | ENERGY_PRESETS).items():
        if key.lower() == name.lower():
            return material
    raise KeyError(name)


MAX_EXPONENT = 100.0  # docs/scenes.md, Bounds: |an Ogden exponent| (λ^100 at λ = 5 is 8e69, still finite)


def material_from_table(data: dict) -> Material | StrainEnergy:
    """The material of a ``[material]`` table (+ ``name``): ``preset = "NAME"``; Ogden ``mu``/``alpha``;
    ``family = "KEY"`` or ``energy = "FORMULA"``, each with a ``[material.parameters]`` table."""
    data = table("material", data, _KEYS)
    name = data.get("name")
    if name is not None and (not isinstance(name, str) or not name.strip()):
        raise SceneError(f"material.name = {show(name)}: must be a non-empty string")
    given = [k for k in ("preset", "family", "energy") if k in data] + (["mu/alpha"] if {"mu", "alpha"} & set(data)
                                                                       else [])
    if len(given) > 1:
        raise SceneError(f"material.{given[0]} = {show(data.get(given[0]))}: give one of preset, family, energy "
                         f"or mu and alpha (got {', '.join(given)})")
    if "parameters" in data and not {"family", "energy"} & set(data):
        raise SceneError("material.parameters: only with family = \"KEY\" or energy = \"FORMULA\"")
    if "family" in data or "energy" in data:
        return _energy_from_table(data, name)
    if "preset" in data:
        preset = data["preset"]
        try:
            material = get_preset(preset) if isinstance(preset, str) else None
        except KeyError:
            material = None
        if material is None:
            raise SceneError(f"material.preset = {show(preset)}: unknown preset"
                             f"{did_you_mean(preset, PRESETS | ENERGY_PRESETS)}; allowed: "
                             f"{', '.join(PRESETS | ENERGY_PRESETS)}")
        return replace(material, name=name) if name else material
    for key in ("mu", "alpha"):
        if key not in data:
            raise SceneError(f'material.{key} is missing: give preset = "NAME", or both mu = [...] and alpha = [...]')
    mu, alpha = _terms("material.mu", data["mu"]), _terms("material.alpha", data["alpha"])
    if len(mu) != len(alpha):
        raise SceneError(
            f"material.alpha = {show(data['alpha'])}: has length {len(alpha)} but material.mu has length {len(mu)}; "
            "they must match"
        )
    for i, a in enumerate(alpha):
        if a == 0 or abs(a) > MAX_EXPONENT:
            raise SceneError(f"material.alpha[{i}] = {show(data['alpha'][i])}: exponents must be nonzero and within "
                             f"±{MAX_EXPONENT:g}")
    material = Material(name or "custom", mu, alpha)
    if material.shear_modulus_sum <= 0:
        raise SceneError(
            f"material.mu = {show(data['mu'])}: with material.alpha = {show(data['alpha'])}, "
            f"Σ μ_i α_i = {material.shear_modulus_sum:g} must be > 0 (initial shear modulus must be positive)"
        )
    return material


def _energy_from_table(data: dict, name: str | None) -> StrainEnergy:
    """``family = "KEY"`` or ``energy = "FORMULA"`` with ``[material.parameters]`` (name = number)."""
    parameters = data.get("parameters", {})
    if not isinstance(parameters, dict):
        raise SceneError(f"material.parameters = {show(parameters)}: must be a table of name = number")
    values = {k: number(f"material.parameters.{k}", v) for k, v in parameters.items()}
    if "family" in data:
        family = data["family"]
        if family not in FAMILIES:
            raise SceneError(f"material.family = {show(family)}: unknown family; allowed: {', '.join(FAMILIES)}")
        extra = [k for k in values if k not in FAMILIES[family].parameters]
        if extra:
            raise SceneError(f"material.parameters.{extra[0]} = {show(values[extra[0]])}: not a parameter of "
                             f"family {family} ({', '.join(FAMILIES[family].parameters)})")
        return family_energy(family, values, name or family)
    return formula_energy(data["energy"], values, name or "formula")


def _terms(key: str, values) -> tuple[float, ...]:
    """A non-empty list of at most MAX_TERMS finite numbers."""
    if not isinstance(values, (list, tuple)) or not values:
        raise SceneError(f"{key} = {show(values)}: must be a non-empty list of numbers")
    if len(values) > MAX_TERMS:
        raise SceneError(f"{key} = {show(values)}: at most {MAX_TERMS} Ogden terms (got {len(values)})")
    return tuple(number(f"{key}[{i}]", v) for i, v in enumerate(values))


def modified_name(before: Material | StrainEnergy, after: Material | StrainEnergy) -> str:
    """The name of ``after``, the material ``before`` with keys set (``Scene.with_overrides``): ``before``'s name
    while the values are the same, else that name with what changed (``TPOM2 (mu1 = 1)``: the terms numbered
    from 1, a family's parameters by name), or ``custom`` when more than the values changed (the number of
    terms, the family, the formula). A file then never names a preset whose values it did not compute with."""
    if isinstance(before, Material) and isinstance(after, Material) and len(before.mu) == len(after.mu):
        changed = [f"{key}{i + 1} = {new:g}" for key in ("mu", "alpha")
                   for i, (old, new) in enumerate(zip(getattr(before, key), getattr(after, key))) if old != new]
    elif (isinstance(before, StrainEnergy) and isinstance(after, StrainEnergy) and before.family == after.family
          and before.formula == after.formula):
        changed = [f"{key} = {new:g}" for (key, new), old in zip(after.parameters.items(), before.values)
                   if old != new]
    else:
        return "custom"
    return f"{before.name} ({', '.join(changed)})" if changed else before.name
