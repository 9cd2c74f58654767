"""The pressure's work −P V (MODEL.md §2, §8): V = ⅓ ∫∫ x · (x_θ × x_φ) dθ dφ, per 2π.

Axisymmetric form per d(cos θ): ½ P λ2² w sin θ (the enclosed volume as ½ ρ² (−η') per dθ, integrated by
parts); on the whole sphere and in the second variation the cone form −(P/3) x · (x_θ × x_φ) per dθ dφ (per
d(cos θ) divided by sin θ). For an axisymmetric state the two differ pointwise by −(P/6)(ρ²η)'/sin θ, whose
integral vanishes. Continued in P: pressure_gradient, rhs_pressure, surface_pressure_gradient.
"""
from dataclasses import dataclass

import sympy as sp

from ..functional import lam2, sin_theta, w
from ..second_variation import cross, dot, epsilon_order, phi_average
from . import Term

P = sp.Symbol("P", real=True)


def volume_density(x, x_t, x_p):
    """Enclosed-volume density per dθ dφ, (1/3) x · (x_θ × x_φ) (outward normal)."""
    return dot(x, cross(x_t, x_p)) / 3


@dataclass(frozen=True)
class Pressure(Term):
    name = "pressure"
    parameters = (P,)
    continuation = (P, "pressure", "P")

    def axisymmetric(self, c, s, metric):
        return P * lam2**2 * w * s / 2

    def surface(self, point, a_t, a_p, areal):
        return -P * volume_density(point, a_t, a_p)

    def second_order(self, x, x_t, x_p, metric, closed=True):
        """The cone form on a closed surface; on a tube the volume between its end planes, ½ x_h · (x_S × x_φ)
        (codegen/second_variation.py)."""
        density = volume_density(x, x_t, x_p) if closed else dot((x[0], x[1], 0), cross(x_t, x_p)) / 2
        return -P * phi_average(epsilon_order(density, 2)) / sin_theta

    def pole(self, lam, z, q, s, z0, metric):
        return P * lam**2 * q * s**2 / 2


PRESSURE = Pressure()
