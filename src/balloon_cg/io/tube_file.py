"""A tube's run file (format ``balloon-cg-tube/1``, docs/hdf5.md "Tube run files"): the branches of
tube/picture.py, written atomically (io/hdf5.py), read back checked.

Root attributes: the format, the scene (name, TOML), the shape and its parameters (``shape``, ``length``, ``ends``,
``axial_stretch``: NaN where the ends' distance is free), the discretisation (``degree``, ``quadrature``),
``maxwell_pressure`` (NaN where there is none), ``control`` (the scene's loading.control, whose stability reading and
folds count: files before it have none, read as "pressure"), ``not_started`` (one line "name: why" per switched
branch whose first step did not converge, "" for none; files before it have none, read as ""), the verdict
(``complete``, ``incomplete_gaps``/``_branches``/``_messages``: tube/picture.gaps, as a run file's; files before it
have none) and the provenance. One group per branch under
/branches/<name>/:
per point ``unknowns`` (n, size: u of galerkin/interval.py), ``pressure``, ``volume`` (V/V0), ``unstable_pressure``,
``unstable_volume`` and ``unstable_gas`` (negative eigenvalues of ∂R/∂u, on δV = 0, and of ∂R/∂u + (P/Ṽ) g gᵀ:
tube/stability.py; files before gas control have no ``unstable_gas``), ``smallest_stress`` (the smallest
principal stress: negative where the membrane is compressed, tube/stability.py), ``crest_height`` (the height η of
the largest radius, the bulge's crest, from the tube's middle plane: IntervalDiscretisation.crest), ``tail`` and
``first_integral_spread`` (the state's Legendre tail and the spread of H = λ1Φ_1 − Φ along the tube: tube/accuracy.py;
files before them have none), ``lowest_even``/
``lowest_odd`` (the mirror blocks' lowest eigenvalues, on the primary branch), on a voltage continuation (tube/voltage.py:
P fixed) ``voltage`` (Φ̄, also per located point), on a continuation in the held distance of the ends (tube/stretch.py: P
fixed) ``axial_stretch`` (λ, each state's λ̄, also per located point), with stability.m_max ≥ 1 ``lowest_m<m>``
(n, 3) and ``unstable_m<m>`` for m = 1..m_max (tube/azimuthal.py; the branch's attribute ``m_max``, 0 or absent: m ≥ 1
not assessed; in a coil's field on sliding ends also ``lowest_m1_held``, ``unstable_m1_held``: the held tube's m = 1
block, the translation removed; the free one's is ``lowest_m1``), the located zeros of their eigenvalues under
azimuthal_points/ (``held`` 1 for the held block's: files before it have none, read as 0; ``critical_modes``: the
eigenvector at each, files before it have none, read as None); its located points under
special_points/ (``kind``, ``block``, ``status``, ``note`` (a UZ point's event, "volume_ratio = 3"; files before
it have none), ``index``, ``pressure``, ``volume``, ``smallest_stress``,
``crest_height``, ``unknowns``), and its stop (``stop_code``, ``stop_message`` attributes); a switched branch
("bulge", "bulge_<label>": tube/picture.branch_name) has the attributes ``parent_branch``, ``parent_label`` (the
label of the branch point it was born at) and ``rejoins_label`` (where it rejoined the parent, −1: it did not; files
before them have none). A ``critical`` run adds
/onset (tube/onset.py: the first odd branch point followed in the parameter ``parameter`` from ``q0``): per point
``q``, ``pressure``, ``volume``, ``crest_height``, ``unknowns`` and ``modes`` (the odd null vector; read back with
``hoop_stretch``, the largest radius ρ of each state, from its unknowns) and ``tail`` (each state's Legendre tail:
files before it have none); its folds in q under folds/ (``q``, ``pressure``, ``status``, ``tail``: files before it
have none, read as NaN); ``stop_code``, ``stop_message``. ``interrupted``: the stage a signal
stopped (tube/picture.Stage: ``primary``, ``bulge``, ``onset``; its branch or curve ends ``interrupted`` where it had
started, and is absent where it had not; ``modes``: the branches whole, no m ≥ 1 blocks; ``frequencies``: the branches
whole, the frequencies of the branches finished before the signal only), "" where the work is whole (files before it have none: read as "").
With [dynamics] frequencies, each branch's natural frequencies under frequencies/ (io/tube_frequencies.py). With
[surface] branches, the non-axisymmetric branches under /surface_branches/ (io/tube_surface_file.py).
"""
import math
from pathlib import Path

