"""User points (UZ): where a branch's stored quantity passes a value the scene asks for (``[[events]]``).

For each event (quantity q, value v) of the scene, every interval of a branch where q − v changes sign (or
reaches 0 at its end) holds a UZ point: the equilibrium between the two stored points with q(X) = v, landed on by
Newton on R(X) = 0 and the linearised constraint ∇q(X_k)·(X − X_k) = v − q(X_k), repeated until
|q − v| ≤ LANDING_RTOL·max(1, |v|) (``assembly.land``, the landing of a branch end on a stop value). The
quantities (``scene.events.Quantity``): the enclosed volume V = 2π Ṽ(u), the gas amount n = P V, the pressure P
(the continuation parameter: on a continuation in Φ̄ or M, P is fixed and passes no value: not searched), and λ2 at the north
pole, the south pole and the equator (linear rows in u). A landing that fails stores the linear interpolant,
APPROXIMATE with its bracket.

On a non-axisymmetric branch (``SurfaceBranch``, X = (a, P) of its ``surface.system``) the volume, the amount and
the pressure are located the same way (``surface_event_points``): V = 2π Ṽ(c) (``surface.measures``), whose gradient
is ∇_a V = −2π ∂R/∂P (R = Zᵀ∇E, and the −PṼ term of E gives ∂R/∂P = −∇_a Ṽ), n = P V, and P (a capsule's branches over
(θ, φ) the same way: analysis/surface/meridian/events.py). λ2 at the poles and the equator are not located there
(``unlocated_on_surface`` says so in the verdict line).
"""
import numpy as np

from ...galerkin.profiles import EQUATOR
from ...scene import Control
from ...scene.events import Quantity
from .assembly import land, quantity_of
from .control import control_gradient
from ...surface.measures import body_moments
from .problem import branch_system, continuation_settings
from ..results import Branch, Kind, SpecialPoint, Status, SurfaceBranch, approximate

POLE_ROWS = {Quantity.LAM2_TOP: "lam2_top", Quantity.LAM2_BOTTOM: "lam2_bottom"}


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
        if event.quantity == Quantity.PRESSURE and branch.parameter != "P":
            continue  # P is fixed along the branch: it passes no value (it is the value everywhere, or nowhere)
        quantity = event_quantity(system, event.quantity)
        offset = np.array([quantity[0](X) for X in branch.X]) - event.value
        note = f"{event.quantity.value} = {event.value:g}"
        if offset[0] == 0:
            found.append(SpecialPoint(Kind.UZ, 0, branch.X[0].copy(), note=note))
        for i, point, t in crossings(system, branch.X, offset, quantity, event.value, settings):
            if point is not None:
                found.append(SpecialPoint(Kind.UZ, i, point.X, note=note))
                continue
            before, after = branch.X[i], branch.X[i + 1]
            found.append(SpecialPoint(Kind.UZ, i, before + t * (after - before), note=note, **approximate(
                branch.disc, before, after, f"{note}: {NOT_LANDED}")))
    return found


NOT_LANDED = "Newton did not land on the value; the linear interpolant"


def crossings(system, X: np.ndarray, offset: np.ndarray, quantity, value: float, settings):
    """Per interval i of the points X where ``offset`` = q(X) − value changes sign: (i, the point Newton landed on
    q = value (``assembly.land``) or None, the fraction t of the interval where the linear interpolant of the
    offset vanishes)."""
    for i in np.flatnonzero((offset[:-1] != 0) & (offset[:-1] * offset[1:] <= 0)):
        t = offset[i] / (offset[i] - offset[i + 1])
        yield int(i), land(system, X[i], X[i + 1], quantity, value, settings), t


def with_events(branch: Branch, points: list | None = None) -> Branch:
    """``branch`` with its UZ points (``points``, default ``event_points``) among its special points, ordered by
    index."""
    points = event_points(branch) if points is None else points
    if points:
        branch.special = sorted(branch.special + points, key=lambda s: s.index)
    return branch


