"""The control parameter of a loading (scene/loading.py) at a branch point X = (u, P), and its folds.

q = P (pressure control), q = V = 2π Ṽ(u) (volume control; Ṽ = ``enclosed_volume``, per 2π), q = n = P V (gas
control, isothermal ideal gas P V = n). Branches are traced in P (the equilibria are the same for every
control); a fold of q is where dq/ds = ∇q·τ = 0 along the arclength, located by the continuation engine from
∇q (``fold_monitors``): ∇_u V = −2π ∂R/∂P (R = ∂(E/2π)/∂u holds −P Ṽ), ∂V/∂P = 0; ∇n = (P ∇_u V, V).
"""
import numpy as np

from ...galerkin.equilibrium import enclosed_volume, node_radius
from ...scene import Control, Geometry
from .problem import ParameterSystem
from ..results import Kind, StopCode

FOLD_KIND = {Control.PRESSURE: Kind.LP, Control.VOLUME: Kind.LV, Control.GAS: Kind.LN}


def scene_stops(scene) -> tuple:
    """((key, StopCode, Control q, limit), ...) of a scene's stops in V or n: ``continuation.stop_volume`` (V/R0³,
    under every control) and ``loading.stop_amount`` (n = P V, gas control); the branch ends where q reaches
    the limit, landed on exactly (``landing``)."""
    stops = (("stop_volume", StopCode.STOP_VOLUME, Control.VOLUME, scene.continuation.stop_volume),
             ("stop_amount", StopCode.STOP_AMOUNT, Control.GAS, scene.loading.stop_amount))
    return tuple(stop for stop in stops if stop[3] is not None)


def landing(scene) -> dict:
    """The ``assembly.assemble`` land_on entries of a scene's stops in V or n: {StopCode: (Control, limit)}."""
    return {code: (control, limit) for _, code, control, limit in scene_stops(scene)}


def control_value(disc, X, control: Control, geometry: Geometry = Geometry()) -> float:
    """q(X) on the discretisation ``disc`` of a scene of reference ``geometry`` (module docstring)."""
    if control == Control.PRESSURE:
        return float(X[-1])
    volume = enclosed_volume(disc, X[:-1], node_radius(geometry, disc))
    return float(control_values(X[-1], 2 * np.pi * volume, control))


def control_values(pressure, volume, control: Control):
    """q of points with pressure P and enclosed volume V (arrays): P, V, or n = P V."""
    return {Control.PRESSURE: pressure, Control.VOLUME: volume, Control.GAS: pressure * volume}[control]


def minimised_energy(energy, pressure, volume, control: Control):
    """The energy per 2π that ``control`` minimises, from E/2π = W/2π − P V/2π (``Equilibrium.energy``) at P and
    the volume V: E under pressure control, W/2π = E + P V/2π at fixed volume, W/2π − (n/2π) ln V with n = P V
    for an isothermal ideal gas (the ranking of snap-through targets)."""
    if control == Control.PRESSURE:
        return energy
    work = pressure * volume / (2 * np.pi)
    return energy + work - (work * np.log(volume) if control == Control.GAS else 0.0)


def control_gradient(system, X, control: Control) -> np.ndarray:
    """∇q(X) = ∂q/∂(u, P) of volume or gas control for the continuation system ``system`` (an
    ``analysis.branches.problem.ParameterSystem`` in P; under pressure control q = P is linear: its monitor is e_P)."""
    eq = system.eq
    dV = -2 * np.pi * eq.parameter_derivative(X[:-1], system.params.with_value("P", X[-1]), "P")
    if control == Control.VOLUME:
        return np.append(dV, 0.0)
    return np.append(X[-1] * dV, 2 * np.pi * eq.volume(X[:-1]))


def control_gradient_at(eq, u, params, control: Control) -> np.ndarray:
    """∇c = ∂c/∂(u, P) of the control parameter c at the state u of ``eq`` (a galerkin Equilibrium) and ``params``:
    e_P under pressure control, else ``control_gradient``."""
    if control == Control.PRESSURE:
        return np.append(np.zeros(u.size), 1.0)
    return control_gradient(ParameterSystem(eq, params, "P"), np.append(u, params.P), control)


def fold_monitors(system, control: Control) -> dict:
    """The continuation monitor of the folds of q besides those of P (none under pressure control)."""
    if control == Control.PRESSURE:
        return {}
    return {FOLD_KIND[control]: lambda X: control_gradient(system, X, control)}
