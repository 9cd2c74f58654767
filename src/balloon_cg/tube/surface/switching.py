"""The switched point of a tube: the point of amplitude ε on the branch born at a located m ≥ 1 zero
(tube/azimuthal_crossings.AzimuthalCrossing: the state u, the pressure P_0, the critical mode φ of the m-th block,
G-unit), on the TubeSurfaceBasis of the orders (0, m, 2m) (analysis/surface/meridian/switching.py solves it;
docs/tubes.md "The tube over (S, φ)").
"""
from .basis import TubeSurfaceBasis
from ...analysis.surface.meridian.switching import SwitchedPoint, mode_row, point_at_amplitude
from ...galerkin.equilibrium import Parameters
from ...galerkin.interval import IntervalDiscretisation


def switched_point(scene, disc: IntervalDiscretisation, crossing, amplitude: float, params: Parameters,
                   orders: tuple | None = None, n_phi: int = 0, tol: float = 1e-12,
                   max_iter: int = 30) -> SwitchedPoint:
    """The point of amplitude ε = ``amplitude`` (≠ 0) on the branch born at ``crossing`` (its state on ``disc``, the
    branch's discretisation; ``params`` the branch's, P replaced), in the orders (0, m, 2m) unless ``orders``."""
    m = crossing.m
    if crossing.mode is None or crossing.held:
        raise ValueError("crossing: held or without its mode; switched_point starts from the free tube's critical "
                         "mode (allowed: a crossing with mode, held False)")
    if amplitude == 0:
        raise ValueError("amplitude: 0 is the axisymmetric state itself (allowed: ε ≠ 0)")
    basis = TubeSurfaceBasis(disc, orders or (0, m, 2 * m), n_phi)
    if m not in basis.orders:
        raise ValueError(f"orders: {basis.orders} lack the crossing's order (allowed: orders holding m = {m})")
    start = basis.with_mode(basis.axisymmetric(crossing.u), m, amplitude * crossing.mode)
    return point_at_amplitude(scene, basis, start, crossing.pressure, mode_row(basis, m, crossing.mode), amplitude, m,
                              params, tol, max_iter)