import h5py
import numpy as np

from .hdf5 import atomic_file, checksummed, plain, provenance, write_strings
from .layout import FileError, opened
from .run_file import verdict_attrs
from .tube_frequencies import read_tube_frequencies, write_tube_frequencies
from .tube_surface_file import read_surface_branches, write_surface_branches
from ..galerkin.equilibrium import Equilibrium
from ..galerkin.interval import IntervalDiscretisation, Mirror
from ..galerkin.interval_elements import ElementInterval, element_interval
from ..scene.tables import Ends
from ..analysis.results import IntervalStop, Kind, StopCode
from ..numerics.continuation import RootStatus, Stop, TraceStop
from ..tube.accuracy import accuracy
from ..tube.azimuthal import COUNT, operators
from ..tube.primary import volume_ratio
from ..tube.results import IntervalBranch, IntervalSpecial
from ..scene.loading import Control

FORMAT = "balloon-cg-tube/1"
POINT_COLUMNS = ("pressure", "volume", "unstable_pressure", "unstable_volume", "smallest_stress")
CREST = "crest_height"  # per point and located point: η of the largest radius (files before it have none)
GAS = "unstable_gas"  # per point: unstable directions under gas control (files before it have none)
ACCURACY = ("tail", "first_integral_spread")  # per point: tube/accuracy.accuracy (files before them have none)
SPECIAL_NUMBERS = ("index", "pressure", "volume", "smallest_stress")
CURVE_COLUMNS = ("q", "pressure", "volume", CREST)
HOOP = "hoop_stretch"  # the onset curve's largest radius per point (read back from its unknowns: crest_hoops)
SPECIAL_TEXT = ("kind", "block", "status")
VOLTAGE = "voltage"  # per point and located point of a voltage continuation (tube/voltage.py; others have none)
STRETCH = "axial_stretch"  # per point and located point of a continuation in λ (tube/stretch.py; others have none)
NOTE = "note"  # per located point: a UZ point's event (files before tube events have none: read as "")
AZIMUTHAL_LIMIT = 8  # the largest stability.m_max (scene/tables.py)
MODES = "critical_modes"  # per located m ≥ 1 zero: its eigenvector (files before it have none)
HELD_M1 = "1 held"  # read_tube_run's key of the held tube's m = 1 block (beside the free blocks' m)


