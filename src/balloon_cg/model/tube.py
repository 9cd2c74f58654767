"""The uniformly inflated tube with closed, sliding ends: the state a tube's bulge bifurcates from (docs/tubes.md).

A cylinder of reference radius 1 inflated to the hoop stretch λθ (radius λθ) and the axial stretch λz, both
uniform; its ends are closed by plugs that carry the pressure on their faces and slide freely (no axial force
beyond the plugs' load). Per 2π and per unit reference length the energy is (MODEL.md §2 units: Φ in μ/2,
P = P̄R/(T0 μ/2), the tube's radius R for the sphere's)

    e(λθ, λz; P) = Φ(λz, λθ) − ½ P λθ² λz          (λ1 = λz meridional, λ2 = λθ hoop),

and its stationarity gives the hoop balance and the closed-end axial balance

    P = Φ_2/(λθ λz),        N = Φ_1 − ½ P λθ² = Φ_1 − λθ Φ_2/(2 λz) = 0.

So the uniform path is λz(λθ) from N = 0 and P(λθ) along it. Its pressure maximum is the limit point under
pressure control and, for a long tube, the onset of bulging (Yu & Fu: det ∂(P, N)/∂(λθ, λz) = 0), where along
N = 0

    dP/dλθ = P_θ − P_z N_θ/N_z = det ∂(P, N)/∂(λθ, λz) / N_z = 0,

with P_θ = Φ_22/(λθλz) − P/λθ, P_z = Φ_12/(λθλz) − P/λz, N_θ = Φ_12 − (Φ_2 + λθΦ_22)/(2λz),
N_z = Φ_11 − λθ(Φ_12 − Φ_2/λz)/(2λz). On a tube of length L the bulge mode cos(nπS/L) sets in where
``bulge_condition`` changes sign (``bulge_onset``), which tends to the pressure maximum as 1/L².

A bulge on a long closed tube propagates at Maxwell's pressure P_M (``maxwell_pressure``): its front joins two
uniform states a (λθ below the pressure maximum) and b (beyond the pressure minimum) at the same P, and the first
integral of the axial translation, H = λ1Φ_1 − Φ (constant along the meridian; ρ'∂π/∂ρ' + η'∂π/∂η' − π with the
pressure's term, linear in η', dropping out), is the same on both: on a uniform state with N = 0 it is −e, so
e(a) = e(b) (Φ_1 = ½Pλθ² there), which along N = 0 is the equal-area rule ∫_a^b (P − P_M) d(λθ²λz) = 0.
"""
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from .membrane import stretch_derivatives

TOLERANCE = 1e-15  # brentq's relative tolerance on the stretches (xtol and rtol)
_BRACKET_GROWTH = 60  # doublings of the axial bracket before giving up
_SCAN_POINTS = 400  # hoop stretches scanned for the pressure maximum


@dataclass(frozen=True)
class UniformTube:
    """A uniform state: hoop stretch λθ, axial stretch λz, pressure P."""

    hoop: float
    axial: float
    pressure: float


def hoop_pressure(material, hoop, axial):
    """P = Φ_2(λz, λθ)/(λθ λz): the pressure that holds the radius λθ at the axial stretch λz."""
    return stretch_derivatives(material, axial, hoop)["phi_2"] / (hoop * axial)


def axial_force(material, hoop, axial):
    """N = Φ_1 − λθ Φ_2/(2λz) (per 2π and per unit reference circumference, at the hoop-balancing pressure):
    the axial membrane force beyond the plugs' pressure load; zero on a closed tube with sliding ends."""
    d = stretch_derivatives(material, axial, hoop)
    return d["phi_1"] - hoop * d["phi_2"] / (2 * axial)


def closed_end_state(material, hoop: float) -> UniformTube:
    """The uniform state of hoop stretch λθ with N = 0 (brentq in λz from the bracket [1/2, 2], doubled outwards
    until N changes sign); ValueError where no axial stretch balances it."""
    low, high = 0.5, 2.0
    for _ in range(_BRACKET_GROWTH):
        if axial_force(material, hoop, low) < 0 < axial_force(material, hoop, high):
            axial = brentq(lambda z: axial_force(material, hoop, z), low, high, xtol=TOLERANCE, rtol=TOLERANCE)
            return UniformTube(float(hoop), float(axial), float(hoop_pressure(material, hoop, axial)))
        low, high = low / 2, high * 2
    raise ValueError(f"no axial stretch balances the closed tube at the hoop stretch {hoop:g}")


