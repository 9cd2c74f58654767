"""The second parameter q of a two-parameter continuation: any runtime parameter of the scene's kernels, by name.

Names are the scene's keys (as ``--set`` takes them), looked up in the scene's kernel class, so that a runtime
parameter added to the kernels later needs no change here:

    field.M, field.chi, …     a runtime scalar of the kernels: a 'param' argument of the class's energy_gradient
                              that is a field of ``galerkin.equilibrium.Parameters`` (P excepted; M always),
                              named by the scene key that holds it, or by the bare name where no scene key does
                              (the bare name, e.g. ``M``, is always accepted)
    material.parameters.NAME  a strain energy's named parameter (families: Jm, C20, N, …; a user formula's)
    material.mu[i]            an Ogden modulus
    material.alpha[i]         an Ogden exponent (kernels of the general class: exponents at run time)
    alpha1                    the Ogden family α1 with μ1 = (4 − Σ_{i≥2} μ_i α_i)/α1 (Σ μ_i α_i = 4 kept)

∂R/∂q (``Derivative``): EXACT where a generated kernel gives it (a runtime scalar with a derivative kernel,
``Equilibrium.derivative_kernel``: M's field_gradient, NAME_gradient), else CENTRAL: the central difference
(R(q + h) − R(q − h))/(2h) with h = H_STEP·max(1, |q|) (``branch_point.H_STEP``, relative 1e-6). Ogden exponents,
α1 and a family's positive parameters (``energies.Family.positive``) must not reach 0 (``bound``: the curve
stops there); the runtime scalars M, χ and Φ̄ must not fall below 0 (``nonnegative``: their scene ranges start at 0;
M = I²/(16π²R0²μ) is a square), so the curve stops where one does.
"""
import enum
import re
from dataclasses import dataclass, fields, replace

from ...galerkin.equilibrium import Equilibrium, Parameters
from ...model.kernels import KernelSet
from ...scene.energies import FAMILIES, StrainEnergy
from ...scene.materials import ALPHA1, alpha1_terms
from ...scene.tables import Shape

GENERAL_CLASS = "ogden_general_field"


class UnknownParameter(ValueError):
    """A second-parameter name the scene's kernels do not take; the one-line message lists those they do."""


class Source(enum.StrEnum):
    """Where q enters the kernels."""

    SCALAR = "scalar"  # a runtime scalar argument (Parameters field): M, chi, …
    ENERGY = "energy"  # a strain energy's parameter value (Parameters.material)
    MODULUS = "modulus"  # an Ogden μ_i (Parameters.mu)
    EXPONENT = "exponent"  # an Ogden α_i (Parameters.alpha, general class)
    ALPHA1 = "alpha1"  # α1 with μ1 from Σ μ_i α_i = 4


class Derivative(enum.StrEnum):
    """How ∂R/∂q is computed (module docstring)."""

    EXACT = "exact"  # a generated kernel
    CENTRAL = "central"  # central differences of the residual, step H_STEP·max(1, |q|)


@dataclass(frozen=True)
class SecondParameter:
    """One second parameter of a scene (module docstring): its key, short name (labels, messages), where it
    enters, its index among the material's values or terms, the scene's value q0, how ∂R/∂q is computed, the
    kernel class it needs (None: the scene's), whether q must keep the sign of q0 (``bound``) and whether it must
    not fall below 0 (``nonnegative``: a runtime scalar, M, χ, Φ̄)."""

    key: str
    name: str
    source: Source
    index: int
    q0: float
    derivative: Derivative
    kernel_class: str | None
    bound: bool
    nonnegative: bool = False

    def at(self, params: Parameters, material, q: float) -> Parameters:
        """``params`` with q set; ``material`` is the scene's (the values q does not replace)."""
        q = float(q)
        if self.source == Source.SCALAR:
            return params.with_value(self.name, q)
        if self.source == Source.ENERGY:
            return replace(params, material=_put(material.values, self.index, q))
        if self.source == Source.MODULUS:
            return replace(params, mu=_put(material.mu, self.index, q))
        if self.source == Source.EXPONENT:
            return replace(params, alpha=_put(material.alpha, self.index, q))
        member = alpha1_material(material, q)
        return replace(params, mu=member.mu, alpha=member.alpha)


def alpha1_material(material, alpha1: float):
    """``material`` with α1 replaced and μ1 = (4 − Σ_{i≥2} μ_i α_i)/α1 (Σ μ_i α_i = 4 kept)."""
    mu, alpha = alpha1_terms(material.mu, material.alpha, alpha1)
    return replace(material, name=f"{material.name}(alpha1={alpha1:g})", mu=mu, alpha=alpha)