#: name: (units, long_name, description) of a tube run file's datasets (io/schema.py's VARIABLES are the sphere's)
TUBE_VARIABLES = {
    "point": ("", "point index", "index of the point along the branch (or onset curve), in continuation order"),
    "special": ("", "located point index", "index of the located point on its branch"),
    "unknown": ("", "unknown index", "u of galerkin/interval.py: λ2's coefficients, λ̄, η's bubbles (docs/hdf5.md)"),
    "mode": ("", "odd unknown index", "index into the odd block of u (galerkin/interval.py's block('odd'))"),
    "unknowns": ("1", "unknowns u", "u of galerkin/interval.py (docs/hdf5.md)"),
    "pressure": ("1", "pressure P", "P = P̄ R / (T0 μ/2), R the reference radius"),
    "volume": ("1", "V/V0", "enclosed volume over the reference tube's, V0 = πL R³"),
    "unstable_pressure": ("", "unstable directions, pressure control", "negative eigenvalues of ∂R/∂u"),
    "unstable_volume": ("", "unstable directions, volume control", "negative eigenvalues of ∂R/∂u on δV = 0"),
    GAS: ("", "unstable directions, gas control", "negative eigenvalues of ∂R/∂u + (P/Ṽ) g gᵀ (P V = n fixed)"),
    "smallest_stress": ("1", "smallest principal stress", "over the nodes, in μ/2: negative where compressed"),
    CREST: ("1", "crest height", "height η of the largest radius from the tube's middle plane, in R"),
    "tail": ("1", "Legendre tail", "spectral error estimate of the state over its mean radius (tube/accuracy.py)"),
    "first_integral_spread": ("1", "spread of H", "(max H − min H)/max |H| over the nodes, H = λ1Φ_1 − Φ (constant "
                              "on an exact state; NaN in a coil field)"),
    "lowest_even": ("1", "lowest eigenvalue, even block", "of the mirror-symmetric block of ∂R/∂u"),
    "lowest_odd": ("1", "lowest eigenvalue, odd block", "of the mirror-antisymmetric block of ∂R/∂u"),
    **{f"lowest_m{m}": ("1", f"lowest eigenvalues, m = {m}", f"the lowest μ of the cos {m}φ block, H c = μ G c "
                        "(tube/azimuthal.py), ascending") for m in range(1, AZIMUTHAL_LIMIT + 1)},
    **{f"unstable_m{m}": ("", f"unstable directions, m = {m}", f"negative eigenvalues of the cos {m}φ block (pressure "
                          "and volume control alike)") for m in range(1, AZIMUTHAL_LIMIT + 1)},
    "lowest_m1_held": ("1", "lowest eigenvalues, m = 1, held", "the lowest μ of the cos φ block of the tube held at "
                       "its centroid (the sideways translation removed: tube/azimuthal.py), ascending"),
    "unstable_m1_held": ("", "unstable directions, m = 1, held", "negative eigenvalues of the held tube's cos φ block"),
    "held": ("", "held block", "1: a zero of the held tube's m = 1 block, 0: of the free one's"),
    "eigenvalue": ("", "eigenvalue index", "the lowest eigenvalues of a block, ascending"),
    "m": ("", "azimuthal number", "the cos mφ block whose eigenvalue vanishes"),
    "order": ("", "eigenvalue number", "which eigenvalue of the block vanishes (ascending, from 0)"),
    "value": ("1", "eigenvalue there", "the located eigenvalue at the located state (0 to the location's accuracy)"),
    "kind": ("", "located point kind", "LP fold in P, LV fold in V, BP branch point, UZ an event's value reached"),
    VOLTAGE: ("1", "voltage Φ̄", "a voltage continuation's Φ̄ (tube/voltage.py: P fixed), per point and located point"),
    STRETCH: ("1", "held axial stretch λ", "a continuation in the held distance of the ends' λ (tube/stretch.py: P "
              "fixed), the ends at λL; per point and located point"),
    NOTE: ("", "event", "a UZ point's event, quantity = value (tube/events.py); empty for the others"),
    "block": ("", "mirror block", "the block of a BP whose eigenvalue vanishes (even, odd)"),
    "status": ("", "location status", "located or nearest"),
    "index": ("", "point index", "the located point lies between points index and index + 1"),
    "q": ("1", "second parameter", "the onset curve's parameter (the group's attribute parameter: M, voltage or "
          "axial_stretch)"),
    "modes": ("1", "odd null vector", "the odd block's null vector φ at the onset"),
    "coefficient": ("", "coefficient index", "index into the m ≥ 1 perturbation's coefficients (R's, T's, Z's: "
                    "tube/azimuthal.py)"),
    MODES: ("1", "critical mode", "the block's eigenvector at the located zero, coefficients of (R, T, Z) with "
            "cᵀGc = 1 (tube/azimuthal.critical_mode)"),
}


def _dimensions(group, rows: str, axes: dict) -> None:
    """Named dimensions (netCDF-4, so that xarray with h5netcdf opens ``group`` alone with them): the scale ``rows``
    (0 … n − 1, n the rows of its datasets) and those of ``axes`` ({second axis's scale name: length}), attached to
    every dataset (its first axis ``rows``; a 2-D dataset's second: ``unknown``, ``mode`` for ``modes``,
    ``eigenvalue`` for ``lowest_m<m>``) and each described from TUBE_VARIABLES."""
    items = [(name, item) for name, item in group.items() if isinstance(item, h5py.Dataset)]
    n = items[0][1].shape[0]
    scales = {name: checksummed(group, name, np.arange(length, dtype=np.int64))
              for name, length in {rows: n, **axes}.items()}
    for name, scale in scales.items():
        scale.make_scale(name)
        _describe(scale, name)
    for name, item in items:
        item.dims[0].attach_scale(scales[rows])
        if item.ndim == 2:
            second = {"modes": "mode", MODES: "coefficient"}.get(name, "eigenvalue" if name.startswith("lowest_m")
                                                                  else "unknown")
            item.dims[1].attach_scale(scales[second])
        _describe(item, name)