SURFACE_QUANTITIES = (Quantity.VOLUME, Quantity.AMOUNT, Quantity.PRESSURE)  # located on surface branches


def surface_quantity(system, quantity: Quantity):
    """(q(X), ∇q(X)) of ``quantity`` (one of SURFACE_QUANTITIES) for a surface branch's continuation system
    (``surface.system.SurfaceSystem`` in P; module docstring)."""
    basis = system.eq.basis

    def volume(X):
        return 2 * np.pi * body_moments(basis, basis.node_state(system.coefficients(X)))[0]

    def volume_gradient(X):
        c = system.coefficients(X)
        return np.append(-2 * np.pi * system.gauge.reduce(system.eq.parameter_derivative(c, system.params_at(X), "P")),
                         0.0)

    return quantity_of_volume(quantity, system.gauge.size + 1, volume, volume_gradient)


def quantity_of_volume(quantity: Quantity, size: int, volume, volume_gradient):
    """(q(X), ∇q(X)) of ``quantity`` (one of SURFACE_QUANTITIES) on a system in P of ``size`` unknowns (P last)
    whose enclosed volume V(X) and its gradient are ``volume`` and ``volume_gradient``: V, n = P V (∇n = P ∇V + V e_P)
    or P (the row e_P)."""
    row = np.zeros(size)
    row[-1] = 1.0
    if quantity == Quantity.PRESSURE:
        return (lambda X: float(X[-1])), (lambda X: row)
    if quantity == Quantity.VOLUME:
        return volume, volume_gradient
    return (lambda X: X[-1] * volume(X)), (lambda X: X[-1] * volume_gradient(X) + volume(X) * row)


def surface_event_points(branch: SurfaceBranch, system) -> list[SpecialPoint]:
    """The UZ points of the surface ``branch`` (traced in P) for the events of its scene on SURFACE_QUANTITIES,
    located on ``system`` (the branch's ``surface.system.SurfaceSystem`` on its stored basis), X = (c, P)."""
    events = [e for e in branch.scene.events if e.quantity in SURFACE_QUANTITIES]
    if not events or branch.parameter != "P":
        return []
    settings = continuation_settings(branch.scene)
    X = np.array([system.point(c, P) for c, P in zip(branch.coefficients, branch.values)])
    found = []
    for event in events:
        quantity = surface_quantity(system, event.quantity)
        offset = np.array([quantity[0](x) for x in X]) - event.value
        note = f"{event.quantity.value} = {event.value:g}"
        for i, point, t in crossings(system, X, offset, quantity, event.value, settings):
            if point is not None:
                found.append(SpecialPoint(Kind.UZ, i, np.append(system.coefficients(point.X), point.X[-1]),
                                          note=note))
                continue
            c = branch.coefficients[i] + t * (branch.coefficients[i + 1] - branch.coefficients[i])
            P0, P1 = branch.values[i], branch.values[i + 1]
            found.append(SpecialPoint(Kind.UZ, i, np.append(c, P0 + t * (P1 - P0)), note=note,
                                      status=Status.APPROXIMATE, uncertainty=0.5 * abs(P1 - P0),
                                      reason=f"{note}: {NOT_LANDED}"))
    return found


def with_surface_events(branch: SurfaceBranch, system) -> SurfaceBranch:
    """``branch`` with its UZ points (``surface_event_points``) among its special points, ordered by index (its
    origin, point 0, first)."""
    return with_events(branch, surface_event_points(branch, system))


def unlocated_on_surface(scene) -> str:
    """What events of ``scene`` are not located on surface branches (module docstring), for the verdict line; ''
    when all are."""
    missing = sorted({e.quantity.value for e in scene.events if e.quantity not in SURFACE_QUANTITIES})
    return (f"the [[events]] on {', '.join(missing)} are not located on the non-axisymmetric branches" if missing
            else "")