def closed_end_axial(material, hoops) -> np.ndarray:
    """λz of the closed-end path N = 0 at each of the hoop stretches ``hoops`` at once (the scans' grid): the root
    ``closed_end_state`` finds one at a time, here by bisection from the same brackets (each [1/2, 2] doubled outwards
    until N changes sign) to the same relative width; NaN where no axial stretch balances one (the path has ended
    there: a charged membrane past its pull-in, model/membrane.Charged)."""
    hoops = np.asarray(hoops, dtype=float)
    low, high = np.full(hoops.shape, 0.5), np.full(hoops.shape, 2.0)
    for _ in range(_BRACKET_GROWTH):
        open_ = ~((axial_force(material, hoops, low) < 0) & (axial_force(material, hoops, high) > 0))
        if not open_.any():
            break
        low[open_], high[open_] = low[open_] / 2, high[open_] * 2
    while np.any((high - low > TOLERANCE * high) & ~open_):
        mid = (low + high) / 2
        above = axial_force(material, hoops, mid) > 0
        high, low = np.where(above, mid, high), np.where(above, low, mid)
    return np.where(open_, np.nan, (low + high) / 2)


def pressure_slope(material, hoop: float) -> float:
    """dP/dλθ along the closed-end path N = 0 (module docstring)."""
    state = closed_end_state(material, hoop)
    return float(_path_slope(material, state.hoop, state.axial))


def _path_slope(material, theta, z):
    """dP/dλθ = P_θ − P_z N_θ/N_z at closed-end states (λθ, λz) (broadcast)."""
    d = stretch_derivatives(material, z, theta)
    P = d["phi_2"] / (theta * z)
    P_theta = d["phi_22"] / (theta * z) - P / theta
    P_z = d["phi_12"] / (theta * z) - P / z
    N_theta = d["phi_12"] - (d["phi_2"] + theta * d["phi_22"]) / (2 * z)
    N_z = d["phi_11"] - theta * (d["phi_12"] - d["phi_2"] / z) / (2 * z)
    return P_theta - P_z * N_theta / N_z


def _on_path(material, hoops: np.ndarray) -> tuple:
    """(λθ, λz) of the grid ``hoops`` (ascending) up to where the closed-end path ends (``closed_end_axial``: NaN
    beyond)."""
    axial = closed_end_axial(material, hoops)
    ended = np.flatnonzero(np.isnan(axial))
    return (hoops, axial) if not ended.size else (hoops[:ended[0]], axial[:ended[0]])


def _grid_slopes(material, hoops) -> np.ndarray:
    """dP/dλθ along the closed-end path at the grid ``hoops`` (``closed_end_axial``)."""
    return _path_slope(material, hoops, closed_end_axial(material, hoops))


def pressure_maximum(material, largest_hoop: float = 10.0) -> UniformTube | None:
    """The first pressure maximum of the closed-end path for λθ in (1, ``largest_hoop``]: the first sign change
    + → − of dP/dλθ on a geometric grid, then brentq; None where P rises throughout."""
    hoops = np.geomspace(1.0 + 1e-3, largest_hoop, _SCAN_POINTS)
    slopes = _grid_slopes(material, hoops)
    for k in range(len(hoops) - 1):
        if slopes[k] > 0 >= slopes[k + 1]:
            hoop = brentq(lambda h: pressure_slope(material, h), hoops[k], hoops[k + 1], xtol=TOLERANCE,
                          rtol=TOLERANCE)
            return closed_end_state(material, hoop)
    return None


def bulge_condition(material, state: UniformTube, wavenumber: float) -> float:
    """The sign of the second variation of the uniform ``state`` at fixed P under the bulge mode of axial
    wavenumber k (docs/tubes.md): ρ = λθ + ε A cos kS, η = λz S + ε B sin kS (k = nπ/L on a tube of length L with
    sliding ends: ρ' = 0 and η fixed at both ends). Averaged over a period its Hessian in (A, B) is

        ½ [[Φ_22 + Φ_1 k²/λz − P λz,  k (Φ_12 − P λθ)], [k (Φ_12 − P λθ),  Φ_11 k²]],

    whose determinant is k²/4 times the value returned, (Φ_22 + Φ_1 k²/λz − P λz) Φ_11 − (Φ_12 − P λθ)²: positive
    where the uniform state is stable against the mode (Φ_11 > 0), zero at its onset. As k → 0 it is λθλz times
    det ∂(P, N)/∂(λθ, λz) (the pressure maximum of a long tube)."""
    d = stretch_derivatives(material, state.axial, state.hoop)
    P, k2 = state.pressure, wavenumber**2
    return float((d["phi_22"] + d["phi_1"] * k2 / state.axial - P * state.axial) * d["phi_11"]
                 - (d["phi_12"] - P * state.hoop) ** 2)


