"""The reference meridian at run time: the one place the runtime asks what surface the membrane is cut from.

The codegen side (codegen/meridian.py) derives the kernels from the same meridian: over the polar angle
θ ∈ [0, π] the reference hoop radius is R(θ) = sin θ and the height

    sphere     Z(θ) = cos θ,            S'(θ) = 1,
    spheroid   Z(θ) = aspect · cos θ,   S'(θ) = sqrt(cos²θ + aspect² sin²θ),

S' = dS/dθ the rate of the reference arclength (scene.Geometry: ``aspect`` is the polar over the equatorial
semi-axis). Both meridians end at two poles on the axis (R = 0), where the Legendre basis in cos θ is smooth.
On a deformed state (λ2, v = λ2' sin θ, η, w = η'), ρ = λ2 R and the stretches are

    λ2 = ρ/R (hoop),   λ1 = sqrt(ρ'² + η'²)/S' = sqrt((λ2 cos θ + v)² + w²)/S' (meridional),

and the reference encloses V0 = 4π/3 · aspect. A tube (``shape = "tube"``) is a meridian over its arclength
t = S ∈ [0, L] with R = 1, R' = 0, S' = 1 and Z = −S (codegen/meridian.py), discretised in galerkin/interval.py;
it encloses V0 = πL.
"""
import numpy as np

from ..scene.tables import Geometry, Shape


def metric(geometry: Geometry, cos_theta, sin_theta):
    """S' = dS/dt at the node (cos θ, sin θ): ones on the sphere and on a tube (t = S, whose nodes pass R' = 0 and
    R = 1 for (cos θ, sin θ): galerkin/interval.py)."""
    if geometry.shape in (Shape.SPHERE, Shape.TUBE):
        return np.ones_like(np.asarray(cos_theta, dtype=float))
    return np.sqrt(np.square(cos_theta) + np.square(geometry.aspect * np.asarray(sin_theta)))


def meridional_stretch(geometry: Geometry, cos_theta, sin_theta, lam2, v, w):
    """λ1 = sqrt((λ2 cos θ + v)² + w²)/S' with v = λ2' sin θ, w = η' (module docstring)."""
    return np.hypot(lam2 * cos_theta + v, w) / metric(geometry, cos_theta, sin_theta)


def reference_height(geometry: Geometry, t):
    """Z(t) of the reference meridian: aspect · cos θ (its hoop radius is sin θ), or a tube's −S over its arclength
    S = t (its hoop radius is 1; downwards, as the sphere's meridian runs from its north pole)."""
    if geometry.shape == Shape.TUBE:
        return -np.asarray(t, dtype=float)
    return geometry.aspect * np.cos(t)


def kernel_values(geometry: Geometry) -> dict:
    """The meridian's scalar arguments of its class's kernels by name (codegen/meridian.py: ``parameters``): none
    for the sphere, the spheroid's aspect."""
    return {"aspect": float(geometry.aspect)} if geometry.shape == Shape.SPHEROID else {}
