"""The reference meridian at run time: the one place the runtime asks what surface the membrane is cut from.

The codegen side (codegen/meridian.py) derives the kernels from the same meridian: over the polar angle
θ ∈ [0, π] the reference hoop radius is R(θ) = sin θ and the height

    sphere     Z(θ) = cos θ,            S'(θ) = 1,
    spheroid   Z(θ) = aspect · cos θ,   S'(θ) = sqrt(cos²θ + aspect² sin²θ),

S' = dS/dθ the rate of the reference arclength (scene.Geometry: ``aspect`` is the polar over the equatorial
semi-axis). Both meridians end at two poles on the axis (R = 0), where the Legendre basis in cos θ is smooth.
On a deformed state (λ2, v = λ2' sin θ, η, w = η'), ρ = λ2 R and the stretches are

    λ2 = ρ/R (hoop),   λ1 = sqrt(ρ'² + η'²)/S' = sqrt((λ2 R' + v R/sin θ)² + w²)/S' (meridional),

and the reference encloses V0 = 4π/3 · aspect. A capsule (``shape = "capsule"``, its cylinder's ``length`` L) is a
meridian over θ = S/κ, κ = 1 + L/π (S the arclength from the north pole): R = sin κθ on the caps (κθ < π/2 from
either pole), R = 1 on the cylinder, S' = κ, Z = L/2 + cos κθ on the north cap and L/2 − (κθ − π/2) on the
cylinder (mirrored below); it encloses V0 = πL + 4π/3. A tube (``shape = "tube"``) is a meridian over its arclength
t = S ∈ [0, L] with R = 1, R' = 0, S' = 1 and Z = −S (codegen/meridian.py), discretised in galerkin/interval.py;
it encloses V0 = πL.

The membrane's kinetic energy is taken over the reference surface, dA = R S' dθ dφ: its mass densities per
d(cos θ) (generated/inertia.py, codegen/inertia.py) carry S' R/sin θ (``mass_density``). The sphere and the
spheroid have the m ≥ 1 mass kernel (``AZIMUTHAL``), a capsule and a tube do not (their m ≥ 1 blocks have their own
Gram matrices: analysis/stability/capsule_basis.py, tube/azimuthal.py).
"""
import numpy as np

from ..generated import inertia
from ..scene.tables import Geometry, Shape


def capsule_rate(geometry: Geometry) -> float:
    """κ = dS/dθ = 1 + L/π of a capsule."""
    return 1.0 + geometry.length / np.pi


def _capsule_cap(geometry: Geometry, cos_theta):
    """(κ d, σ) at the node: κ times the angle d from the nearer pole, clipped at the join (κ d ≤ π/2), and σ = ±1
    on the north and south halves (θ = acos(cos θ), the south's measured from the south pole as the kernels do)."""
    c = np.asarray(cos_theta, dtype=float)
    kappa = capsule_rate(geometry)
    return np.minimum(kappa * np.arccos(np.abs(c)), np.pi / 2), np.where(c >= 0.0, 1.0, -1.0)


def hoop(geometry: Geometry, cos_theta, sin_theta):
    """R at the node: sin θ on a sphere and a spheroid, a capsule's sin κd (1 on its cylinder)."""
    if geometry.shape != Shape.CAPSULE:
        return np.asarray(sin_theta, dtype=float)
    angle, _ = _capsule_cap(geometry, cos_theta)
    return np.where(angle < np.pi / 2, np.sin(angle), 1.0)


def hoop_rate(geometry: Geometry, cos_theta, sin_theta):
    """R' = dR/dθ at the node: cos θ on a sphere and a spheroid, a capsule's ±κ cos κd (0 on its cylinder)."""
    if geometry.shape != Shape.CAPSULE:
        return np.asarray(cos_theta, dtype=float)
    angle, side = _capsule_cap(geometry, cos_theta)
    return np.where(angle < np.pi / 2, side * capsule_rate(geometry) * np.cos(angle), 0.0)


