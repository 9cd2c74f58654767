"""Everything a tube scene asks for (``balloon-cg run`` on a tube): the primary branch with its folds and branch
points (tube/primary.py), the bulge branch switched at its first odd branch point (tube/bulge.py; sliding ends only:
on plugged ones the branch points are not trusted, docs/shapes.md) traced until it rejoins the mirror-symmetric
states, its largest hoop stretch passes ``continuation.stop_stretch`` or after ``continuation.max_points``, and
Maxwell's pressure of the uniform closed tube (model/tube.maxwell_pressure; closed ends only: ends held apart have
no single one)."""
from dataclasses import dataclass

from .bulge import bulge_branch
from .onset import OnsetCurve
from .primary import primary_branch
from .results import IntervalBranch
from ..galerkin.interval import Mirror
from ..model.tube import maxwell_pressure
from ..scene.tables import Ends


@dataclass(frozen=True)
class TubePicture:
    """The branches by name ("primary", "bulge" where one was switched), Maxwell's pressure (None where the
    uniform closed path has no maximum and minimum, or the ends are held) and, for ``critical``, the onset of bulging
    followed in a second parameter (tube/onset.py)."""

    branches: dict
    maxwell: float | None
    onset: OnsetCurve | None = None


def tube_picture(scene, primary_only: bool = False) -> TubePicture:
    """The primary branch and, unless ``primary_only``, the bulge branch of a tube scene (module docstring)."""
    primary = primary_branch(scene)
    branches: dict[str, IntervalBranch] = {"primary": primary}
    onset = primary.branch_points(Mirror.ODD)
    if not primary_only and onset and scene.geometry.ends == Ends.SLIDING:
        branches["bulge"] = bulge_branch(scene, primary, onset[0], stop_stretch=scene.continuation.stop_stretch)
    return TubePicture(branches, maxwell(scene))


def maxwell(scene) -> float | None:
    """Maxwell's pressure of the scene's uniform closed tube (None: ends held apart, or no maximum and minimum)."""
    found = None if scene.geometry.axial_stretch is not None else maxwell_pressure(scene.material)
    return None if found is None else float(found[0])