def bulge_onset(material, length: float, mode: int = 1, largest_hoop: float = 10.0) -> UniformTube | None:
    """The first uniform closed-end state (λθ rising from 1) where ``bulge_condition`` of the mode cos(nπS/L),
    n = ``mode``, on a tube of ``length`` L (in reference radii) changes sign: the bulge's onset; None where it
    does not in (1, ``largest_hoop``]."""
    wavenumber = mode * np.pi / length

    def condition(hoop):
        return bulge_condition(material, closed_end_state(material, hoop), wavenumber)

    hoops = np.geomspace(1.0 + 1e-3, largest_hoop, _SCAN_POINTS)
    hoops, _ = _on_path(material, hoops)
    values = [condition(h) for h in hoops]
    for k in range(len(hoops) - 1):
        if values[k] > 0 >= values[k + 1]:
            hoop = brentq(condition, hoops[k], hoops[k + 1], xtol=TOLERANCE, rtol=TOLERANCE)
            return closed_end_state(material, hoop)
    return None


def pressure_minimum(material, largest_hoop: float = 100.0, peak: UniformTube | None = None) -> UniformTube | None:
    """The first pressure minimum of the closed-end path beyond its maximum (``peak``; None: ``pressure_maximum``):
    the first sign change − → + of dP/dλθ on a geometric grid up to ``largest_hoop``, then brentq; None where there
    is no maximum or P falls throughout."""
    peak = pressure_maximum(material) if peak is None else peak
    if peak is None:
        return None
    hoops = np.geomspace(peak.hoop * (1 + 1e-6), largest_hoop, _SCAN_POINTS)
    slopes = _grid_slopes(material, hoops)
    for k in range(len(hoops) - 1):
        if slopes[k] < 0 <= slopes[k + 1]:
            hoop = brentq(lambda h: pressure_slope(material, h), hoops[k], hoops[k + 1], xtol=TOLERANCE,
                          rtol=TOLERANCE)
            return closed_end_state(material, hoop)
    return None


def closed_end_energy(material, state: UniformTube, pressure: float) -> float:
    """e = Φ(λz, λθ) − ½ P λθ² λz of a uniform state at the pressure P (per 2π and unit reference length)."""
    return float(stretch_derivatives(material, state.axial, state.hoop)["phi"]
                 - pressure * state.hoop**2 * state.axial / 2)


def maxwell_pressure(material, largest_hoop: float = 100.0) -> tuple | None:
    """(P_M, a, b): the pressure at which the uniform states a (below the pressure maximum) and b (beyond the
    pressure minimum) of the closed-end path have the same e (module docstring), by brentq in P between the
    minimum and the maximum; None where the path has no maximum and minimum, or ends (``closed_end_axial``) before
    the areas can be equal. b is bracketed by the minimum and the
    first point of a geometric grid beyond it where the path's P exceeds P (the grid's path computed once)."""
    peak = pressure_maximum(material)
    low = None if peak is None else pressure_minimum(material, largest_hoop, peak)
    if low is None:
        return None
    grid, axial = _on_path(material, np.geomspace(low.hoop, largest_hoop, _SCAN_POINTS)[1:])
    rising = hoop_pressure(material, grid, axial)
    top = min(peak.pressure, rising.max(initial=low.pressure))  # b exists for P up to it (the path may end first)

    def states(P):
        def at(h):
            return closed_end_state(material, h).pressure - P

        above = np.flatnonzero(rising > P)
        if not above.size:
            raise ValueError(f"the closed-end pressure stays below {P:g} up to the hoop stretch {largest_hoop:g}")
        a = brentq(at, 1.0, peak.hoop, xtol=TOLERANCE, rtol=TOLERANCE)
        b = brentq(at, low.hoop, float(grid[above[0]]), xtol=TOLERANCE, rtol=TOLERANCE)
        return closed_end_state(material, a), closed_end_state(material, b)

    def difference(P):
        a, b = states(P)
        return closed_end_energy(material, a, P) - closed_end_energy(material, b, P)

    span = top - low.pressure
    if span <= 0:
        return None
    bracket = (low.pressure + 1e-9 * span, top - 1e-9 * span)
    if difference(bracket[0]) * difference(bracket[1]) > 0:  # the path ends before the equal areas
        return None
    P = brentq(difference, *bracket, xtol=TOLERANCE, rtol=TOLERANCE)
    return (P, *states(P))
