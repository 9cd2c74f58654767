"""How the balloon is loaded: the ``[loading]`` table (MODEL.md §5: the control mode decides stability).

- ``pressure``: P prescribed (a pressure regulator); energy E − P V.
- ``volume``: the enclosed volume V prescribed (an incompressible fill); P is its Lagrange multiplier.
- ``gas``: a fixed amount n of isothermal ideal gas, P V = n in the units of MODEL.md §2 (P = P̄ R0/(T0 μ/2),
  V in R0³), i.e. n = N R T / (T0 μ R0² / 2) for N moles at temperature T; energy E − n ln V.

All three share the equilibria of pressure control (P = n/V under gas control); they differ in the stability
reading and in the parameter whose folds and stops count (P, V or n). ``stop_volume`` and ``stop_amount``
end the branch when V, respectively n, reaches them (only under their own control).
"""
import enum
from dataclasses import dataclass

from .validation import SceneError, number, show, table


class Control(enum.StrEnum):
    PRESSURE = "pressure"
    VOLUME = "volume"
    GAS = "gas"


@dataclass(frozen=True)
class Loading:
    control: Control = Control.PRESSURE
    stop_volume: float | None = None  # V / R0³ (volume control)
    stop_amount: float | None = None  # n = P V (gas control)


_STOPS = {"stop_volume": Control.VOLUME, "stop_amount": Control.GAS}


def loading_from_table(data) -> Loading:
    """The checked ``[loading]`` table (defaults: pressure control, no stops)."""
    data = table("loading", data, ("control",) + tuple(_STOPS))
    raw = data.get("control", Loading.control.value)
    if raw not in tuple(Control):
        raise SceneError(f"loading.control = {show(raw)}: must be one of "
                         f"{', '.join(show(c.value) for c in Control)}")
    control = Control(raw)
    stops = {}
    for key, owner in _STOPS.items():
        if data.get(key) is None:
            continue
        value = number(f"loading.{key}", data[key])
        if control != owner:
            raise SceneError(f"loading.{key} = {show(data[key])}: only with loading.control = {show(owner.value)} "
                             f"(here {show(control.value)})")
        if value <= 0:
            raise SceneError(f"loading.{key} = {show(data[key])}: must be > 0")
        stops[key] = value
    return Loading(control, **stops)