def _put(values, index: int, q: float) -> tuple:
    values = tuple(map(float, values))
    return values[:index] + (q,) + values[index + 1:]


def runtime_scalars(kernels: KernelSet) -> tuple[str, ...]:
    """The runtime scalars a second parameter can be: M (a class without field terms does not depend on it:
    ``Equilibrium.parameter_derivative`` gives ∂R/∂M = 0, and ``codim2`` refuses it) and the 'param' arguments
    of the kernels' energy_gradient that are Parameters fields, P excepted."""
    bound = {f.name for f in fields(Parameters)} - {"P"}
    args = [name for name, kind, _ in kernels.module.KERNELS["energy_gradient"]["args"]
            if kind == "param" and name in bound]
    return tuple(dict.fromkeys(["M"] + args))


def _scene_key(scene, name: str) -> str:
    """The dotted scene key holding the scalar ``name`` (a number in a table other than material), or ``name``."""
    for table, entries in scene.to_dict().items():
        if table != "material" and isinstance(entries, dict) and isinstance(entries.get(name), (int, float)):
            return f"{table}.{name}"
    return name


def parameter_keys(scene, kernels: KernelSet | None = None) -> dict[str, str]:
    """{accepted name: canonical key} of the scene's second parameters (module docstring): the canonical keys in
    a fixed order, then the bare names of the runtime scalars; ``kernels``: the scene's (default: loaded as
    ``Equilibrium`` does)."""
    scalars = runtime_scalars(KernelSet.of_scene(scene) if kernels is None else kernels)
    material = scene.material
    if isinstance(material, StrainEnergy):
        own = [f"material.parameters.{name}" for name in material.formula.parameters]
    else:
        terms = range(len(material.mu))
        own = [f"material.{which}[{i}]" for which in ("mu", "alpha") for i in terms] + [ALPHA1]
    canonical = [_scene_key(scene, name) for name in scalars] + own
    return {key: key for key in canonical} | {name: _scene_key(scene, name) for name in scalars}


def resolve(scene, key: str, kernels: KernelSet | None = None) -> str:
    """The canonical key of ``key``; UnknownParameter, one line listing the scene's keys, if it names none, or
    naming the shape if it is an Ogden exponent (alpha1, material.alpha[i]: the general kernel class) of a scene
    other than the sphere."""
    keys = parameter_keys(scene, kernels)
    if key not in keys:
        listed = ", ".join(k for k, c in keys.items() if k == c)
        raise UnknownParameter(f"second parameter {key!r}: not a runtime parameter of scene {scene.name}; its "
                               f"parameters: {listed}")
    canonical = keys[key]
    term = _TERM.fullmatch(canonical)
    exponent = canonical == ALPHA1 or (term is not None and term.group(1) == "alpha")
    if exponent and scene.geometry.shape != Shape.SPHERE:
        raise UnknownParameter(f"second parameter {key!r}: an Ogden exponent is followed on the general kernel "
                               f"class, which is committed for the sphere only: scene {scene.name} is a "
                               f"{scene.geometry.shape.value} (allowed: a modulus, material.mu[i], or a runtime scalar)")
    return canonical


_TERM = re.compile(r"material\.(mu|alpha)\[(\d+)\]")


def second_parameter(scene, eq: Equilibrium, params: Parameters, key: str) -> SecondParameter:
    """The second parameter called ``key`` (``parameter_keys``) at the branch parameters ``params``;
    UnknownParameter (one line listing the scene's keys) if there is none."""
    key = resolve(scene, key, eq.kernels)
    material = scene.material
    if key.startswith("material.parameters."):
        name = key.removeprefix("material.parameters.")
        index = material.formula.parameters.index(name)
        positive = material.family is not None and name in FAMILIES[material.family].positive
        return SecondParameter(key, name, Source.ENERGY, index, float(material.values[index]), Derivative.CENTRAL,
                               None, positive)
    if key == ALPHA1:
        return SecondParameter(key, key, Source.ALPHA1, 0, float(material.alpha[0]), Derivative.CENTRAL,
                               GENERAL_CLASS, True)
    term = _TERM.fullmatch(key)
    if term is not None:
        which, index = term.group(1), int(term.group(2))
        exponent = which == "alpha"
        return SecondParameter(key, f"{which}[{index}]", Source.EXPONENT if exponent else Source.MODULUS, index,
                               float(getattr(material, which)[index]), Derivative.CENTRAL,
                               GENERAL_CLASS if exponent else None, exponent)
    name = key.split(".")[-1]
    exact = eq.derivative_kernel(name) is not None
    return SecondParameter(key, name, Source.SCALAR, -1, float(getattr(params, name)),
                           Derivative.EXACT if exact else Derivative.CENTRAL, None, False, nonnegative=True)
