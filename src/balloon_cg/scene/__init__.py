"""The scene layer: a TOML scene file read, validated and normalised (material, field, continuation, solver).

``load_scene(path)`` / ``parse_scene(text, name)`` give a ``Scene``; invalid input raises ``SceneError`` with one
line naming the key, the value and what is allowed.
"""
from .loading import Control, Loading
from .tables import (Coil, Continuation, ContinuationParameter, Electric, Ends, Field, Geometry, Output, Scene,
                     Shape, Solver, Stability, load_scene, parse_scene, shipped_scenes)
from .validation import SceneError

__all__ = ["Coil", "Continuation", "ContinuationParameter", "Control", "Electric", "Ends", "Field", "Geometry",
           "Loading", "Output", "Scene", "SceneError", "Shape", "Solver", "Stability", "load_scene", "parse_scene",
           "shipped_scenes"]
