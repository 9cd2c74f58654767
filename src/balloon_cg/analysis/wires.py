"""The membrane near the coil wires: its smallest gap to each wire and the basis map that resolves it.

Near a wire the field varies on the scale of the gap, and Legendre series in x converge slowly; a mapped basis
(``galerkin.coordinate_map.WireMap``) clusters the nodes at the membrane's closest approach to each wire.
"""
import numpy as np

from ..galerkin.coordinate_map import WireMap
from ..galerkin.discretisation import Discretisation

# Equator-symmetric layout (primary branches): map width ε_j = MAP_WIDTH · gap_j · |dx/ds|_j, the gap to wire j
# measured in x along the membrane (arc length s, |dx/ds| = sin θ/λ1 at the closest approach), for wires within
# MAP_GAP; measured best 0.6–0.8 at gaps 0.2–1.0 with one and two coils (docs/numerics.md, "The membrane near a wire")
MAP_WIDTH = 0.8
MAP_GAP = 1.5  # wires farther than this from the membrane get no map centre (their field is smooth there)
# General layout (pear branches): the earlier rule ε_j = 0.4 · gap_j within 0.5, kept: the symmetric one moved the
# m = 1 branch point of the TPOM1 pear branches by 5e-8 at stability degree 40, not checked against a reference there
GENERAL_MAP_WIDTH = 0.4
GENERAL_MAP_GAP = 0.5


def _profile(disc: Discretisation, u, n_theta: int):
    """(θ, ρ, z, λ1) of the membrane on an n_theta grid (λ1 = ds/dθ, s the arc length)."""
    theta = np.linspace(0.0, np.pi, n_theta)
    lam2, dlam2, eta, deta = disc.evaluate(u, theta)
    s, c = np.sin(theta), np.cos(theta)
    return theta, lam2 * s, eta, np.hypot(dlam2 * s + lam2 * c, deta)


def wire_gap(disc: Discretisation, u, coils, n_theta: int = 361) -> tuple[float, int]:
    """Smallest distance from the membrane profile to a coil wire, and the coil index."""
    if not len(coils):
        return np.inf, -1
    _, rho, eta, _ = _profile(disc, u, n_theta)
    gaps = [np.hypot(rho - c.radius, eta - c.height).min() for c in coils]
    return float(min(gaps)), int(np.argmin(gaps))


def wire_map(disc: Discretisation, u, coils, symmetric: bool, n_theta: int = 2001) -> WireMap | None:
    """The map clustering a basis at the membrane's closest approach to each wire (centres x_j = cos θ_j; an
    equator-symmetric basis: mirrored ±x_j, wires within MAP_GAP, widths MAP_WIDTH·gap_j·|dx/ds|_j; a general one:
    within GENERAL_MAP_GAP, widths GENERAL_MAP_WIDTH·gap_j); None if there is no such wire."""
    if not len(coils):
        return None
    theta, rho, eta, lam1 = _profile(disc, u, n_theta)
    centres, widths = [], []
    for c in coils:
        distance = np.hypot(rho - c.radius, eta - c.height)
        j = int(np.argmin(distance))
        if distance[j] >= (MAP_GAP if symmetric else GENERAL_MAP_GAP):
            continue
        x = float(np.clip(np.cos(theta[j]), -0.999, 0.999))
        if symmetric:
            width = MAP_WIDTH * float(distance[j]) * float(np.sqrt(1.0 - x * x) / lam1[j])  # |dx/ds| = sin θ/λ1
        else:
            width = GENERAL_MAP_WIDTH * float(distance[j])
        for centre in ((x, -x) if symmetric and abs(x) > 1e-3 else (x,)):
            if all(abs(centre - other) > 1e-6 for other in centres):
                centres.append(centre)
                widths.append(width)
    return WireMap(tuple(centres), tuple(widths)) if centres else None
