"""What is measured along a tube's state (galerkin/interval.py's u): the hoop and axial stretches at reference
arclengths S, and the bulge's front, its position and width along the deformed axis.

On the tube R = 1, S' = 1, so λ2 = ρ (hoop) and λ1 = sqrt(ρ'² + η'²) (axial, along the meridian), ' = d/dS; with
x = 2S/L − 1, d/dS = (2/L) d/dx of the Legendre series (the derivative of the discretisation's ``profile``).

A front joins a bulged part (ρ high) to an unbulged one (ρ low). Its position is the height z where ρ crosses the
mid level (ρ_max + ρ_min)/2, its width w = (ρ_max − ρ_min)/max|dρ/dz|: for ρ = c + b tanh((z − z_f)/δ) the
position z_f and the width 2δ.
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
    """The front of the profile ρ(z) sampled at increasing or decreasing heights z (module docstring): the mid-level
    crossing by linear interpolation between the samples that bracket it (the first, from the largest ρ's side),
    the largest slope by central differences (np.gradient). A uniform profile (ρ_max − ρ_min ≤ 1e-12 ρ_max) has
    none: position and width NaN."""
    z, rho = np.asarray(z, dtype=float), np.asarray(rho, dtype=float)
    high, low = rho.max(), rho.min()
    if high - low <= 1e-12 * abs(high):
        return Front(np.nan, np.nan, float(low), float(high))
    middle, top = 0.5 * (high + low), int(np.argmax(rho))
    below = np.flatnonzero(rho < middle)
    after = below[below > top]
    i = after[0] if after.size else below[below < top][-1] + 1  # ρ[i − 1] ≥ middle > ρ[i] or the reverse
    j = i - 1
    position = z[j] + (middle - rho[j]) * (z[i] - z[j]) / (rho[i] - rho[j])
    return Front(float(position), float((high - low) / np.abs(np.gradient(rho, z)).max()), float(low), float(high))


def fronts(disc, states) -> tuple:
    """Per state u of ``states``: (its front in the reference arclength S, its front along the deformed axis measured
    from the end η(0)), each ``front`` of the profile sampled at SAMPLES evenly spaced S."""
    s = np.linspace(0.0, disc.length, SAMPLES)
    reference, deformed = [], []
    for u in states:
        rho, eta = disc.profile(u, s)
        reference.append(front(s, rho))
        deformed.append(front(eta[0] - eta, rho))
    return reference, deformed
