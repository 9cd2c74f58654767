"""The membrane near the coil wires: its smallest gap to each wire and the basis map that resolves it.

Near a wire the field varies on the scale of the gap, and Legendre series in x converge slowly; a mapped basis
(``galerkin.coordinate_map.WireMap``) clusters the nodes at the membrane's closest approach to each wire.
"""
import numpy as np

from ..galerkin.coordinate_map import WireMap
from ..galerkin.discretisation import Discretisation

MAP_WIDTH = 0.4  # map width ε_j per unit gap to wire j (x units); measured best 0.15–0.5 (docs/numerics.md)
MAP_GAP = 0.5  # wires farther than this from the membrane get no map centre (their field is smooth there)


def _profile(disc: Discretisation, u, n_theta: int):
    theta = np.linspace(0.0, np.pi, n_theta)
    lam2, _, eta, _ = disc.evaluate(u, theta)
    return theta, lam2 * np.sin(theta), eta


def wire_gap(disc: Discretisation, u, coils, n_theta: int = 361) -> tuple[float, int]:
    """Smallest distance from the membrane profile to a coil wire, and the coil index."""
    if not len(coils):
        return np.inf, -1
    _, rho, eta = _profile(disc, u, n_theta)
    gaps = [np.hypot(rho - c.radius, eta - c.height).min() for c in coils]
    return float(min(gaps)), int(np.argmin(gaps))


def wire_map(disc: Discretisation, u, coils, symmetric: bool, n_theta: int = 2001) -> WireMap | None:
    """The map clustering a basis at the membrane's closest approach to each wire within MAP_GAP (centres
    x_j = cos θ_j, mirrored ±x_j for an equator-symmetric basis; widths MAP_WIDTH·gap_j); None if there is no
    such wire."""
    if not len(coils):
        return None
    theta, rho, eta = _profile(disc, u, n_theta)
    centres, widths = [], []
    for c in coils:
        distance = np.hypot(rho - c.radius, eta - c.height)
        j = int(np.argmin(distance))
        if distance[j] >= MAP_GAP:
            continue
        x = float(np.clip(np.cos(theta[j]), -0.999, 0.999))
        for centre in ((x, -x) if symmetric and abs(x) > 1e-3 else (x,)):
            if all(abs(centre - other) > 1e-6 for other in centres):
                centres.append(centre)
                widths.append(MAP_WIDTH * float(distance[j]))
    return WireMap(tuple(centres), tuple(widths)) if centres else None
