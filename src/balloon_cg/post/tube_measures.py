"""What is measured along a tube's state (galerkin/interval.py's u): the hoop and axial stretches at reference
arclengths S, and the bulge's front, its position and width along the deformed axis.

On the tube R = 1, S' = 1, so λ2 = ρ (hoop) and λ1 = sqrt(ρ'² + η'²) (axial, along the meridian), ' = d/dS; with
x = 2S/L − 1, d/dS = (2/L) d/dx of the Legendre series (the derivative of the discretisation's ``profile``).

Along the deformed axis every figure reads the distance z = η(0) − η(S) from the end S = 0 (``along``): a bulge
branch's bulge forms there (sliding ends: the plane of symmetry of a longer tube), so z is also the distance from the
bulge's middle.

A front joins a bulged part (ρ high) to an unbulged one (ρ low). Its position is the distance z where ρ crosses the
mid level (ρ_max + ρ_min)/2, its width w = (ρ_max − ρ_min)/max|dρ/dz|: for ρ = c + b tanh((z − z_f)/δ) the
position z_f and the width 2δ. A profile has a front where it crosses its mid level once or twice, and the front is
narrower than each part it joins: the parts, the profile beyond half a width on either side of z_f, each at least w
long. Once: z_f ± 1.5 w inside the tube. Twice (a bulge in the middle, or a neck: two fronts, mirror images on a
mirror-symmetric state): the front is the crossing nearest the first sample (S = 0 in ``fronts``), its width from
the slopes up to halfway to the other crossing, its parts the profile from that end (at least 1.5 w from z_f) and
the profile between the crossings (at least 2 w from z_f to the other: a bump narrower than that, such as a coil's
bulge on its way up, has none).
Near a bulge's onset the profile is the mode cos(πS/L) over the whole tube, its mid-level crossing at the middle
with a width 2ℓ/π (ℓ the deformed length), which shrinks to a front's as the bulge localises while V/V0 hardly
changes: drawn against V/V0 that was a spike, and it is no front (nor, in a coil's field, the bump at the coil on
its way to the end).
"""
from dataclasses import dataclass

import numpy as np

from ..scene.tables import Ends

SAMPLES = 4001  # reference arclengths a state's front is sampled at (``fronts``)


@dataclass(frozen=True)
class Front:
    """The front of a profile ρ(z): the height where ρ crosses its mid level, its width (module docstring), and the
    radii it joins."""

    position: float
    width: float
    low: float
    high: float


def stretches(disc, u: np.ndarray, s: np.ndarray) -> tuple:
    """(λ1, λ2), the axial and hoop stretches of the tube's state u at reference arclengths s ∈ [0, L]."""
    x = 2 * np.asarray(s, dtype=float) / disc.length - 1
    functions, slopes, _, bubble_slopes = disc.functions(x)
    k = disc.axial_index
    hoop = functions @ u[:k] + (0.0 if disc.ends == Ends.SLIDING else 1.0)
    hoop_slope = slopes @ u[:k]
    height_slope = -u[k] * disc.length / 2 + bubble_slopes @ u[k + 1:]
    return 2 / disc.length * np.hypot(hoop_slope, height_slope), hoop


def front(z: np.ndarray, rho: np.ndarray) -> Front:
    """The front of the profile ρ(z) sampled at increasing or decreasing z (module docstring): the mid-level crossing
    (the first of two) by linear interpolation between the two samples that bracket it, the largest slope by central
    differences (np.gradient). None (position and width NaN) where the profile is uniform (ρ_max − ρ_min ≤ 1e-12
    ρ_max), crosses its mid level more than twice, or leaves a part shorter than the width (module docstring)."""
    z, rho = np.asarray(z, dtype=float), np.asarray(rho, dtype=float)
    high, low = rho.max(), rho.min()
    none = Front(np.nan, np.nan, float(low), float(high))
    if high - low <= 1e-12 * abs(high):
        return none
    middle = 0.5 * (high + low)
    crossings = np.flatnonzero(np.diff(rho >= middle))
    if crossings.size not in (1, 2):
        return none
    position, *other = (z[j] + (middle - rho[j]) * (z[j + 1] - z[j]) / (rho[j + 1] - rho[j]) for j in crossings)
    half = slice(None) if not other else slice(0, (crossings[0] + crossings[1]) // 2 + 1)
    width = (high - low) / np.abs(np.gradient(rho, z)[half]).max()
    if not other and not z.min() + 1.5 * width <= position <= z.max() - 1.5 * width:
        return none
    if other and (abs(position - z[0]) < 1.5 * width or abs(other[0] - position) < 2 * width):
        return none
    return Front(float(position), float(width), float(low), float(high))


def along(disc, u: np.ndarray, s: np.ndarray) -> tuple:
    """(z, ρ): the distance z = η(0) − η(s) along the deformed axis from the end S = 0 and the radius ρ of the tube's
    state u at reference arclengths s (module docstring)."""
    rho, eta = disc.profile(u, np.concatenate([[0.0], np.asarray(s, dtype=float)]))
    return eta[0] - eta[1:], rho[1:]


def fronts(disc, states) -> tuple:
    """Per state u of ``states``: (its front in the reference arclength S, its front along the deformed axis, at the
    distance z from the end S = 0: ``along``), each ``front`` of the profile sampled at SAMPLES evenly spaced S."""
    s = np.linspace(0.0, disc.length, SAMPLES)
    reference, deformed = [], []
    for u in states:
        z, rho = along(disc, u, s)
        reference.append(front(s, rho))
        deformed.append(front(z, rho))
    return reference, deformed