def hoop_acceleration(geometry: Geometry, cos_theta, sin_theta):
    """R'' = d²R/dθ² at the node: −sin θ on a sphere and a spheroid, a capsule's −κ² sin κd (0 on its cylinder)."""
    if geometry.shape != Shape.CAPSULE:
        return -np.asarray(sin_theta, dtype=float)
    angle, _ = _capsule_cap(geometry, cos_theta)
    return np.where(angle < np.pi / 2, -capsule_rate(geometry) ** 2 * np.sin(angle), 0.0)


def cylinder_elements(geometry: Geometry) -> int:
    """n: the cylinder elements of a capsule's piecewise basis: 1 (``element_length`` not given), else the fewest of
    equal length at most ``element_length`` radii, odd (a middle element about the equator, where a
    mirror-symmetric state is smooth, λ2' = 0 exactly: an element boundary there would leave λ2' its one-sided
    value, ~1e-11 off at L = 10)."""
    if geometry.element_length is None:
        return 1
    n = max(1, int(np.ceil(geometry.length / geometry.element_length - 1e-12)))
    return n + 1 - n % 2


def joins(geometry: Geometry) -> tuple:
    """The x = cos θ where the basis and the quadrature split (galerkin/elements.py, galerkin/discretisation.py
    ``split_rule``), ascending: a capsule's ±cos θj, θj = π/(2κ), where its reference curvature jumps, and between
    them its cylinder's n − 1 inner element boundaries (``cylinder_elements``, ``element_length``) at equal arclength,
    x = sin(ξ_e (π/2 − θj)), ξ_e = (2e − n)/n (none at length 0, the sphere); none on other shapes."""
    if geometry.shape != Shape.CAPSULE or geometry.length == 0:
        return ()
    half_span = np.pi / 2 - np.pi / (2 * capsule_rate(geometry))
    join = float(np.cos(np.pi / (2 * capsule_rate(geometry))))
    n = cylinder_elements(geometry)
    inner = tuple(float(np.sin((2 * e - n) / n * half_span)) for e in range(1, n))
    return (-join, *inner, join)


def metric(geometry: Geometry, cos_theta, sin_theta):
    """S' = dS/dt at the node (cos θ, sin θ): ones on the sphere and on a tube (t = S, whose nodes pass R' = 0 and
    R = 1 for (cos θ, sin θ): galerkin/interval.py), κ on a capsule."""
    ones = np.ones_like(np.asarray(cos_theta, dtype=float))
    if geometry.shape in (Shape.SPHERE, Shape.TUBE):
        return ones
    if geometry.shape == Shape.CAPSULE:
        return capsule_rate(geometry) * ones
    return np.sqrt(np.square(cos_theta) + np.square(geometry.aspect * np.asarray(sin_theta)))


def area_density(geometry: Geometry, cos_theta, sin_theta):
    """dA/(dφ d(cos θ)) = R S'/sin θ of the reference at the nodes (``hoop``, ``metric``): 1 on the sphere,
    sqrt(cos²θ + aspect² sin²θ) on the spheroid, κ sin κd/sin θ on a capsule's caps and κ/sin θ on its cylinder. The
    weight of a held balloon's centroid, ∫δη dA = 0 (analysis/stability/axisymmetric.py ``held_means``, banded.py,
    galerkin/discretisation.py's held general basis). A tube's meridian is no closed surface over cos θ."""
    if geometry.shape == Shape.TUBE:
        raise ValueError("area_density: shape 'tube' is not a meridian over cos θ; allowed: sphere, spheroid, capsule")
    if geometry.shape != Shape.CAPSULE:
        return metric(geometry, cos_theta, sin_theta)
    return hoop(geometry, cos_theta, sin_theta) * metric(geometry, cos_theta, sin_theta) / np.asarray(sin_theta)


def reference_area(geometry: Geometry) -> float:
    """A/2π = ∫ ``area_density`` d(cos θ) over [−1, 1] in closed form: 2 on the sphere; 2 + L on a capsule (two
    hemispheres and its cylinder of length L); on the spheroid of aspect c, 1 + c² artanh(e)/e with e² = 1 − c²
    (c < 1) and 1 + c arcsin(e)/e with e² = 1 − 1/c² (c > 1)."""
    if geometry.shape == Shape.TUBE:
        raise ValueError("reference_area: shape 'tube' is not a meridian over cos θ; allowed: sphere, spheroid, "
                         "capsule")
    if geometry.shape == Shape.CAPSULE:
        return 2.0 + float(geometry.length)
    c = float(geometry.aspect) if geometry.shape == Shape.SPHEROID else 1.0
    if c == 1.0:
        return 2.0
    if c < 1.0:
        e = np.sqrt(1.0 - c * c)
        return 1.0 + c * c * np.arctanh(e) / e
    e = np.sqrt(1.0 - 1.0 / (c * c))
    return 1.0 + c * np.arcsin(e) / e