def _describe(dataset, name: str) -> None:
    units, long_name, description = TUBE_VARIABLES[name]
    dataset.attrs.update(({"units": units} if units else {}) | {"long_name": long_name, "description": description})


class TubeFileError(FileError):
    """A file that is not a readable tube run file (names the file and what is missing or wrong)."""


def write_tube_run(path, scene, picture, force: bool = False, command: str | None = None) -> Path:
    """Write ``picture`` (tube/picture.TubePicture) traced for ``scene`` to ``path`` atomically."""
    with atomic_file(path, force) as f:
        write_tube(f, scene, picture, command)
    return Path(path)


def write_tube(f, scene, picture, command: str | None = None) -> None:
    """The root attributes and groups of a tube run file (module docstring) into the open file or group ``f`` (a
    tube run file's root, a sweep member's: io/sweep_file.py)."""
    geometry, primary = scene.geometry, picture.branches["primary"]
    held = math.nan if geometry.axial_stretch is None else geometry.axial_stretch
    attrs = {"format": FORMAT, "scene_name": scene.name, "scene_toml": scene.text, "shape": geometry.shape.value,
             "length": geometry.length, "ends": geometry.ends.value, "axial_stretch": held,
             "degree": primary.disc.degree, "quadrature": primary.disc.quadrature,
             "maxwell_pressure": math.nan if picture.maxwell is None else picture.maxwell,
             "control": scene.loading.control.value,
             "not_started": "\n".join(f"{name}: {why}" for name, why in picture.not_started),
             "interrupted": "" if picture.interrupted is None else picture.interrupted.value,
             "title": f"balloon-cg run of the tube scene {scene.name}", **provenance(command)}
    f.attrs.update(attrs | _verdict(picture))
    for name, branch in picture.branches.items():
        group = f.create_group(f"branches/{name}")
        group.attrs.update({"stop_code": branch.stop.code.value, "stop_message": branch.stop.message,
                            **_lineage(branch), **_layout(branch.disc)})
        checksummed(group, "unknowns", branch.states)
        eq = Equilibrium(scene, branch.disc)
        for column, values in (("pressure", branch.pressure), ("volume", branch.volume),
                               ("unstable_pressure", branch.unstable["pressure"]),
                               ("unstable_volume", branch.unstable["volume"]), (GAS, branch.unstable["gas"]),
                               ("smallest_stress", branch.smallest_stress),
                               (CREST, crest_heights(branch.disc, branch.states)),
                               *zip(ACCURACY, accuracy(eq, branch.states, branch.voltage))):
            checksummed(group, column, values)
        if branch.voltage is not None:
            checksummed(group, VOLTAGE, branch.voltage)
        if branch.stretched:
            checksummed(group, STRETCH, branch.held_stretch())
        for block, values in branch.lowest.items():
            checksummed(group, f"lowest_{block.value}", values)
        modes = None if picture.modes is None else picture.modes[name]
        group.attrs["m_max"] = 0 if modes is None else len(modes.lowest)
        if modes is not None:
            for m in modes.lowest:
                checksummed(group, f"lowest_m{m}", modes.lowest[m])
                checksummed(group, f"unstable_m{m}", modes.unstable[m])
            if modes.held is not None:
                checksummed(group, "lowest_m1_held", modes.held["lowest"])
                checksummed(group, "unstable_m1_held", modes.held["unstable"])
            _write_crossings(group.create_group("azimuthal_points"), modes.crossings, branch.disc.size,
                             operators(branch.disc)[1].shape[0])
        special = group.create_group("special_points")
        s = branch.special
        write_strings(special, "kind", [p.kind.value for p in s])
        write_strings(special, "block", ["" if p.block is None else p.block.value for p in s])
        write_strings(special, "status", [p.status.value for p in s])
        write_strings(special, NOTE, [p.note for p in s])
        checksummed(special, "index", np.array([p.index for p in s], dtype=int))
        checksummed(special, "pressure", np.array([p.pressure for p in s], dtype=float))
        volume = [volume_ratio(eq, np.append(p.u, p.pressure)) for p in s]
        checksummed(special, "volume", np.array(volume, dtype=float))
        checksummed(special, "smallest_stress", np.array([p.smallest_stress for p in s], dtype=float))
        if branch.voltage is not None:
            checksummed(special, VOLTAGE, np.array([p.voltage for p in s], dtype=float))
        if branch.stretched:
            checksummed(special, STRETCH, np.array([p.u[branch.disc.axial_index] for p in s], dtype=float))
        checksummed(special, CREST, crest_heights(branch.disc, [p.u for p in s]))
        checksummed(special, "unknowns", np.array([p.u for p in s], dtype=float).reshape(len(s), branch.disc.size))
        _dimensions(group, "point", {"unknown": branch.disc.size} | ({} if modes is None else {"eigenvalue": COUNT}))
        _dimensions(special, "special", {"unknown": branch.disc.size})
        if picture.frequencies is not None and name in picture.frequencies:  # (a signal: only the finished ones)
            write_tube_frequencies(group, picture.frequencies[name])
    write_surface_branches(f, picture.surface)
    if picture.onset is not None:
        _write_onset(f.create_group("onset"), picture.onset)


