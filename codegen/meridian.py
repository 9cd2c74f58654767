"""The reference meridian of a scene class: the surface of revolution the membrane is cut from, as data.

A meridian is given by its hoop radius R(θ) and height Z(θ) over the polar angle θ ∈ [0, π], with R = sin θ
(zero at both ends: two poles, the Legendre basis in cos θ and the pole series apply):

    sphere     R = sin θ,   Z = cos θ,            S' = 1
    spheroid   R = sin θ,   Z = aspect · cos θ,   S' = g(θ) = sqrt(cos²θ + aspect² sin²θ)

(S' = dS/dθ = sqrt(R'² + Z'²), S the reference arclength; aspect = polar over equatorial semi-axis, a runtime
argument of the kernels). On it the stretches are λ1 = |x'|/S' (meridional) and λ2 = ρ/R (hoop), the reference
area element is R S' dθ dφ: per d(cos θ) every density per reference area carries the factor S' (``metric``),
the pressure's work does not (the enclosed volume is the deformed surface's). The sphere's metric is the number 1,
so its kernels are those derived before the meridian was data, byte for byte.
"""
from dataclasses import dataclass

import sympy as sp

aspect = sp.Symbol("aspect", positive=True)
_theta = sp.Symbol("theta", real=True)


@dataclass(frozen=True)
class Meridian:
    """The sphere; subclasses change ``height`` (and name their runtime scalars in ``parameters``)."""

    name = "sphere"
    parameters: tuple = ()

    def height(self, theta):
        """Z(θ) of the reference meridian (R(θ) = sin θ for every meridian here)."""
        return sp.cos(theta)

    def metric(self, c, s):
        """S' = dS/dθ = sqrt(R'² + Z'²) at the node (cos θ, sin θ) = (c, s), derived from R and Z (simplified:
        the sphere's is 1)."""
        speed = sp.trigsimp(sp.sqrt(sp.diff(sp.sin(_theta), _theta) ** 2 + sp.diff(self.height(_theta), _theta) ** 2))
        return speed.subs({sp.cos(_theta): c, sp.sin(_theta): s})

    def inputs(self) -> dict:
        """Its entries in a module's header: none for the sphere (its modules' headers stay as they were)."""
        return {} if self.name == SPHERE.name else {"shape": self.name}

    def title(self) -> str | None:
        if self.name == SPHERE.name:
            return None
        return f"{self.name} reference (parameters {', '.join(map(str, self.parameters))})"


@dataclass(frozen=True)
class Spheroid(Meridian):
    name = "spheroid"
    parameters: tuple = (aspect,)

    def height(self, theta):
        return aspect * sp.cos(theta)


SPHERE = Meridian()
SPHEROID = Spheroid()
MERIDIANS = {m.name: m for m in (SPHERE, SPHEROID)}
