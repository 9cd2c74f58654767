"""How the balloon is loaded: the ``[loading]`` table (MODEL.md §5: the control mode decides stability).

- ``pressure``: P prescribed (a pressure regulator); energy E − P V.
- ``volume``: the enclosed volume V prescribed (an incompressible fill); P is its Lagrange multiplier.
- ``gas``: a fixed amount n of isothermal ideal gas, P V = n in the units of MODEL.md §2 (P = P̄ R0/(T0 μ/2),
  V in R0³), i.e. n = N R T / (T0 μ R0² / 2) for N moles at temperature T; energy E − n ln V.

All three share the equilibria of pressure control (P = n/V under gas control); they differ in the stability
reading and in the parameter whose folds and stops count (P, V or n). ``stop_amount`` ends the branch when n
reaches it (gas control only). ``loading.stop_volume`` is the old name of ``continuation.stop_volume`` (V/R0³, any
control and shape): old scenes still read with it (``moved_stop_volume``), one of the two names at a time.
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
    stop_amount: float | None = None  # n = P V (gas control)


_STOPS = {"stop_amount": Control.GAS}
OLD_STOP_VOLUME = "stop_volume"  # loading.stop_volume: read as continuation.stop_volume (``moved_stop_volume``)


def moved_stop_volume(loading: dict, continuation: dict) -> tuple[dict, dict]:
    """The [loading] and [continuation] tables with an old scene's ``loading.stop_volume`` moved to
    ``continuation.stop_volume`` (the same V/R0³, now under every control); SceneError when both are given."""
    if not isinstance(loading, dict) or not isinstance(continuation, dict) or OLD_STOP_VOLUME not in loading:
        return loading, continuation  # (a table that is no table: refused by its own reader)
    old = loading[OLD_STOP_VOLUME]
    moved = {k: v for k, v in loading.items() if k != OLD_STOP_VOLUME}
    if old is None:  # (with_overrides restoring its default)
        return moved, continuation
    if continuation.get("stop_volume") is not None:
        raise SceneError(f"loading.stop_volume = {show(old)}: the old name of continuation.stop_volume, which is "
                         f"given too ({show(continuation['stop_volume'])}); give continuation.stop_volume only")
    value = number("loading.stop_volume", old)
    if value <= 0:
        raise SceneError(f"loading.stop_volume = {show(old)}: must be > 0 (V/R0³; the old name of "
                         "continuation.stop_volume)")
    return moved, {**continuation, "stop_volume": value}


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