def _verdict(picture) -> dict:
    """``complete`` and ``incomplete_gaps``/``_branches``/``_messages`` (io/run_file.verdict_attrs) of tube/picture.gaps:
    what ``inspect`` shows as the result, what ``run``'s exit code follows."""
    from ..tube.picture import gaps  # here: reading a file does not need the tracers

    return verdict_attrs(found=gaps(picture))


def _layout(disc) -> dict:
    """A branch traced on spectral elements (tube/front.py): ``element_order`` and ``element_bounds`` (the inner
    bounds in x = 2S/L − 1); none on the root's Legendre series."""
    if not isinstance(disc, ElementInterval):
        return {}
    return {"element_order": disc.order, "element_bounds": np.array(disc.bounds, dtype=float)}


def _lineage(branch) -> dict:
    """A switched branch's attributes ``parent_branch``, ``parent_label`` (the branch point it was born at) and
    ``rejoins_label`` (where it rejoined its parent branch, −1: it did not); none for the primary branch."""
    if branch.parent is None:
        return {}
    return {"parent_branch": branch.parent[0], "parent_label": branch.parent[1],
            "rejoins_label": -1 if branch.rejoins is None else branch.rejoins}


def _write_crossings(group, found, size: int, coefficients: int) -> None:
    """The located zeros of the m ≥ 1 eigenvalues (tube/azimuthal_crossings.py): per point ``m``, ``order``,
    ``index``, ``pressure``, ``volume``, ``value``, ``held``, ``status``, ``unknowns`` and ``critical_modes`` (the
    eigenvector there: ``coefficients`` of (R, T, Z), tube/azimuthal.critical_mode)."""
    for column, kind in (("m", int), ("order", int), ("index", int), ("pressure", float), ("volume", float),
                         ("value", float), ("held", int)):
        checksummed(group, column, np.array([getattr(c, column) for c in found], dtype=kind))
    write_strings(group, "status", [c.status.value for c in found])
    checksummed(group, "unknowns", np.array([c.u for c in found], dtype=float).reshape(len(found), size))
    checksummed(group, MODES, np.array([c.mode for c in found], dtype=float).reshape(len(found), coefficients))
    _dimensions(group, "special", {"unknown": size, "coefficient": coefficients})


def crest_heights(disc: IntervalDiscretisation, states) -> np.ndarray:
    """η of the largest radius of each state (IntervalDiscretisation.crests)."""
    states = np.asarray(states, dtype=float)
    return disc.crests(states)[1] if len(states) else np.zeros(0)


