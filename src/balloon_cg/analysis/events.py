"""User points (UZ): where a branch's stored quantity passes a value the scene asks for (``[[events]]``).

For each event (quantity q, value v) of the scene, every interval of a branch where q − v changes sign (or
reaches 0 at its end) holds a UZ point: the equilibrium between the two stored points with q(X) = v, landed on by
Newton on R(X) = 0 and the linearised constraint ∇q(X_k)·(X − X_k) = v − q(X_k), repeated until
|q − v| ≤ LANDING_RTOL·max(1, |v|) (``assembly.land``, the landing of a branch end on a stop value). The
quantities (``scene.events.Quantity``): the enclosed volume V = 2π Ṽ(u), the gas amount n = P V, the pressure P
(the continuation parameter: a voltage continuation's P is fixed and never passes a value), and λ2 at the north
pole, the south pole and the equator (linear rows in u). A landing that fails stores the linear interpolant,
APPROXIMATE with its bracket.
"""
import numpy as np

from ..galerkin.profiles import EQUATOR
from ..scene import Control
from ..scene.events import Quantity
from .assembly import land, quantity_of
from .control import control_gradient
from .problem import branch_system, continuation_settings
from .results import Branch, Kind, SpecialPoint, approximate

POLE_ROWS = {Quantity.LAM2_NORTH: "lam2_north", Quantity.LAM2_SOUTH: "lam2_south"}


def event_quantity(system, quantity: Quantity):
    """(q(X), ∇q(X)) of ``quantity`` for the continuation system of a branch (X = (u, p), p its parameter)."""
    disc, size = system.eq.disc, system.eq.disc.size + 1
    if quantity in POLE_ROWS:
        return quantity_of(system, POLE_ROWS[quantity])
    if quantity == Quantity.LAM2_EQUATOR:  # λ2(π/2) is linear in u: its row from the basis values there
        row = np.append(disc.evaluate(np.eye(disc.size), EQUATOR)[0][:, 0], 0.0)
        return (lambda X: float(row @ X)), (lambda X: row)
    volume = quantity_of(system, Control.VOLUME)
    in_pressure = system.name == "P"
    if quantity == Quantity.VOLUME:
        return volume
    if quantity == Quantity.AMOUNT:
        if in_pressure:
            return quantity_of(system, Control.GAS)
        P = system.params.P
        return (lambda X: P * volume[0](X)), (lambda X: P * control_gradient(system, X, Control.VOLUME))
    if in_pressure:  # Quantity.PRESSURE
        row = np.zeros(size)
        row[-1] = 1.0
        return (lambda X: float(X[-1])), (lambda X: row)
    P = system.params.P
    return (lambda X: P), (lambda X: np.zeros(size))


def event_points(branch: Branch) -> list[SpecialPoint]:
    """The UZ points of ``branch`` for the events of its scene (module docstring), in order of the events."""
    events = branch.scene.events
    if not events:
        return []
    system, settings = branch_system(branch), continuation_settings(branch.scene)
    found = []
    for event in events:
        quantity = event_quantity(system, event.quantity)
        offset = np.array([quantity[0](X) for X in branch.X]) - event.value
        note = f"{event.quantity.value} = {event.value:g}"
        if offset[0] == 0:
            found.append(SpecialPoint(Kind.UZ, 0, branch.X[0].copy(), note=note))
        for i in np.flatnonzero((offset[:-1] != 0) & (offset[:-1] * offset[1:] <= 0)):
            before, after = branch.X[i], branch.X[i + 1]
            point = land(system, before, after, quantity, event.value, settings)
            if point is not None:
                found.append(SpecialPoint(Kind.UZ, int(i), point.X, note=note))
                continue
            X = before + offset[i] / (offset[i] - offset[i + 1]) * (after - before)
            found.append(SpecialPoint(Kind.UZ, int(i), X, note=note, **approximate(
                branch.disc, before, after, f"{note}: Newton did not land on the value; the linear interpolant")))
    return found


def with_events(branch: Branch) -> Branch:
    """``branch`` with its UZ points (``event_points``) among its special points, ordered by index."""
    points = event_points(branch)
    if points:
        branch.special = sorted(branch.special + points, key=lambda s: s.index)
    return branch
