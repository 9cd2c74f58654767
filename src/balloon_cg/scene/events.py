"""User events: the ``[[events]]`` array of tables, each a stored quantity and the value at which a point is wanted.

    [[events]]
    quantity = "volume"      # one of QUANTITIES
    value = 20.0             # > 0

Every branch then gets a special point labelled UZ wherever its quantity passes the value, located to the solver
tolerance (``analysis.branches.events``). The quantities are those stored per point: the enclosed volume V, the gas amount
n = P V, the pressure P, and the hoop stretch λ2 at the meridian's top and bottom ends (a sphere's poles, a tube's
ends S = 0 and S = L) and at the equator (the meridian's middle: a tube's S = L/2). Scenes written before session 21
name the ends ``lam2_north`` and ``lam2_south``: read as ``lam2_top`` and ``lam2_bottom`` (OLD_QUANTITIES). On a
tube (``tube.events``) also the volume ratio V/V0 (V0 = πL), the largest hoop stretch and the axial stretch λ̄ (the
ends' distance over L); ``check_on_shape`` refuses what has no meaning on a scene's shape (TUBE_ONLY elsewhere, the
hoop stretch at a plugged tube's ends, where it is 1, the axial stretch of ends held apart).
"""
import enum
from dataclasses import dataclass

from .validation import SceneError, did_you_mean, number, show, table

MAX_EVENTS = 64  # a scene asks for a few; the bound keeps a hostile file from asking for millions


class Quantity(enum.StrEnum):
    VOLUME = "volume"
    AMOUNT = "amount"
    PRESSURE = "pressure"
    LAM2_TOP = "lam2_top"
    LAM2_BOTTOM = "lam2_bottom"
    LAM2_EQUATOR = "lam2_equator"
    VOLUME_RATIO = "volume_ratio"
    LAM2_MAX = "lam2_max"
    AXIAL_STRETCH = "axial_stretch"


TUBE_ONLY = (Quantity.VOLUME_RATIO, Quantity.LAM2_MAX, Quantity.AXIAL_STRETCH)  # located on a tube's branches only


OLD_QUANTITIES = {"lam2_north": Quantity.LAM2_TOP, "lam2_south": Quantity.LAM2_BOTTOM}


@dataclass(frozen=True)
class Event:
    """A point wanted where ``quantity`` equals ``value``."""

    quantity: Quantity
    value: float

    def to_table(self) -> dict:
        return {"quantity": self.quantity.value, "value": self.value}


def events_from_list(data) -> tuple[Event, ...]:
    """The checked ``[[events]]`` array (default: none); SceneError naming the key, the value and what is allowed."""
    if not isinstance(data, list):
        raise SceneError(f"events = {show(data)}: must be an array of tables [[events]] with quantity and value")
    if len(data) > MAX_EVENTS:
        raise SceneError(f"events: {len(data)} events; at most {MAX_EVENTS}")
    return tuple(_event(f"events[{i}]", entry) for i, entry in enumerate(data))


def _event(key: str, data) -> Event:
    data = table(key, data, ("quantity", "value"))
    for name in ("quantity", "value"):
        if name not in data:
            raise SceneError(f"{key}.{name}: missing (an event needs quantity and value)")
    quantity = data["quantity"]
    if isinstance(quantity, str):
        quantity = OLD_QUANTITIES.get(quantity, quantity)
    if quantity not in tuple(Quantity):
        raise SceneError(f"{key}.quantity = {show(quantity)}: must be one of "
                         f"{', '.join(show(q.value) for q in Quantity)}{did_you_mean(quantity, tuple(Quantity))}")
    value = number(f"{key}.value", data["value"])
    if value <= 0:
        raise SceneError(f"{key}.value = {show(data['value'])}: must be > 0")
    return Event(Quantity(quantity), value)


def check_on_shape(events: tuple[Event, ...], shape: str, ends: str | None, held: bool) -> None:
    """SceneError naming the first event whose quantity has no meaning on the reference ``shape`` (module docstring;
    ``ends`` a tube's, ``held``: its ends' distance held), the allowed quantities listed."""
    for i, event in enumerate(events):
        if why := _meaningless(event.quantity, shape, ends, held):
            allowed = (q for q in Quantity if not _meaningless(q, shape, ends, held))
            raise SceneError(f"events[{i}].quantity = {show(event.quantity.value)}: {why}; allowed: "
                             f"{', '.join(show(q.value) for q in allowed)}")


def _meaningless(q: Quantity, shape: str, ends: str | None, held: bool) -> str:
    """Why ``q`` means nothing on the shape (``check_on_shape``); '' where it does."""
    if shape != "tube":
        return f"located on a tube's branches only, not on a {shape}" if q in TUBE_ONLY else ""
    if ends == "plugged" and q in (Quantity.LAM2_TOP, Quantity.LAM2_BOTTOM):
        return "the plugs hold the hoop stretch at a plugged tube's ends at 1"
    if held and q == Quantity.AXIAL_STRETCH:
        return "the ends are held apart (geometry.axial_stretch): it passes no value"
    return ""
