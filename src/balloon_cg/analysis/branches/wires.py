"""The membrane near the coil wires: its smallest gap to each wire and the basis map that resolves it.

Near a wire the field varies on the scale of the gap, and Legendre series in x converge slowly; a mapped basis
(``galerkin.coordinate_map.WireMap``) clusters the nodes at the membrane's closest approach to each wire.
"""
from dataclasses import dataclass

import numpy as np

from ...galerkin.coordinate_map import WireMap
from ...galerkin.discretisation import Discretisation
from ...galerkin.profiles import meridional_stretch
from ...model.meridian import hoop
from ...scene.tables import Geometry

# Map width ε_j = gap_j · clip(MAP_ARC_WIDTH · |dx/ds|_j, MAP_MIN_WIDTH, MAP_WIDTH) (x units) for each wire
# within MAP_GAP of the membrane. benchmarks/results/wire_map_widths.txt (cheapest degree for P to 1e-8, gaps
# 0.05–2, three coil scenes): the best width is ~0.8 × the gap measured along the membrane (0.8·gap·|dx/ds|)
# where the membrane is stretched (|dx/ds| ≤ 0.5: the a = 4 coil, 0.21–0.27 × gap in x: degree 28 against 64
# for 0.4·gap at gap 0.17), and never wider than 0.4·gap in x: where λ1 drops next to the wire (|dx/ds| up to
# 1.15, the paper coil at gap 0.05) the layer is narrower than the gap (0.8·gap·|dx/ds| needs degree 320,
# 0.4·gap 160, 0.15·gap 64).
MAP_ARC_WIDTH = 0.8  # map width per unit gap along the membrane, |dx/ds|·gap
MAP_WIDTH = 0.4  # largest map width per unit gap in x
MAP_MIN_WIDTH = 0.1  # smallest (the narrowest studied): |dx/ds| → 0 at a pole, where x = cos θ is quadratic in s
MAP_GAP = 2.0  # wires farther than this get no map centre (up to 2 no point needs a higher degree mapped than plain)


@dataclass(frozen=True)
class Approach:
    """The membrane's closest approach to one wire: x = cos θ there, the gap, and |dx/ds| = sin θ/|x'| there
    (s the arclength along the deformed meridian; |x'| = ds/dθ, λ1 on the sphere: ``meridional_stretch`` on
    its default geometry)."""

    x: float
    gap: float
    dx_ds: float


def _profile(disc: Discretisation, u, n_theta: int, geometry: Geometry = Geometry()):
    """θ on n_theta points, ρ = λ2 R (R = sin θ but on a capsule: model/meridian.py) and η there, and
    (λ2, λ2', η') there for the stretch λ1 (``approaches`` only: ``wire_gap`` runs at every continuation step and
    needs no λ1)."""
    theta = np.linspace(0.0, np.pi, n_theta)
    lam2, dlam2, eta, deta = disc.evaluate(u, theta)
    return theta, lam2 * hoop(geometry, np.cos(theta), np.sin(theta)), eta, (lam2, dlam2, deta)


def wire_gap(disc: Discretisation, u, coils, geometry: Geometry = Geometry(), n_theta: int = 361) -> tuple[float, int]:
    """Smallest distance from the membrane profile (on the reference ``geometry``) to a coil wire, and the coil
    index."""
    if not len(coils):
        return np.inf, -1
    _, rho, eta, _ = _profile(disc, u, n_theta, geometry)
    gaps = [np.hypot(rho - c.radius, eta - c.height).min() for c in coils]
    return float(min(gaps)), int(np.argmin(gaps))


def approaches(disc: Discretisation, u, coils, n_theta: int = 2001) -> list[Approach]:
    """The closest approach of the membrane profile to each wire of ``coils``, in their order."""
    theta, rho, eta, fields = _profile(disc, u, n_theta)
    lam1 = meridional_stretch(theta, *fields)
    out = []
    for c in coils:
        j = int(np.argmin(np.hypot(rho - c.radius, eta - c.height)))
        out.append(Approach(float(np.cos(theta[j])), float(np.hypot(rho[j] - c.radius, eta[j] - c.height)),
                            float(np.sin(theta[j]) / lam1[j])))
    return out


def surface_approaches(state: np.ndarray, cos_theta: np.ndarray, coils) -> list[Approach]:
    """The closest approach of a whole-sphere state to each wire of ``coils``, over its nodes: ``state`` the node
    rows (x, a_θ, a_φ; surface.basis), ``cos_theta`` the material cos θ of each node; |dx/ds| = sin θ/|a_θ|
    there (|a_θ| the meridional stretch)."""
    x, a_theta = state[:3], state[3:6]
    rho = np.hypot(x[0], x[1])
    out = []
    for c in coils:
        j = int(np.argmin(np.hypot(rho - c.radius, x[2] - c.height)))
        out.append(Approach(float(cos_theta[j]), float(np.hypot(rho[j] - c.radius, x[2, j] - c.height)),
                            float(np.sqrt(1.0 - cos_theta[j] ** 2) / np.linalg.norm(a_theta[:, j]))))
    return out


def map_width(approach: Approach) -> float | None:
    """The map width ε_j (x units) for one closest approach, None if the wire gets no map centre."""
    if approach.gap >= MAP_GAP:
        return None
    return approach.gap * float(np.clip(MAP_ARC_WIDTH * approach.dx_ds, MAP_MIN_WIDTH, MAP_WIDTH))


def centred_map(found: list[Approach], widths, symmetric: bool) -> WireMap | None:
    """The map with a centre x_j = cos θ_j (mirrored ±x_j for an equator-symmetric basis) of width ε_j per
    approach whose width is not None; None if there is none."""
    centres, kept = [], []
    for a, width in zip(found, widths):
        if width is None:
            continue
        x = float(np.clip(a.x, -0.999, 0.999))
        for centre in ((x, -x) if symmetric and abs(x) > 1e-3 else (x,)):
            if all(abs(centre - other) > 1e-6 for other in centres):
                centres.append(centre)
                kept.append(float(width))
    return WireMap(tuple(centres), tuple(kept)) if centres else None


def wire_map(disc: Discretisation, u, coils, symmetric: bool, n_theta: int = 2001) -> WireMap | None:
    """The map clustering a basis at the membrane's closest approach to each wire (``map_width``); None if no
    wire gets a centre, or on a capsule's piecewise basis (``disc.joins``: a map of its elements is not built, so
    its degree alone resolves a layer next to a wire)."""
    if not len(coils) or disc.joins:
        return None
    found = approaches(disc, u, coils, n_theta)
    return centred_map(found, [map_width(a) for a in found], symmetric)
