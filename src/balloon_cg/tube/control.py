"""A tube's branches under its loading control (scene/loading.py): the control parameter on a trace's unknowns, its
folds, and the stop at ``continuation.stop_volume``.

The equilibria are those of pressure control (the branches are traced in P); the control decides the stability
reading (tube/stability.py) and which folds count: q = V = 2π Ṽ(u) under volume control (LV), q = n = P V under gas
control (LN; P V = n, an isothermal ideal gas), both located by the tracer's fold monitors from ∇q in the trace's
coordinates X = (u[unknowns], P) (a ``TubeSystem``): ∇_u V = −2π ∂R/∂P, ∇n = (P ∇_u V, V)
(analysis/branches/control.py). ``VolumeStop``: the trace ends where V reaches ``continuation.stop_volume`` (V/R0³,
any control; a tube's V0 = πL), its end point landed there by Newton on the linearised constraint
∇V(X_k)·(X − X_k) = target − V(X_k) (analysis/branches/assembly.land, to LANDING_RTOL).
"""
import numpy as np

from ..analysis.branches.assembly import land
from ..analysis.branches.control import FOLD_KIND, control_gradient, control_value
from ..analysis.results import StopCode
from ..numerics.continuation import Stop
from ..scene.loading import Control


def gradient(system, control: Control):
    """X -> ∇q(X) of q = V or n in the coordinates of ``system`` (a tube/primary.TubeSystem)."""
    return lambda X: control_gradient(system.system, system.full(X), control)[system.columns]


def value(system, control: Control):
    """X -> q(X) (P, V or n) of a point of ``system``'s trace."""
    eq = system.system.eq
    return lambda X: control_value(eq.disc, system.full(X), control, eq.scene.geometry)


def control_monitors(system, control: Control) -> dict:
    """The tracer's fold monitor of the control's parameter besides P's: {LV: ∇V} or {LN: ∇n}; none under pressure
    control (its folds are the LPs every trace locates)."""
    return {} if control == Control.PRESSURE else {FOLD_KIND[control]: gradient(system, control)}


class VolumeStop:
    """A stop at the enclosed volume ``target`` (V/R0³; None: no stop) on the trace of ``system`` (module
    docstring): called with a point's X it returns Stop(STOP_VOLUME) once V ≥ target; ``end`` lands on it."""

    def __init__(self, target: float | None, system):
        self.target, self.system = target, system
        self.volume = value(system, Control.VOLUME)

    def __call__(self, X) -> Stop | None:
        if self.target is None or self.volume(X) < self.target:
            return None
        return Stop(StopCode.STOP_VOLUME, f"V reached continuation.stop_volume {self.target:g} (V/V0 = "
                                          f"{self.target / (np.pi * self.system.system.eq.disc.length):.6g})")

    def end(self, path, settings) -> tuple:
        """(Y = (u, P) of the trace's end landed on V = target, or None; the branch's stop): None and the trace's
        stop where it did not stop here; where Newton does not land, None and LANDING_FAILED (the branch ends at
        its last point before the target)."""
        if path.stop.code != StopCode.STOP_VOLUME:
            return None, path.stop
        quantity = (self.volume, gradient(self.system, Control.VOLUME))
        landed = land(self.system, path.points[-1].X, path.overshoot.X, quantity, self.target, settings)
        if landed is None:
            return None, Stop(StopCode.LANDING_FAILED, f"could not land on continuation.stop_volume {self.target:g} "
                                                       "(Newton failed); stopped before it")
        return self.system.full(landed.X), path.stop

    def kept(self, path, end, X) -> bool:
        """Whether a point X located in the last step of a trace stopped here (between its last point and the
        overshoot) lies on the branch: before its landed ``end`` (V between the last point's and the target); none
        where the landing failed (``end`` None: the branch ends at its last point)."""
        last, here = self.volume(path.points[-1].X), self.volume(X)
        return end is not None and (here - last) * (self.target - here) >= 0
