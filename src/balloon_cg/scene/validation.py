"""SceneError and the small checks that raise it (shared by materials.py and scene.py), and ``did_you_mean`` for
every one-line error about a mistyped name (scene keys, presets, commands, plot kinds, files)."""

import difflib
import json
import math
import numbers
import re


class SceneError(ValueError):
    """Invalid scene input. The message is one line: ``<scene>: <dotted.key> = <value>: <what is allowed>``."""


def did_you_mean(word, allowed) -> str:
    """' (did you mean X?)' naming the allowed name closest to ``word`` (difflib), or '' when none is close."""
    close = difflib.get_close_matches(str(word), [str(a) for a in allowed], n=1)
    return f" (did you mean {close[0]}?)" if close else ""


def show_key(key: str) -> str:
    """A TOML key as written in a file: bare when possible, else quoted."""
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else show(key)


def show(value) -> str:
    """One-line TOML rendering of a value (valid TOML for strings, numbers, booleans, lists, tables)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(map(show, value)) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{show_key(str(k))} = {show(v)}" for k, v in value.items()) + "}"
    return show(str(value))


MAX_MAGNITUDE = 1e6  # docs/scenes.md, Bounds: |any number of a scene| (most keys have a tighter range)


def number(key: str, value, *, integer: bool = False, allowed: str | None = None):
    """``value`` as a finite float within ±MAX_MAGNITUDE (or an int when ``integer``); bool is not a number.
    ``allowed``: the key's own range, quoted when the value is beyond ±MAX_MAGNITUDE too (one bound per key)."""
    kind = numbers.Integral if integer else numbers.Real
    if isinstance(value, bool) or not isinstance(value, kind):
        raise SceneError(f"{key} = {show(value)}: must be {'an integer' if integer else 'a number'}")
    if integer:
        return int(value)
    if not math.isfinite(value):
        raise SceneError(f"{key} = {show(value)}: must be finite")
    if abs(value) > MAX_MAGNITUDE:
        raise SceneError(f"{key} = {show(value)}: must be {allowed}" if allowed else
                         f"{key} = {show(value)}: must be within ±{MAX_MAGNITUDE:g} (no balloon needs more: "
                         "docs/scenes.md, Bounds)")
    return float(value)


def table(key: str, value, allowed: tuple[str, ...]) -> dict:
    """``value`` checked to be a table whose keys are all in ``allowed``."""
    if not isinstance(value, dict):
        raise SceneError(f"{key} = {show(value)}: must be a table")
    for k, v in value.items():
        if k not in allowed:
            raise SceneError(f"{key}.{show_key(k)} = {show(v)}: unknown key{did_you_mean(k, allowed)}; allowed keys: "
                             f"{', '.join(allowed)}")
    return value