def crest_hoops(disc: IntervalDiscretisation, states) -> np.ndarray:
    """ρ (the hoop stretch, R = 1) at the crest of each state (IntervalDiscretisation.crests): its largest radius."""
    states = np.atleast_2d(np.asarray(states, dtype=float))
    if not len(states):
        return np.zeros(0)
    return disc.radius(states, 2 * disc.crests(states)[0] / disc.length - 1)[0]


def _write_onset(group, curve) -> None:
    group.attrs.update({"parameter": curve.name, "q0": curve.q0, "stop_code": curve.stop.code.value,
                        "stop_message": curve.stop.message})
    for column, values in (("q", curve.q), ("pressure", curve.pressure), ("volume", curve.volume),
                           (CREST, crest_heights(curve.disc, curve.states)), ("unknowns", curve.states),
                           ("modes", curve.modes), ("tail", curve.tail)):
        checksummed(group, column, values)
    folds = group.create_group("folds")
    checksummed(folds, "q", np.asarray(curve.fold_q, dtype=float))
    checksummed(folds, "tail", np.asarray(curve.fold_tail, dtype=float))
    checksummed(folds, "pressure", np.array([p.pressure for p in curve.folds], dtype=float))
    write_strings(folds, "status", [p.status.value for p in curve.folds])
    _dimensions(group, "point", {"unknown": curve.states.shape[1], "mode": curve.modes.shape[1]})
    _dimensions(folds, "special", {})


def read_tube_run(path) -> dict:
    """{'path', 'attrs', 'branches': {name: {'attrs', the point columns, 'unknowns', 'lowest_*',
    'special_points': [dict per point] , 'special_unknowns', 'frequencies' (None: not asked for)}}}; TubeFileError
    for anything that is not one."""
    path = Path(path)
    with opened(path, TubeFileError) as f:
        fmt = plain(f.attrs.get("format"))
        if fmt != FORMAT:
            raise TubeFileError(path, f"not a balloon-cg tube run file (format {fmt!r}, expected {FORMAT!r})")
        return {"path": str(path), **read_tube(f, path)}


def read_tube(f, path, where: str = "") -> dict:
    """{'attrs', 'branches', 'onset', 'surface_branches'} of the tube run written by ``write_tube`` into the open file
    or group ``f`` (``where``: its path in the file ``path``, for the messages); TubeFileError naming what is
    missing."""
    attrs = {"interrupted": "", "control": "pressure", "not_started": ""} | {k: _text(plain(v))
                                                                             for k, v in f.attrs.items()}
    if "branches" not in f or "primary" not in f["branches"]:
        raise TubeFileError(path, f"no {where}/branches/primary group")
    branches = {}
    for name, group in f["branches"].items():
        missing = [c for c in ("unknowns", *POINT_COLUMNS, "special_points") if c not in group]
        if missing:
            raise TubeFileError(path, f"{where}/branches/{name}: missing {', '.join(missing)}")
        branch = {"attrs": {k: _text(plain(v)) for k, v in group.attrs.items()}, "unknowns": group["unknowns"][()]}
        n = branch["unknowns"].shape[0]
        optional = tuple(c for c in (CREST, GAS, VOLTAGE, STRETCH, *ACCURACY, *(f"lowest_{b.value}" for b in Mirror))
                         if c in group)
        for column in POINT_COLUMNS + optional:
            branch[column] = group[column][()]
            if branch[column].shape != (n,):
                raise TubeFileError(path, f"{where}/branches/{name}/{column}: shape {branch[column].shape}, expected "
                                          f"({n},)")
        special = group["special_points"]
        columns = {c: list(special[c].asstr()[()]) for c in SPECIAL_TEXT}
        columns[NOTE] = list(special[NOTE].asstr()[()]) if NOTE in special else [""] * len(columns["kind"])
        columns |= {c: special[c][()] for c in SPECIAL_NUMBERS + tuple(c for c in (CREST, VOLTAGE, STRETCH) if c in special)}
        branch["special_points"] = [{c: plain(v[i]) for c, v in columns.items()}
                                    for i in range(len(columns["kind"]))]
        branch["azimuthal"] = _read_modes(path, group, n, f"{where}/branches/{name}")
        branch["special_unknowns"] = special["unknowns"][()]
        branch["frequencies"] = read_tube_frequencies(path, group, n, len(branch["special_points"]), TubeFileError)
        branches[name] = branch
    onset = None if "onset" not in f else _read_onset(path, f["onset"], discretisation(attrs,
                                                                                          branches["primary"]["attrs"]))
    return {"attrs": attrs, "branches": branches, "onset": onset,
            "surface_branches": read_surface_branches(f, path, TubeFileError)}


