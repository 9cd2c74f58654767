"""A tube's run file (format ``balloon-cg-tube/1``, docs/hdf5.md "Tube run files"): the branches of
tube/picture.py, written atomically (io/hdf5.py), read back checked.

Root attributes: the format, the scene (name, TOML), the shape and its parameters (``shape``, ``length``, ``ends``,
``axial_stretch``: NaN where the ends' distance is free), the discretisation (``degree``, ``quadrature``),
``maxwell_pressure`` (NaN where there is none) and the provenance. One group per branch under /branches/<name>/:
per point ``unknowns`` (n, size: u of galerkin/interval.py), ``pressure``, ``volume`` (V/V0), ``unstable_pressure``
and ``unstable_volume`` (negative eigenvalues of ∂R/∂u without and with δV = 0), ``smallest_stress`` (the smallest
principal stress: negative where the membrane is compressed, tube/stability.py), ``lowest_even``/``lowest_odd`` (the
mirror blocks' lowest eigenvalues, on the primary branch); its located points under special_points/ (``kind``,
``block``, ``status``, ``index``, ``pressure``, ``volume``, ``smallest_stress``, ``unknowns``), and its stop
(``stop_code``, ``stop_message`` attributes).
"""
import math
from pathlib import Path

import numpy as np

from .hdf5 import atomic_file, checksummed, plain, provenance, write_strings
from .layout import FileError, opened
from ..galerkin.equilibrium import Equilibrium
from ..galerkin.interval import IntervalDiscretisation, Mirror
from ..scene.tables import Ends
from ..tube.primary import volume_ratio

FORMAT = "balloon-cg-tube/1"
POINT_COLUMNS = ("pressure", "volume", "unstable_pressure", "unstable_volume", "smallest_stress")
SPECIAL_NUMBERS = ("index", "pressure", "volume", "smallest_stress")
SPECIAL_TEXT = ("kind", "block", "status")


class TubeFileError(FileError):
    """A file that is not a readable tube run file (names the file and what is missing or wrong)."""


def write_tube_run(path, scene, picture, force: bool = False, command: str | None = None) -> Path:
    """Write ``picture`` (tube/picture.TubePicture) traced for ``scene`` to ``path`` atomically."""
    geometry, primary = scene.geometry, picture.branches["primary"]
    held = math.nan if geometry.axial_stretch is None else geometry.axial_stretch
    attrs = {"format": FORMAT, "scene_name": scene.name, "scene_toml": scene.text, "shape": geometry.shape.value,
             "length": geometry.length, "ends": geometry.ends.value, "axial_stretch": held,
             "degree": primary.disc.degree, "quadrature": primary.disc.quadrature,
             "maxwell_pressure": math.nan if picture.maxwell is None else picture.maxwell,
             "title": f"balloon-cg run of the tube scene {scene.name}", **provenance(command)}
    with atomic_file(path, force) as f:
        f.attrs.update(attrs)
        for name, branch in picture.branches.items():
            group = f.create_group(f"branches/{name}")
            group.attrs.update({"stop_code": branch.stop.code.value, "stop_message": branch.stop.message})
            checksummed(group, "unknowns", branch.states)
            for column, values in (("pressure", branch.pressure), ("volume", branch.volume),
                                   ("unstable_pressure", branch.unstable["pressure"]),
                                   ("unstable_volume", branch.unstable["volume"]),
                                   ("smallest_stress", branch.smallest_stress)):
                checksummed(group, column, values)
            for block, values in branch.lowest.items():
                checksummed(group, f"lowest_{block.value}", values)
            special = group.create_group("special_points")
            s = branch.special
            write_strings(special, "kind", [p.kind.value for p in s])
            write_strings(special, "block", ["" if p.block is None else p.block.value for p in s])
            write_strings(special, "status", [p.status.value for p in s])
            checksummed(special, "index", np.array([p.index for p in s], dtype=int))
            checksummed(special, "pressure", np.array([p.pressure for p in s], dtype=float))
            eq = Equilibrium(scene, branch.disc)
            volume = [volume_ratio(eq, np.append(p.u, p.pressure)) for p in s]
            checksummed(special, "volume", np.array(volume, dtype=float))
            checksummed(special, "smallest_stress", np.array([p.smallest_stress for p in s], dtype=float))
            checksummed(special, "unknowns", np.array([p.u for p in s], dtype=float).reshape(len(s), -1))
    return Path(path)


def read_tube_run(path) -> dict:
    """{'path', 'attrs', 'branches': {name: {'attrs', the point columns, 'unknowns', 'lowest_*',
    'special_points': [dict per point] , 'special_unknowns'}}}; TubeFileError for anything that is not one."""
    path = Path(path)
    with opened(path, TubeFileError) as f:
        fmt = plain(f.attrs.get("format"))
        if fmt != FORMAT:
            raise TubeFileError(path, f"not a balloon-cg tube run file (format {fmt!r}, expected {FORMAT!r})")
        attrs = {k: _text(plain(v)) for k, v in f.attrs.items()}
        if "branches" not in f or "primary" not in f["branches"]:
            raise TubeFileError(path, "no /branches/primary group")
        branches = {}
        for name, group in f["branches"].items():
            missing = [c for c in ("unknowns", *POINT_COLUMNS, "special_points") if c not in group]
            if missing:
                raise TubeFileError(path, f"/branches/{name}: missing {', '.join(missing)}")
            branch = {"attrs": {k: _text(plain(v)) for k, v in group.attrs.items()},
                      "unknowns": group["unknowns"][()]}
            n = branch["unknowns"].shape[0]
            for column in POINT_COLUMNS + tuple(f"lowest_{b.value}" for b in Mirror if f"lowest_{b.value}" in group):
                branch[column] = group[column][()]
                if branch[column].shape != (n,):
                    raise TubeFileError(path, f"/branches/{name}/{column}: shape {branch[column].shape}, expected "
                                              f"({n},)")
            special = group["special_points"]
            columns = {c: list(special[c].asstr()[()]) for c in SPECIAL_TEXT}
            columns |= {c: special[c][()] for c in SPECIAL_NUMBERS}
            branch["special_points"] = [{c: plain(v[i]) for c, v in columns.items()}
                                        for i in range(len(columns["kind"]))]
            branch["special_unknowns"] = special["unknowns"][()]
            branches[name] = branch
    return {"path": str(path), "attrs": attrs, "branches": branches}


def discretisation(attrs: dict) -> IntervalDiscretisation:
    """The interval discretisation a tube run file's unknowns are on (its root attributes)."""
    held = attrs["axial_stretch"]
    return IntervalDiscretisation(int(attrs["degree"]), float(attrs["length"]), int(attrs["quadrature"]),
                                  Ends(attrs["ends"]), None if math.isnan(held) else float(held))


def _text(value):
    return value.decode("utf-8") if isinstance(value, bytes) else value
