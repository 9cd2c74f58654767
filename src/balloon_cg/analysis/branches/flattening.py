"""The deflating balloon folded about a coil wire: the end at P → 0 of a branch whose rim a wire holds.

When the field holds the equator at a wire (a free balloon centred on a coil's plane, or a held one on the
equator-symmetric coil), the balloon deflates past its fold in the pole stretch into two caps spanning that rim.
The Laplace law at a pole, P = 2Tκ (T its tension, bounded below: λ2(0) stays above 1.19), flattens each cap
as P falls, and the poles' separation s = η(0) − η(π) falls in proportion to P: at P = 0 the caps coincide, the
membrane lies flat on itself folded about the rim, and the rim's meridional stress vanishes with P while its
curvature grows without bound (SPOM1, a coil r = 2 at M = 0.002: s/P = 1.263, 1.258, 1.256 at P = 0.93, 0.79,
0.68; rim curvature 164, 221, 288; σ1 there 0.80 at P = 0.87, 0.52 at 0.64; docs/surface.md). That end is
reached at no degree: a leg at solver.max_degree on its way there stops with ``StopCode.FLATTENING``, a stated
limit of the method (``verdict``), not with ``RESOLUTION_LIMIT``.

The test: on the leg's last point, P falls along the tangent τ and the tangent line of (P, s) meets P = 0 at
|s₀| = |s − P ds/dP| ≤ FLAT_TOL · s (the poles meet where the pressure vanishes), with the basis mapped at a wire.
"""
from ...numerics.continuation import Point, Stop
from ..results import StopCode

FLAT_TOL = 0.05  # |s₀| / s at which the poles meet at P = 0 (measured 0.004 where the coil r = 2 stops at degree 320)


def pole_separation(disc, u) -> float:
    """s = η(0) − η(π): the axial distance between the poles."""
    rows = disc.pole_rows()
    return float((rows["eta_top"] - rows["eta_bottom"]) @ u)


def flattening_stop(disc, point: Point, max_degree: int) -> Stop | None:
    """The FLATTENING stop of a leg whose last ``point`` (X = (u, P) on ``disc``, its tangent along the leg) is
    at ``max_degree`` on the way to the flat balloon folded about a wire (module docstring); None otherwise."""
    if disc.mapping is None or point.tangent[-1] >= 0.0:
        return None
    u, P = point.X[:-1], point.X[-1]
    s = pole_separation(disc, u)
    ds_dP = pole_separation(disc, point.tangent[:-1]) / point.tangent[-1]
    at_zero = s - P * ds_dP
    if s <= 0.0 or abs(at_zero) > FLAT_TOL * s:
        return None
    return Stop(StopCode.FLATTENING, (
        f"flattening: at P = {P:.4g} the poles' separation {s:.4g} falls in proportion to P (its tangent meets P = 0 "
        f"at {at_zero:.2g}): the balloon deflates into a membrane folded flat about the wire at P = 0, whose rim "
        f"no degree resolves; traced to solver.max_degree = {max_degree}"))
