"""A capsule's non-axisymmetric branches (a run file's /surface_branches: io/tube_surface_file.py) in the layout the
sphere's surface branches are drawn from (post/plotting.py: ``pressure-pole``, ``surface``), so that both are drawn
by the same code.

Each is added to the run's ``branches`` under its name with the attributes the figures read (``m``,
``parent_branch``, ``parent_branch_point``: its number among the parent's branch points, as a sphere's surface
branch's; ``reflection_of``: the branch it is the image of under the rotation by π/m, ``image_of``; the parent's
``M``; ``parameter`` P) and its stored ``orders``, ``degree``, ``mode_degree``, ``equator``, ``n_phi`` (the basis
``stored_meridian_basis`` rebuilds), per point its stored ``pressure``, ``volume``, ``amplitude`` and ``coefficients``, and the
material poles' stretches ``lam2_top``, ``lam2_bottom``: √J = √(λ1 λ2) at θ = 0, π (surface/measures.pole_stretch,
the sphere's measure, from the basis' ``point_values``; on an axisymmetric state λ2 there). No special points (its
folds carry no labels) and no stability flags: its stored counts are the mirror sector's alone, not the whole
stability the sphere's flags read, so its curve is drawn solid and the legend says there is no stability data.
"""
from dataclasses import replace

import numpy as np

from .quantities import branch_discretisation
from ..analysis.surface.meridian.capsule import CapsuleSurfaceBasis
from ..io.run_file import stored_scene
from ..scene.tables import Shape
from ..surface.measures import pole_stretch


def stored_meridian_basis(run: dict, name: str) -> CapsuleSurfaceBasis:
    """The CapsuleSurfaceBasis of the capsule's stored branch ``name``: its parent's discretisation (its stored
    attributes) at the branch's ``degree``, even in z where ``equator``, the branch's ``mode_degree``, ``orders``
    and ``n_phi`` (capsule.py: the final basis of its trace)."""
    attrs = run["meridian_surface"][name]["attrs"]
    geometry = stored_scene(run).geometry
    if geometry.shape != Shape.CAPSULE:
        raise ValueError(f"geometry.shape: {geometry.shape.value} (allowed: capsule, whose branches are drawn here)")
    parent = branch_discretisation(run["branches"][attrs["parent_branch"]])
    degree = int(attrs["degree"])
    disc = replace(parent, symmetric=bool(attrs["equator"]),
                   **({} if degree == parent.degree else {"degree": degree, "quadrature": 0}))
    return CapsuleSurfaceBasis(disc, geometry, int(attrs["mode_degree"]), tuple(int(m) for m in attrs["orders"]),
                               int(attrs["n_phi"]), bool(attrs["equator"]))


def with_meridian_branches(run: dict) -> dict:
    """``run`` with its capsule's non-axisymmetric branches among its ``branches`` (module docstring); ``run``
    itself where it has none or has them already."""
    found = run.get("meridian_surface") or {}
    if set(found) <= set(run["branches"]):
        return run
    branches = dict(run["branches"])
    for name, b in found.items():
        attrs, basis = b["attrs"], stored_meridian_basis(run, name)
        stretches = np.array([[pole_stretch(basis, c, theta) for theta in (0.0, np.pi)] for c in b["coefficients"]])
        parent = run["branches"][attrs["parent_branch"]]["attrs"]
        branches[name] = {
            "attrs": attrs | {"parent_branch_point": int(attrs["parent_zero"]), "M": parent["M"], "parameter": "P",
                              "reflection_of": attrs.get("image_of", "")},
            "pressure": b["pressure"], "volume": b["volume"], "amplitude": b["amplitude"],
            "coefficients": b["coefficients"], "lam2_top": stretches[:, 0], "lam2_bottom": stretches[:, 1],
            "special_points": [], "stability": {}}
    return run | {"branches": branches}
