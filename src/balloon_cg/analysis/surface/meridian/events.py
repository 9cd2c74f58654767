"""User points (UZ, ``[[events]]``) on a non-axisymmetric branch over a meridian (trace.py): where its enclosed
volume V, gas amount n = P V or pressure P passes the value an event asks for, as on the sphere's surface branches
(analysis/branches/events.py: ``crossings`` brackets the sign changes of q − v between stored points and lands on
q = v by Newton on the branch's equations, system.py on its final basis, X = (c, τ, P), with the linearised
constraint; a landing that fails gives the linear interpolant, not located). V = 2π Ṽ(c) (equilibrium.py's volume,
per 2π), ∇_c V = −2π ∂R/∂P (the −P Ṽ term of E). λ2 at the poles and the equator are not located on these branches
either (``events.unlocated_on_surface`` says so in the verdict line).
"""
from dataclasses import dataclass, replace

import numpy as np

from .equilibrium import MeridianSurfaceEquilibrium
from .system import MeridianSurfaceSystem
from .trace import MeridianSurfaceBranch
from ...branches.events import NOT_LANDED, SURFACE_QUANTITIES, crossings, quantity_of_volume
from ...branches.problem import continuation_settings
from ....galerkin.equilibrium import Parameters


@dataclass(frozen=True)
class MeridianEvent:
    """A UZ point between points ``index`` and ``index`` + 1: its ``coefficients`` c (on the branch's basis),
    ``pressure``, ``volume`` (V/V0), ``note`` ('volume = 60'), ``located`` (Newton landed on the value; else the
    linear interpolant)."""

    index: int
    coefficients: np.ndarray
    pressure: float
    volume: float
    note: str
    located: bool


def event_points(scene, branch: MeridianSurfaceBranch, params: Parameters) -> tuple:
    """The MeridianEvents of ``branch`` (traced in P at ``params``, P replaced) for the events of ``scene`` on
    SURFACE_QUANTITIES, in the order of the events (module docstring)."""
    events = [e for e in scene.events if e.quantity in SURFACE_QUANTITIES]
    if not events:
        return ()
    basis = branch.basis
    system = MeridianSurfaceSystem(MeridianSurfaceEquilibrium(scene, basis), params, branch.coefficients[0])
    X = np.array([_point(system, c, P, tau) for c, P, tau in zip(branch.coefficients, branch.pressure,
                                                                  branch.reaction)])

    def volume(x):
        return 2 * np.pi * system.surface.volume(system.coefficients(x))

    def volume_gradient(x):
        rate = system.surface.parameter_derivative(system.coefficients(x), system.params_at(x))[system.free]
        return np.concatenate([-2 * np.pi * rate, np.zeros(system.gauged + 1)])

    settings, found = continuation_settings(scene), []
    for event in events:
        quantity = quantity_of_volume(event.quantity, X.shape[1], volume, volume_gradient)
        offset = np.array([quantity[0](x) for x in X]) - event.value
        note = f"{event.quantity.value} = {event.value:g}"
        for i, point, t in crossings(system, X, offset, quantity, event.value, settings):
            x = X[i] + t * (X[i + 1] - X[i]) if point is None else point.X
            ratio = basis.volume_ratio(volume(x) / (2 * np.pi))
            found.append(MeridianEvent(i, system.coefficients(x), float(x[-1]), ratio,
                                       note if point is not None else f"{note}: {NOT_LANDED}", point is not None))
    return tuple(found)


def with_events(scene, branch: MeridianSurfaceBranch, params: Parameters) -> MeridianSurfaceBranch:
    """``branch`` with its ``events`` (``event_points``)."""
    return replace(branch, events=event_points(scene, branch, params))


def _point(system: MeridianSurfaceSystem, c: np.ndarray, P: float, reaction: float) -> np.ndarray:
    """X of a stored point: c, its first gauge reaction (the one stored), P."""
    X = system.point(c, P)
    if system.gauged:
        X[system.free.size] = reaction
    return X
