"""The energy functional of MODEL.md §2 for one scene class: the sum of its energy terms (codegen/terms/).

Π(θ, λ2, v, η, w) = Φ(λ1, λ2) S' sin θ + (the terms' densities) sin θ,   λ1 = sqrt((λ2 cos θ + v)² + w²)/S',

Φ the elastic term's strain energy plus every term that is a function of the stretches (the dielectric one), the
others in the state at the node: ½ P λ2² w sin θ (pressure), −½ χ M H²(ρ, η) (magnetic, ρ = λ2 sin θ), i.e.
for the full set Π = Φ sin θ − ½ χ M H² sin θ + ½ P λ2² w sin² θ on the sphere. S' = dS/dθ is the class's
reference meridian's (codegen/meridian.py: 1 on the sphere, so the sphere's kernels are unchanged); the densities
per reference area (Φ, the field's) carry it, the pressure's work does not.
"""
from dataclasses import dataclass

import sympy as sp

from .meridian import SPHERE, Meridian
from .terms.elastic import Elastic

theta = sp.Symbol("theta", real=True)
cos_theta, sin_theta = sp.symbols("cos_theta sin_theta", real=True)
lam2, v, eta, w = sp.symbols("lam2 v eta w", real=True)
STATE = (lam2, v, eta, w)


@dataclass(frozen=True)
class SceneClass:
    """What a kernel module is specialised to: its elastic term (the material), its further energy terms, in
    kernel order (codegen/classes.py: pressure, then magnetic, then dielectric where present), and its reference
    meridian (codegen/meridian.py)."""

    name: str
    elastic: Elastic
    terms: tuple = ()
    meridian: Meridian = SPHERE

    def inputs(self) -> dict:
        """What the module is generated from (its header): every header says whether the magnetic term is present
        ('field'), the other terms' entries appear only where they are."""
        inputs = {"class": self.name, **self.elastic.inputs(), "field": False}
        for term in self.terms:
            inputs.update(term.inputs())
        return inputs | self.meridian.inputs()

    @property
    def term_names(self) -> tuple:
        """Its terms beyond the elastic one by name, in kernel order (the registry's and the runtime's key)."""
        return tuple(t.name for t in self.terms)

    @property
    def field(self) -> bool:
        """Whether the class has the magnetic term (its header's 'field')."""
        return self.inputs()["field"]

    def title(self, kind: str, surface: bool = False) -> str:
        """The module's title line: ``kind`` (what the module holds), the material, the field, the other terms."""
        phrases = [phrase for t in self.terms if (phrase := t.title(surface))]
        phrases += [phrase for phrase in (self.meridian.title(),) if phrase]
        return f"{kind} {self.name}: {', '.join([self.elastic.title(), f'field {self.field}', *phrases])}."


def membrane_energy(cls: SceneClass, l1, l2):
    """Φ(λ1, λ2): the elastic term plus every term that is a function of the stretches (what the equations, pole
    limits and second variation use)."""
    return cls.elastic.membrane(l1, l2) + sum((t.membrane(l1, l2) for t in cls.terms), sp.S.Zero)


def meridional_stretch(c, vv, ww, l2=lam2):
    return sp.sqrt((l2 * c + vv) ** 2 + ww**2)


def at_node(cls: SceneClass, expr):
    """Put the terms' Taylor proxies back at their own expansion points (after all differentiation), at the node's
    reference radius R (the meridian's: sin θ on a meridian with poles, 1 on a tube)."""
    radius = cls.meridian.hoop(cos_theta, sin_theta)
    expansion = {}
    for term in cls.terms:
        expansion.update(term.expansion(radius))
    return expr.xreplace(expansion)


def energy_density(cls: SceneClass, c=cos_theta, s=sin_theta):
    """π̂ = Π / R (on a meridian with poles the integrand per d(cos θ)), as a function of the node's
    (cos θ, sin θ) and state: Φ(λ1, λ2) S' with λ1 = |x'|/S' = sqrt((λ2 R' + v)² + w²)/S', plus the terms' densities
    (those per reference area times S'), with R', R and S' the meridian's at the node (codegen/meridian.py: the
    sphere's are cos θ, sin θ and 1, a tube's 0, 1 and 1)."""
    meridian = cls.meridian
    metric, rate, radius = meridian.metric(c, s), meridian.hoop_rate(c, s), meridian.hoop(c, s)
    density = membrane_energy(cls, meridional_stretch(rate, v, w) / metric, lam2) * metric
    density = density + sum((t.axisymmetric(rate, radius, metric) for t in cls.terms), sp.S.Zero)
    return meridian.galerkin(density, c, s)


def lagrangian(cls: SceneClass):
    """Π(θ, λ2, v, η, w) per dθ with explicit sin θ, cos θ (for the Euler–Lagrange equations)."""
    return energy_density(cls, sp.cos(theta), sp.sin(theta)) * sp.sin(theta)


def runtime_args(cls: SceneClass) -> list:
    """Scalar symbols a kernel of this class takes, in order: every term's runtime scalars (branch parameters),
    then the meridian's (its shape: the spheroid's aspect)."""
    return [p for term in cls.terms for p in term.parameters] + list(cls.meridian.parameters)


def continuations(cls: SceneClass) -> list:
    """(symbol, word, shown) of every parameter the class's terms are continued in: the ∂/∂parameter kernels."""
    return [term.continuation for term in cls.terms if term.continuation is not None]