def _read_modes(path, group, n: int, where: str) -> dict:
    """{m: {'lowest': (n, COUNT), 'unstable': (n,), 'points': [dict per located zero]}} for m = 1..the group's
    ``m_max`` of the free tube's blocks, and under the key '1 held' the held tube's m = 1 block where the file has
    one ({}: not assessed; 'points' empty in files written before they were located; a point's 'held' False in
    files before the held block)."""
    out = {}
    located = group.get("azimuthal_points")
    points = [] if located is None else [
        {"m": int(m), "order": int(k), "index": int(i), "pressure": float(p), "volume": float(v), "value": float(x),
         "status": s} for m, k, i, p, v, x, s in zip(*(located[c][()] for c in ("m", "order", "index", "pressure",
                                                                              "volume", "value")),
                                                    located["status"].asstr()[()])]
    held = [False] * len(points) if located is None or "held" not in located else located["held"][()].astype(bool)
    modes = [None] * len(points) if located is None or MODES not in located else list(located[MODES][()])
    for p, h, mode in zip(points, held, modes):
        p["held"], p["mode"] = bool(h), mode
    blocks = [(m, f"lowest_m{m}", f"unstable_m{m}", False) for m in range(1, int(group.attrs.get("m_max", 0)) + 1)]
    blocks += [(HELD_M1, "lowest_m1_held", "unstable_m1_held", True)] if "lowest_m1_held" in group else []
    for key, lowest, unstable, is_held in blocks:
        missing = [c for c in (lowest, unstable) if c not in group]
        if missing:
            raise TubeFileError(path, f"{where}: m_max = {group.attrs['m_max']} but {', '.join(missing)} missing")
        m = 1 if is_held else key
        out[key] = {"lowest": group[lowest][()], "unstable": group[unstable][()],
                    "points": [p for p in points if p["m"] == m and p["held"] == is_held]}
        if out[key]["lowest"].shape[0] != n or out[key]["unstable"].shape != (n,):
            raise TubeFileError(path, f"{where}/{lowest}, {unstable}: not one row per point ({n})")
    return out


def tube_labels(run: dict) -> list:
    """The labels of a tube run (``read_tube_run``'s dict), as ``inspect`` numbers them and ``continue`` takes them:
    (branch, its k-th located point, the point) for the primary branch's located points, then the other branches'."""
    ordered = sorted(run["branches"].items(), key=lambda item: item[0] != "primary")
    return [(name, k, s) for name, b in ordered for k, s in enumerate(b["special_points"])]


def tube_row(run: dict) -> dict:
    """What a tube run (``read_tube``'s dict) found, as a sweep's table row (io/sweep_file.py): the uniform
    pressure maximum ``P_max`` (the primary branch's first LP), the onset of bulging ``P_onset``, ``V_onset`` (its
    first odd BP: P and V/V0), the bulge's volume fold ``P_LV``, ``V_LV`` (its first LV) and Maxwell's pressure
    ``P_M``; NaN where there is none."""
    def first(branch: str, kind: str, block: str = "") -> dict:
        points = run["branches"].get(branch, {"special_points": []})["special_points"]
        return next((s for s in points if s["kind"] == kind and s["block"] == block),
                    {"pressure": np.nan, "volume": np.nan})

    fold, onset, lv = first("primary", "LP"), first("primary", "BP", Mirror.ODD.value), first("bulge", "LV")
    return {"P_max": fold["pressure"], "P_onset": onset["pressure"], "V_onset": onset["volume"],
            "P_LV": lv["pressure"], "V_LV": lv["volume"], "P_M": float(run["attrs"]["maxwell_pressure"])}


