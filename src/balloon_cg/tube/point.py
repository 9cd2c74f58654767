"""One equilibrium of a tube (``balloon-cg solve`` on a tube scene): the state of its primary branch (tube/primary.py)
where the hoop stretch at the tube's middle, λ2(L/2), is a given value.

The middle is where the primary branch's states (mirror-symmetric about it) have their largest radius (the uniform
tube everywhere, a plugged tube's or a coil's middle bulge), so λ2(L/2) rises along the branch from the start as its
largest hoop stretch does. The primary branch is traced until its largest hoop stretch passes the value; then, from
the stored point nearest below it, Newton on the even block's rows with the bordering row ℓ·u = λ (ℓ: λ2(L/2) =
Σ a_k P_k(0) as a linear map of u, plugged ends' 1 added) lands on it, P an unknown.
"""
from dataclasses import dataclass

import numpy as np

from .events import hoop_row
from .primary import TubeSystem, held, primary_branch, volume_ratio
from ..analysis.results import IntervalStop
from ..analysis.branches.problem import ParameterSystem
from ..galerkin.equilibrium import Equilibrium
from ..galerkin.interval import IntervalDiscretisation, Mirror
from ..numerics.newton import newton
from ..numerics.threads import limited_blas


class NotReached(ArithmeticError):
    """The primary branch stopped before λ2(L/2) reached the value asked for (one line: its stop, the largest value
    reached)."""


@dataclass(frozen=True)
class TubePoint:
    """An equilibrium of the primary branch: its unknowns u, pressure, V/V0, Newton's last residual and the
    discretisation."""

    disc: IntervalDiscretisation
    u: np.ndarray
    pressure: float
    volume: float
    residual: float

    def hoop_stretch(self, s: float) -> float:
        """λ2 = ρ at the reference arclength s."""
        return float(self.disc.profile(self.u, np.array([s]))[0][0])


def middle_hoop(disc: IntervalDiscretisation) -> tuple:
    """(ℓ, c): λ2(L/2) = ℓ·u + c (c = 1 on plugged ends, else 0)."""
    return hoop_row(disc, disc.length / 2)


@limited_blas
def point_at_middle_hoop(scene, hoop: float) -> TubePoint:
    """The primary branch's state with λ2(L/2) = ``hoop`` (> 1; module docstring); NotReached where the branch stops
    before it."""
    limits = {"continuation.stop_stretch": hoop}
    if hoop <= scene.continuation.start_stretch:  # a sphere's key the tube does not read; stop_stretch must exceed it
        limits |= {"continuation.start_stretch": (1 + hoop) / 2, "continuation.min_stretch": None}
    traced = primary_branch(scene.with_overrides(limits))
    disc = traced.disc
    ell, c = middle_hoop(disc)
    values = traced.states @ ell + c
    below = np.flatnonzero(values <= hoop)
    if traced.stop.code != IntervalStop.HOOP_STRETCH and values.max() < hoop:
        raise NotReached(f"the primary branch stopped before the hoop stretch at the middle reached {hoop:g} "
                         f"({traced.stop.message}); largest reached: {values.max():.10g}")
    start = below[-1] if below.size else 0
    eq = Equilibrium(scene, disc)
    even = disc.block(Mirror.EVEN)
    system = TubeSystem(ParameterSystem(eq, traced.params, "P"), even, held(disc))
    X = np.append(traced.states[start], traced.pressure[start])[system.columns]
    row = np.append(ell[even], 0.0)
    found = newton(system.residual, system.jacobian, X, row, hoop - c, scene.solver.tol, scene.solver.max_newton)
    if not found.converged:
        raise NotReached(f"Newton did not land on the hoop stretch {hoop:g} at the middle from the primary branch's "
                         f"point {start}: {found.message}")
    Y = system.full(found.x)
    return TubePoint(disc, Y[:-1], float(Y[-1]), volume_ratio(eq, Y), float(found.residual))


def tube_solution(point: TubePoint) -> dict:
    """The reported quantities of a tube's equilibrium (``solve``): P, the hoop stretch at the middle and at the ends,
    the ends' distance over L (λ̄), V/V0, Newton's residual."""
    disc = point.disc
    return {"pressure": point.pressure, "hoop_stretch_middle": point.hoop_stretch(disc.length / 2),
            "hoop_stretch_end": point.hoop_stretch(0.0), "axial_stretch": float(point.u[disc.axial_index]),
            "volume_ratio": point.volume, "residual": point.residual}