def meridional_stretch(geometry: Geometry, cos_theta, sin_theta, lam2, v, w):
    """λ1 = sqrt((λ2 R' + v R/sin θ)² + w²)/S' with v = λ2' sin θ, w = η' (module docstring)."""
    if geometry.shape == Shape.CAPSULE:
        radius, s = hoop(geometry, cos_theta, sin_theta), np.asarray(sin_theta, dtype=float)
        # R/sin θ, κ at the poles (R = sin κθ there): v R/sin θ = λ2' R
        ratio = np.divide(radius, s, out=np.full(np.broadcast(radius, s).shape, capsule_rate(geometry)), where=s > 0)
        rate = lam2 * hoop_rate(geometry, cos_theta, sin_theta) + v * ratio
        return np.hypot(rate, w) / metric(geometry, cos_theta, sin_theta)
    return np.hypot(lam2 * cos_theta + v, w) / metric(geometry, cos_theta, sin_theta)


def reference_height(geometry: Geometry, t):
    """Z(t) of the reference meridian: aspect · cos θ (its hoop radius is sin θ), a capsule's (module docstring), or
    a tube's −S over its arclength S = t (its hoop radius is 1; downwards, as the sphere's meridian runs from its
    north pole)."""
    if geometry.shape == Shape.TUBE:
        return -np.asarray(t, dtype=float)
    if geometry.shape == Shape.CAPSULE:
        t = np.asarray(t, dtype=float)
        kappa, half = capsule_rate(geometry), geometry.length / 2
        north, south = kappa * t, kappa * (np.pi - t)
        return np.where(north < np.pi / 2, half + np.cos(north),
                        np.where(south < np.pi / 2, -half - np.cos(south), half - north + np.pi / 2))
    return geometry.aspect * np.cos(t)


def kernel_values(geometry: Geometry) -> dict:
    """The meridian's scalar arguments of its class's kernels by name (codegen/meridian.py: ``parameters``): none
    for the sphere, the spheroid's aspect, the capsule's length."""
    if geometry.shape == Shape.SPHEROID:
        return {"aspect": float(geometry.aspect)}
    if geometry.shape == Shape.CAPSULE:
        return {"length": float(geometry.length)}
    return {}


AZIMUTHAL = (Shape.SPHERE, Shape.SPHEROID)  # the shapes with the m ≥ 1 mass kernel (codegen/inertia.py: ``analytic``)


def mass_density(geometry: Geometry, block: str, cos_theta, sin_theta) -> np.ndarray:
    """∂²t of the kinetic energy at the nodes (cos θ, sin θ), ``block`` 'axisymmetric' (rows of energy_hessian's
    layout) or 'azimuthal' (azimuthal_hessian's; ``AZIMUTHAL`` shapes only): the sphere's kernel,
    t = ½(R² λ̇2² + η̇²) S' with R = sin θ and S' = 1, also a tube's (its nodes pass R' = 0, R = 1 for cos θ, sin θ
    and its S' is 1), or the spheroid's and the capsule's, whose densities carry their S' R/sin θ
    (generated/inertia.py)."""
    own = geometry.shape not in (Shape.SPHERE, Shape.TUBE)
    name = f"{geometry.shape.value}_{block}_mass" if own else f"{block}_mass"
    cos_theta = np.ascontiguousarray(cos_theta, dtype=float)
    out = np.empty((len(inertia.KERNELS[name]["outputs"]), cos_theta.size))
    getattr(inertia, f"{name}_nodes")(cos_theta, np.ascontiguousarray(sin_theta, dtype=float),
                                      *kernel_values(geometry).values(), out)
    return out