def _read_onset(path, group, disc: IntervalDiscretisation) -> dict:
    """The /onset group: its attributes, the point columns, ``unknowns``, ``modes``, ``folds`` (dict per fold) and
    ``hoop_stretch``, the largest radius of each state (``crest_hoops``; ``disc``: the primary branch's)."""
    missing = [c for c in (*CURVE_COLUMNS, "unknowns", "modes", "folds") if c not in group]
    if missing:
        raise TubeFileError(path, f"/onset: missing {', '.join(missing)}")
    onset = {"attrs": {k: _text(plain(v)) for k, v in group.attrs.items()}}
    n = group["q"].shape[0]
    for column in (*CURVE_COLUMNS, "unknowns", "modes", *(["tail"] if "tail" in group else [])):
        onset[column] = group[column][()]
        if onset[column].shape[0] != n:
            raise TubeFileError(path, f"/onset/{column}: {onset[column].shape[0]} rows, expected {n}")
    folds = group["folds"]
    status = list(folds["status"].asstr()[()])
    tails = folds["tail"][()] if "tail" in folds else [math.nan] * len(status)  # files before it have none
    onset["folds"] = [{"q": float(q), "pressure": float(p), "status": s, "tail": float(t)}
                      for q, p, s, t in zip(folds["q"][()], folds["pressure"][()], status, tails)]
    onset[HOOP] = crest_hoops(disc, onset["unknowns"])
    return onset


def stored_branch(run: dict, name: str, params) -> IntervalBranch:
    """The branch ``name`` of a tube run (``read_tube_run``'s dict) as tube/results.IntervalBranch (its points, located
    points and stop as written; ``params``: the branch's parameters, tube/primary.scene_parameters), to restart from
    (``continue``)."""
    b = run["branches"][name]
    special = tuple(IntervalSpecial(Kind(s["kind"]), u, float(s["pressure"]), int(s["index"]), RootStatus(s["status"]),
                                    Mirror(s["block"]) if s["block"] else None, float(s["smallest_stress"]),
                                    s[NOTE], float(s.get(VOLTAGE, math.nan)))
                    for s, u in zip(b["special_points"], b["special_unknowns"]))
    code = b["attrs"]["stop_code"]
    stop = Stop(next(enum(code) for enum in (IntervalStop, StopCode, TraceStop) if code in enum._value2member_map_),
                b["attrs"]["stop_message"])
    lowest = {block: b[f"lowest_{block.value}"] for block in Mirror if f"lowest_{block.value}" in b}
    unstable = {control: b[f"unstable_{control.value}"] for control in Control if f"unstable_{control.value}" in b}
    attrs = b["attrs"]
    parent = (attrs["parent_branch"], int(attrs["parent_label"])) if "parent_label" in attrs else None
    rejoins = int(attrs["rejoins_label"]) if attrs.get("rejoins_label", -1) >= 0 else None
    return IntervalBranch(discretisation(run["attrs"], b["attrs"]), b["unknowns"], b["pressure"], b["volume"], lowest,
                          unstable, special, stop, b["smallest_stress"], params, voltage=b.get(VOLTAGE), stretched=STRETCH in b,
                          parent=parent,
                          rejoins=rejoins)


def discretisation(attrs: dict, branch: dict | None = None) -> IntervalDiscretisation:
    """The interval discretisation a tube run file's unknowns are on: its root attributes' Legendre series, or the
    spectral elements of a branch whose attributes ``branch`` name them (``element_order``, ``element_bounds``)."""
    held = attrs["axial_stretch"]
    held = None if math.isnan(held) else float(held)
    if branch is not None and "element_order" in branch:
        return element_interval(float(attrs["length"]), int(branch["element_order"]),
                                np.atleast_1d(branch["element_bounds"]), Ends(attrs["ends"]), int(attrs["quadrature"]),
                                held)
    return IntervalDiscretisation(int(attrs["degree"]), float(attrs["length"]), int(attrs["quadrature"]),
                                  Ends(attrs["ends"]), held)


def _text(value):
    return value.decode("utf-8") if isinstance(value, bytes) else value
