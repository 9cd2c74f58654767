"""Run files (HDF5, format "balloon-cg/6"): traced branches with their provenance.

Layout::

    /                      attrs: format, scene_name, scene_toml, tolerance, control (loading.control), title,
                                  + provenance (io.hdf5: package_version, generated_digest, created (UTC ISO
                                  8601), command, Conventions, history: CF), complete (bool),
                                  incomplete_gaps, incomplete_branches, incomplete_messages (analysis.verdict),
                                  [phase_names, phase_seconds, total_seconds] (analysis.timing: seconds per
                                  phase and of the whole run, writing included), + extra_attrs
    /branches              attrs: snap_throughs (bool: the group /snap_throughs is written)
    /branches/<name>/      attrs: order, assessed (bool: a stability group), m (0: axisymmetric, this layout;
                                  m ≥ 1: a surface branch, below), stop_reason (for people), leg_labels,
                                  leg_stop_codes (per traced leg: 'up'/'down'/'forward' and a StopCode/TraceStop
                                  value), wall_time, degree,
                                  symmetric, pin_translation, quadrature, map_centres, map_widths,
                                  kernel_class, kernel_signature, M, chi, electric (the dielectric term is in
                                  the kernels), voltage (Φ̄, fixed unless it is the parameter), parameter
                                  ("P", "voltage" or "M": what the last unknown is), origin (traced,
                                  reflected, ...: analysis.results.Origin), gauge (held, free or both:
                                  the reading its states are equilibria of, analysis.results.Gauge),
                                  [parent_branch, parent_branch_point, rejoins_branch_point, reflection_of]
        point, unknown                                     dimension scales (0, 1, …)
        pressure, volume, amount (n = P V), lam2_top, lam2_bottom, eta_top, eta_bottom,
        lam1_equator, lam2_equator, converged, residual, error_estimate,
        newton_iterations, solved_degree, [voltage], [M]   (point,) (voltage: where electric; M: a
                                                           continuation in M, ``continue --parameter M``)
        unknowns                                           (point, unknown): Legendre unknowns u, then P (or Φ̄)
        theta                                              (theta,): linspace(0, π), a dimension scale
        profiles/lam1, profiles/lam2, profiles/rho, profiles/eta     (point, theta)
        special_points/kind (LP, TP, LV, LN, BP, EP, UZ), classification, block, gauge (held, free, both),
                       status (located, approximate), reason, stop_code, note, index, m, pressure, [voltage], [M], uncertainty, E2, E3, E4,
                       lam2_top, lam2_bottom, eta_top, eta_bottom                          (special,)
        special_points/state/unknowns                      (special, unknown): each point's own X
        stability/stable_*                                 (point,) flags
        stability/lowest_<block>                           (point, eigenvalue): lowest eigenvalues
        frequencies/omega2_<block>                         (point, frequency): the lowest Ω² = ω² R0² ρ/μ of the
                                                           block (NaN: fewer modes); attrs count, m_max ([dynamics])
        frequencies/perturbation_degree                    (point,): the degree they were computed at
        frequencies/special_omega2_<block>                 (special, frequency): the same at each special point's
                                                           own state
        frequencies/translation_axial, translation_lateral (point,): Ω² of the rigid translations (0 without a
                                                           field; > 0 the field restores, < 0 it pulls)
        frequencies/modes_<block>                          (special, frequency, component, theta): with [dynamics]
                                                           modes, the mode shapes of special_omega2_<block>
                                                           (δρ, δz, δφ over R0 for a unit modal mass)
    /branches/<name>/      a surface branch (analysis.results.SurfaceBranch, m ≥ 1): attrs order, m, parent_branch,
                           parent_branch_point, stop_reason, leg_labels, leg_stop_codes, wall_time, kernel_class,
                           kernel_signature, M, chi, electric, voltage, parameter, and its SphericalBasis:
                           surface_degree, surface_order, symmetry (k × 3 int), characters (k int), n_theta,
                           n_phi, map_centres, map_widths (the polar coordinate map; empty: none); origin,
                           [reflection_of] (a branch's image under a diagonal reflection), [reflection] (its
                           signs (s_x, s_y, s_z); absent: the rotation by π about the axis, (−1, −1, 1))
        point, coefficient, axis                           dimension scales (axis: x, y, z as 0, 1, 2)
        pressure, volume, amount, lam2_top, lam2_bottom (√J at the material poles), tilt (degrees),
        converged, residual, error_estimate, newton_iterations, [voltage]                    (point,)
        centroid                                           (point, axis)
        coefficients                                       (point, coefficient)
        special_points/ as above, state/unknowns (special, unknown): the coefficients c, then P (or Φ̄);
                           state/sector (special, reflection) int: a secondary branch point's symmetry sector, its
                           character ±1 under each reflection of ``symmetry`` (0 … 0: none; absent in older files)
        stability/lowest_<reading> (point, eigenvalue) for the readings held, free, held_volume, free_volume,
                           held_gas, free_gas; stable_pressure, stable_pressure_free, stable_volume, … (point,)
        frequencies/omega2_<reading>_<signs> (point, frequency), special_omega2_<reading>_<signs> (special,
                           frequency): Ω² of each symmetry sector (its characters under ``symmetry`` as + and −) under
                           each reading ([dynamics]: dynamics.surface); attrs count
    /snap_throughs/        from_branch, from_index, pressure, to_branch, to_index

Every dataset carries ``long_name`` and ``description``, and a quantity its ``units`` (``io.schema``); its axes
are netCDF-4 dimensions (HDF5 dimension scales), so ``xarray.open_dataset(path, engine="h5netcdf", group=...)``
names them.
A fold (LP, TP) or branch point (BP) lies between points ``index`` and ``index + 1``; its own X is in
special_points/state/unknowns, a group of its own so that special_points opens (xarray) as a table of one row per
special point. Files are written atomically (``io.hdf5.atomic_file``). Files of the previous formats still read:
"balloon-cg/4" (the X rows in special_points/unknowns), "balloon-cg/3" (no ``m`` attribute, no surface branches:
every branch reads as m = 0) and
"balloon-cg/2" (no volume, no dimension scales), and so do files without amount, control or the gas stability
flags (written before gas control), and files without ``gauge`` (written before the free balloon's branch points:
a branch's is read from its layout, ``legacy_gauge``; a special point's from its block, ``read_special``).
"""
import io
from pathlib import Path

import h5py
import numpy as np

from ..analysis.timing import Clock, Step
from ..scene.tables import Shape, parse_stored
from .hdf5 import atomic_file, checksummed, plain, provenance, write_strings
from .legacy import current
from .layout import (FileError, carries_checksums, check_columns, check_data, check_sizes, opened, reading, require_attrs,
                     require_group)
from .tube_surface_file import read_surface_branches, write_surface_branches
from .schema import FINITE, MODES, OMEGA2, SPECIAL_OMEGA2, attach_dimensions, check_described, coordinates, scale

FORMAT = "balloon-cg/6"
READABLE = (FORMAT, "balloon-cg/5", "balloon-cg/4", "balloon-cg/3", "balloon-cg/2")  # /5 and older: the meridian's
#                                                     ends named north and south, read as top and bottom (io/legacy.py)
POLES = ("lam2_top", "lam2_bottom", "eta_top", "eta_bottom")
SPECIAL_NUMBERS = ("pressure", "uncertainty", "E2", "E3", "E4") + POLES
SPECIAL_TEXT = ("kind", "classification", "block", "status", "reason", "stop_code", "note")
TRANSLATIONS = ("translation_axial", "translation_lateral")  # frequencies/: the rigid translations' Ω²


class RunFileError(FileError):
    """A file that is not a readable balloon-cg run file (names the file and what is missing or wrong)."""


def write_run(path, scene, branches, force: bool = False, extra_attrs: dict | None = None,
              snaps: list | None = None, found: list | None = None, clock: Clock | None = None,
              meridian_surface: dict | None = None) -> Path:
    """Write the branches traced for ``scene`` to ``path`` atomically; returns the path.

    An existing file is kept unless ``force`` (FileExistsError); on any failure the existing file is
    untouched and the temporary file removed. ``extra_attrs`` are added to (or override, except ``format``)
    the root attributes. ``found``: analysis.verdict.Incomplete entries (default: those of ``branches``).
    ``clock``: the run's analysis.timing.Clock (its phases and total stored with the write's own time:
    ``timing_attrs``). ``meridian_surface``: a capsule's non-axisymmetric branches (name -> MeridianSurfaceBranch,
    analysis/picture.Picture.meridian_surface) under /surface_branches/ (io/tube_surface_file.py). Raises ValueError
    if a branch holds a point that is not a finite solution.
    """
    attrs = _run_attrs(scene, branches, extra_attrs, found)
    with atomic_file(path, force) as f:
        _write_timed(f, attrs, scene, branches, snaps, clock)
        write_surface_branches(f, meridian_surface)
    return Path(path)


def run_image(scene, branches, extra_attrs: dict | None = None, snaps: list | None = None,
              found: list | None = None, clock: Clock | None = None, meridian_surface: dict | None = None) -> bytes:
    """The bytes of the file ``write_run`` writes, made in memory (an HDF5 file image; nothing on disk)."""
    attrs = _run_attrs(scene, branches, extra_attrs, found)
    with h5py.File(f"{scene.name}.h5", "w", driver="core", backing_store=False) as f:
        _write_timed(f, attrs, scene, branches, snaps, clock)
        write_surface_branches(f, meridian_surface)
        f.flush()
        return f.id.get_file_image()


def _write_timed(f, attrs: dict, scene, branches, snaps, clock: Clock | None) -> None:
    """The root attributes and the branches into the open file ``f``, then, with a ``clock``, the timing
    (``timing_attrs``, the write charged to Step.WRITING)."""
    if clock is None:
        f.attrs.update(attrs)
        write_branches(f, scene, branches, snaps)
        return
    with clock.step(Step.WRITING):
        f.attrs.update(attrs)
        write_branches(f, scene, branches, snaps)
    f.attrs.update(timing_attrs(clock))


def timing_attrs(clock: Clock) -> dict:
    """phase_names and phase_seconds (the phases that ran, in Step order) and total_seconds (since the clock
    started: the phases and what lies between them)."""
    steps = [step for step in Step if step in clock.seconds]
    return {"phase_names": np.array([step.value for step in steps], dtype=h5py.string_dtype()),
            "phase_seconds": np.array([clock.seconds[step] for step in steps]), "total_seconds": clock.total()}


def _run_attrs(scene, branches, extra_attrs, found) -> dict:
    """The root attributes of a run file, after checking the branches (ValueError: nothing is written)."""
    attrs = root_attrs(scene) | verdict_attrs(branches, found) | dict(extra_attrs or {})
    if attrs["format"] != FORMAT:
        raise ValueError(f"extra_attrs may not change format (= {FORMAT!r})")
    check_branches(branches)
    return attrs


def root_attrs(scene, command: str | None = None) -> dict:
    """The root attributes of a run file: format, the scene, the provenance and a CF ``title``."""
    return {"format": FORMAT, "scene_name": scene.name, "scene_toml": scene.text, "tolerance": scene.solver.tol,
            "control": scene.loading.control.value, "title": f"balloon-cg run of scene {scene.name}",
            **provenance(command)}


def verdict_attrs(branches=None, found=None) -> dict:
    """complete and incomplete_* attributes from Incomplete entries (or computed from ``branches``)."""
    from ..analysis.verdict import failing, incomplete

    if found is None:
        found = incomplete(branches)
    text = h5py.string_dtype()
    return {"complete": not failing(found),
            "incomplete_gaps": np.array([item.gap.value for item in found], dtype=text),
            "incomplete_branches": np.array([item.branch for item in found], dtype=text),
            "incomplete_messages": np.array([item.message for item in found], dtype=text)}


def check_branches(branches) -> None:
    """Distinct names, only finite points, special points as wide as the points (ValueError otherwise: nothing
    is written)."""
    names = [b.name for b in branches]
    if len(set(names)) != len(names):
        raise ValueError(f"branch names must be distinct, got {names}")
    for branch in branches:
        bad = np.flatnonzero(~finite(branch))
        if bad.size:
            raise ValueError(f"branch {branch.name!r}: points {bad.tolist()} are not converged solutions; not written")
        width = branch_rows(branch).shape[1]
        wrong = [f"{s.kind.value} after point {s.index} ({np.size(s.X)})" for s in branch.special
                 if np.size(s.X) != width]
        if wrong:
            raise ValueError(f"branch {branch.name!r}: special points {', '.join(wrong)} are not rows of its {width} "
                             "unknowns and parameter (another basis?); not written")
        reflections = len(branch.basis.symmetry) if is_surface(branch) else 0
        wrong = [f"{s.kind.value} after point {s.index} {s.sector}" for s in branch.special
                 if s.sector and (len(s.sector) != reflections or not set(s.sector) <= {-1, 1})]
        if wrong:
            raise ValueError(f"branch {branch.name!r}: special points {', '.join(wrong)} have no symmetry sector of its "
                             f"{reflections} reflections (characters ±1, one each); not written")


def finite(branch) -> np.ndarray:
    """Per point: finite unknowns and residual (every traced point is a converged Newton solution)."""
    return np.isfinite(branch_rows(branch)).all(axis=1) & np.isfinite(branch.residual)


def is_surface(branch) -> bool:
    """Whether ``branch`` is a surface branch (analysis.results.SurfaceBranch: coefficients in a SphericalBasis)
    rather than an axisymmetric Branch (Legendre unknowns on a Discretisation)."""
    return hasattr(branch, "coefficients")


def branch_rows(branch) -> np.ndarray:
    """The rows (unknowns, parameter) of every point: X of a Branch, (c, p) of a SurfaceBranch."""
    return np.column_stack([branch.coefficients, branch.values]) if is_surface(branch) else branch.X


def write_branches(parent, scene, branches, snaps=None) -> None:
    """/branches (and /snap_throughs when ``snaps`` is given) of a run file into the h5py group ``parent``."""
    from ..galerkin.profiles import theta_grid

    group = parent.create_group("branches")
    group.attrs["snap_throughs"] = snaps is not None
    theta = theta_grid(scene.output.theta_points)
    first_label = 1  # special points are labelled 1, 2, … through the branches in order (``labelled``)
    for order, branch in enumerate(branches):
        write = _write_surface_branch if is_surface(branch) else lambda g, b, f: _write_branch(g, b, theta, f)
        write(group.create_group(branch.name), branch, first_label)
        group[branch.name].attrs.update({"order": order, "assessed": bool(branch.stability)})
        first_label += len(branch.special)
    if snaps is not None:
        _write_snaps(parent.create_group("snap_throughs"), snaps)


def _write_branch(group, branch, theta, first_label: int = 1):
    from ..analysis.branches.problem import equilibrium_of
    from ..galerkin.profiles import equator_values, profiles

    disc = branch.disc
    _write_common_attrs(group, branch)
    group.attrs.update({
        "m": 0,
        "degree": disc.degree,
        "symmetric": disc.symmetric,
        "pin_translation": disc.pin_translation,
        "quadrature": disc.quadrature,
        "map_centres": np.array(disc.mapping.centres if disc.mapping else [], dtype=float),
        "map_widths": np.array(disc.mapping.widths if disc.mapping else [], dtype=float),
        "joins": np.array(disc.joins, dtype=float),
        "origin": branch.origin.value,
        "gauge": branch.gauge.value,
    })
    if disc.element_degrees:  # a capsule's graded basis (absent: the greedy order of ``degree``)
        group.attrs["element_degrees"] = np.array(disc.element_degrees, dtype=int)
    if disc.held is not None:  # a held general basis holding its area centroid (absent: b_0 = 0)
        size = disc.held.aspect if disc.held.shape == Shape.SPHEROID else disc.held.length
        group.attrs.update({"held_shape": disc.held.shape.value, "held_size": float(size)})
    if branch.parent is not None:
        group.attrs["parent_branch"], group.attrs["parent_branch_point"] = branch.parent
    if branch.rejoins is not None:
        group.attrs["rejoins_branch_point"] = branch.rejoins
    if branch.reflection_of:
        group.attrs["reflection_of"] = branch.reflection_of
    volume = equilibrium_of(branch).volume
    volumes = 2 * np.pi * np.array([volume(u) for u in branch.X[:, :-1]])
    parameters = parameter_columns(branch, branch.X)
    columns = {
        **parameters,
        "volume": volumes,
        "amount": parameters["pressure"] * volumes,
        **branch.pole_values(),
        **equator_values(branch.disc, branch.X, branch.scene.geometry),
        "converged": finite(branch),
        "residual": branch.residual,
        "error_estimate": branch.error_estimate,
        "newton_iterations": branch.iterations,
        "solved_degree": branch.degree,
        "unknowns": branch.X,
    }
    point, unknown = scale(group, "point", len(branch.X)), scale(group, "unknown", branch.X.shape[1])
    theta_scale = scale(group, "theta", values=theta)
    for name, data in columns.items():
        checksummed(group, name, data)
    attach_dimensions(group, {1: (point,), 2: (point, unknown)})
    shapes = group.create_group("profiles")
    for name, data in profiles(branch.disc, branch.X, theta, branch.scene.geometry).items():
        checksummed(shapes, name, data, compression="gzip", shuffle=True)
    attach_dimensions(shapes, {2: coordinates(shapes, point, theta_scale)})
    write_special(group.create_group("special_points"), branch.special, branch.X.shape[1],
                  lambda X: legendre_poles(branch.disc, X), lambda X: parameter_columns(branch, X), first_label)
    if branch.stability:
        _write_stability(group.create_group("stability"), branch, point)
    if branch.frequencies is not None:
        _write_frequencies(group.create_group("frequencies"), branch.frequencies, point, theta_scale)


def _write_common_attrs(group, branch) -> None:
    """The attributes every branch has: its stop, legs, run time, kernels and parameters."""
    group.attrs.update({
        "stop_reason": branch.stop_reason,
        "wall_time": branch.wall_time,
        "kernel_class": branch.kernel_class,
        "kernel_signature": branch.kernel_signature,
        "M": branch.params.M,
        "chi": branch.params.chi,
        "electric": branch.scene.electric is not None,
        "voltage": branch.params.voltage,
        "parameter": branch.parameter,
    })
    text = h5py.string_dtype()
    group.attrs.create("leg_labels", np.array([leg.label for leg in branch.legs], dtype=object), dtype=text)
    group.attrs.create("leg_stop_codes", np.array([leg.stop.code.value for leg in branch.legs], dtype=object),
                       dtype=text)


def _write_surface_branch(group, branch, first_label: int = 1) -> None:
    """A SurfaceBranch (module docstring): its basis as attributes, the per-point measures (the volume per 2π
    of ``surface.measures`` times 2π, as the axisymmetric ``volume``), the coefficients, special points with
    the pole values of their own states, and the lowest eigenvalues held and free with the pressure-control
    flags they give (the lowest > 0, as ``analysis.stability.axisymmetric.Assessment``)."""
    from ..surface.loads import LOADS  # here, not at the top: surface/ imports numba and scipy

    basis = branch.basis
    _write_common_attrs(group, branch)
    group.attrs.update({
        "m": branch.m,
        "parent_branch": branch.parent[0],
        "parent_branch_point": branch.parent[1],
        "surface_degree": basis.degree,
        "surface_order": basis.order,
        "symmetry": np.array(basis.symmetry, dtype=np.int64).reshape(len(basis.symmetry), 3),
        "characters": np.array(basis.characters, dtype=np.int64),
        "n_theta": basis.n_theta,
        "n_phi": basis.n_phi,
        "map_centres": np.array(basis.mapping.centres if basis.mapping else [], dtype=float),
        "map_widths": np.array(basis.mapping.widths if basis.mapping else [], dtype=float),
        "aspect": basis.aspect,
        "origin": branch.origin.value,
        "gauge": branch.gauge.value,
    })
    if branch.reflection_of:
        group.attrs["reflection_of"] = branch.reflection_of
    if branch.reflection:
        group.attrs["reflection"] = np.array(branch.reflection, dtype=np.int64)
    rows = branch_rows(branch)
    parameters = parameter_columns(branch, rows)
    measures = branch.measures
    volumes = 2 * np.pi * np.asarray(measures["volume"], dtype=float)
    columns = {
        **parameters,
        "volume": volumes,
        "amount": parameters["pressure"] * volumes,
        "lam2_top": np.asarray(measures["lam_top"], dtype=float),
        "lam2_bottom": np.asarray(measures["lam_bottom"], dtype=float),
        "centroid": np.asarray(measures["centroid"], dtype=float).reshape(len(rows), 3),
        "tilt": np.asarray(measures["tilt"], dtype=float),
        "converged": finite(branch),
        "residual": branch.residual,
        "error_estimate": branch.error_estimate,
        "newton_iterations": branch.iterations,
        "coefficients": branch.coefficients,
        **{name: np.asarray(measures[name], dtype=float).reshape(len(rows), 3) for name in LOADS if name in measures},
    }
    point, coefficient = scale(group, "point", len(rows)), scale(group, "coefficient", basis.size)
    axis = scale(group, "axis", 3)
    for name, data in columns.items():
        checksummed(group, name, data)
    attach_dimensions(group, {**{name: (point, axis) for name in ("centroid", *LOADS) if name in columns},
                              1: (point,), 2: (point, coefficient)})
    write_special(group.create_group("special_points"), branch.special, rows.shape[1],
                  lambda X: surface_poles(basis, X), lambda X: parameter_columns(branch, X), first_label,
                  len(basis.symmetry))
    if branch.stability:
        _write_surface_stability(group.create_group("stability"), branch.stability, point)
    if branch.frequencies is not None:
        _write_surface_frequencies(group.create_group("frequencies"), branch.frequencies, point)


def _write_surface_stability(group, lowest: dict, point) -> None:
    """lowest_<reading> (held, free, held_volume, free_volume, held_gas, free_gas: every symmetry sector, zero
    modes removed: surface.stability) and the flags they give."""
    columns = {f"lowest_{reading}": np.asarray(values, dtype=float) for reading, values in lowest.items()}
    for name, sector_reading in (("stable_pressure", "held"), ("stable_pressure_free", "free"),
                                 ("stable_volume", "held_volume"), ("stable_volume_free", "free_volume"),
                                 ("stable_gas", "held_gas"), ("stable_gas_free", "free_gas")):
        if sector_reading in lowest:
            checksummed(group, name, np.asarray(lowest[sector_reading])[:, 0] > 0)
            group[name].attrs["meaning"] = STABILITY_FLAGS[name]
    eigenvalue = scale(group, "eigenvalue", max(v.shape[1] for v in columns.values()))
    for name, values in columns.items():
        checksummed(group, name, values)
    (point,) = coordinates(group, point)
    attach_dimensions(group, {1: (point,), 2: (point, eigenvalue)})
    group.attrs["unsettled_points"] = np.zeros(0, dtype=np.int64)


STABILITY_FLAGS = {
    "stable_pressure": "held at the centre (axial translation excluded), pressure control",
    "stable_volume": "held at the centre, volume control (volume-preserving perturbations)",
    "stable_pressure_free": "free balloon (axial translation included), pressure control",
    "stable_volume_free": "free balloon, volume control",
    "stable_gas": "held at the centre, gas control (fixed amount of isothermal ideal gas, P V = n)",
    "stable_gas_free": "free balloon, gas control",
}


def _write_stability(group, branch, point):
    """Flags per point (what each means is in the dataset's 'meaning' attribute) and lowest eigenvalues."""
    results = branch.stability
    for name, meaning in STABILITY_FLAGS.items():
        checksummed(group, name, np.array([a.flags()[name] for a in results], dtype=bool))
        group[name].attrs["meaning"] = meaning
    lowest = {f"lowest_{block}": np.array([a.blocks[block] for a in results]) for block in results[0].blocks}
    eigenvalue = scale(group, "eigenvalue", max(v.shape[1] for v in lowest.values()))
    for name, values in lowest.items():
        checksummed(group, name, values)
    (point,) = coordinates(group, point)
    attach_dimensions(group, {1: (point,), 2: (point, eigenvalue)})
    group.attrs["unsettled_points"] = np.asarray(branch.unsettled, dtype=np.int64)


def _write_frequencies(group, frequencies, point, theta):
    """Ω² per block (dynamics.frequencies.BranchFrequencies) and the degree per point; the special points' mode
    shapes where computed (on the branch's ``theta`` scale)."""
    group.attrs["m_max"] = frequencies.m_max
    point, *theta = coordinates(group, point, *([theta] if frequencies.modes is not None else []))  # θ: the modes'
    special, frequency, axes = _write_omega2(group, frequencies, point)
    checksummed(group, "perturbation_degree", frequencies.degree)
    for direction, values in frequencies.translation.items():
        checksummed(group, f"translation_{direction}", values)
    if frequencies.modes is not None:
        component = scale(group, "component", next(iter(frequencies.modes.values())).shape[2])
        for block, shapes in frequencies.modes.items():
            checksummed(group, f"{MODES}{block}", shapes, compression="gzip", shuffle=True)
            axes[f"{MODES}{block}"] = (special, frequency, component, *theta)
    attach_dimensions(group, axes)


def _write_surface_frequencies(group, frequencies, point):
    """Ω² per sector and reading of a surface branch (dynamics.surface.SurfaceFrequencies)."""
    (point,) = coordinates(group, point)
    attach_dimensions(group, _write_omega2(group, frequencies, point)[2])


def _write_omega2(group, frequencies, point) -> tuple:
    """The ``count`` attribute, the frequency and special scales and omega2_<block>, special_omega2_<block> of
    ``frequencies`` (its ``omega2``, ``special``, ``count``); returns (special, frequency, the datasets' axes)."""
    group.attrs["count"] = frequencies.count
    frequency = scale(group, "frequency", frequencies.count)
    special = scale(group, "special", len(next(iter(frequencies.special.values()), ())))
    axes = {1: (point,), 2: (point, frequency)}
    for block, values in frequencies.omega2.items():
        checksummed(group, f"{OMEGA2}{block}", values)
        checksummed(group, f"{SPECIAL_OMEGA2}{block}", frequencies.special[block])
        axes[f"{SPECIAL_OMEGA2}{block}"] = (special, frequency)
    return special, frequency, axes


def _write_snaps(group, snaps):
    """Snap-throughs under the loading control: from (branch, index) at pressure P to (branch, index) or none."""
    write_strings(group, "from_branch", [s.from_branch for s in snaps])
    write_strings(group, "to_branch", [s.to_branch for s in snaps])
    checksummed(group, "from_index", np.array([s.from_index for s in snaps], dtype=np.int64))
    checksummed(group, "to_index", np.array([s.to_index for s in snaps], dtype=np.int64))
    checksummed(group, "pressure", np.array([s.pressure for s in snaps], dtype=float))
    attach_dimensions(group, {1: (scale(group, "snap", len(snaps)),)})


def parameter_columns(branch, X) -> dict:
    """{'pressure': P, 'voltage': Φ̄ where the dielectric term is present, 'M' on a continuation in M} of the rows
    X = (u, p) of a branch (p is its continuation parameter; the others are fixed)."""
    last = X[:, -1]
    fixed = lambda name: last if branch.parameter == name else np.full(len(X), getattr(branch.params, name))  # noqa: E731
    return {"pressure": fixed("P"), **({"voltage": fixed("voltage")} if branch.scene.electric is not None else {}),
            **({"M": last} if branch.parameter == "M" else {})}


def legendre_poles(disc, X) -> dict:
    """The POLES columns of rows X = (u, p) on the Discretisation ``disc``."""
    return {name: X[:, :-1] @ row for name, row in disc.pole_rows().items()}


def surface_poles(basis, X) -> dict:
    """The POLES columns of rows X = (c, p) in the SphericalBasis ``basis``: the stretch √J at the material poles
    (surface.measures.pole_stretch, λ2 there on an axisymmetric state) and their height z."""
    from ..surface.measures import pole_stretch

    heights = np.array([basis.point_values(row[:-1], np.array([0.0, np.pi]), np.zeros(2))[0][2] for row in X])
    return {"lam2_top": np.array([pole_stretch(basis, row[:-1], 0.0) for row in X]),
            "lam2_bottom": np.array([pole_stretch(basis, row[:-1], np.pi) for row in X]),
            "eta_top": heights[:, 0] if len(X) else np.zeros(0),
            "eta_bottom": heights[:, 1] if len(X) else np.zeros(0)}


def write_special(group, special: list, width: int, poles, parameters=None, first_label: int = 1,
                  reflections: int | None = None) -> None:
    """Special points (results.SpecialPoint) as columns; ``width`` the length of their X rows (unknowns, then
    the parameter), ``poles(X)`` the POLES columns of the rows (``legendre_poles``, ``surface_poles``), in
    state/unknowns along state's own ``special`` and ``unknown`` scales (it opens alone); ``parameters(X)``: the
    parameter columns of the rows (default pressure = the last unknown); ``label``: first_label, first_label + 1,
    … (unique in the file: ``write_branches``); ``reflections``: a surface branch's number of reflections, whose
    points' sectors go to state/sector (``sector_rows``; None: an axisymmetric branch, no sectors)."""
    X = np.array([s.X for s in special]).reshape(len(special), width)
    checksummed(group, "label", np.arange(first_label, first_label + len(special), dtype=np.int64))
    write_strings(group, "kind", [s.kind.value for s in special])
    write_strings(group, "classification", [s.classification.value for s in special])
    write_strings(group, "block", [s.block.value for s in special])
    write_strings(group, "gauge", [s.gauge.value for s in special])
    write_strings(group, "status", [s.status.value for s in special])
    write_strings(group, "reason", [s.reason for s in special])
    checksummed(group, "uncertainty", np.array([s.uncertainty for s in special], dtype=float))
    write_strings(group, "stop_code", [s.stop.code.value if s.stop else "" for s in special])
    write_strings(group, "note", [s.stop.message if s.stop else s.note for s in special])
    checksummed(group, "index", np.array([s.index for s in special], dtype=np.int64))
    checksummed(group, "m", np.array([s.m for s in special], dtype=np.int64))
    for name, values in (parameters or (lambda X: {"pressure": X[:, -1]}))(X).items():
        checksummed(group, name, values)
    for n, name in enumerate(("E2", "E3", "E4")):
        checksummed(group, name, np.array([s.E[n] for s in special], dtype=float))
    pole_values = poles(X)
    for name in POLES:
        checksummed(group, name, pole_values[name])
    special_scale = scale(group, "special", len(special))
    attach_dimensions(group, {1: (special_scale,)})
    state = group.create_group("state")  # the 2-D rows apart: special_points stays a table of one row per point
    checksummed(state, "unknowns", X)
    (special_scale,) = coordinates(state, special_scale)
    axes = {}
    if reflections is not None:
        checksummed(state, "sector", sector_rows(special, reflections))
        axes["sector"] = (special_scale, scale(state, "reflection", reflections))
    attach_dimensions(state, axes | {2: (special_scale, scale(state, "unknown", width))})


def sector_rows(special: list, reflections: int) -> np.ndarray:
    """(special, reflections) int: each point's ``sector`` (its character ±1 under each reflection of its basis),
    zeros where it has none (folds, end points, the point a branch is born at)."""
    rows = np.zeros((len(special), reflections), dtype=np.int64)
    for row, s in zip(rows, special):
        row[:len(s.sector)] = s.sector
    return rows


def read_run(path) -> dict:
    """Summary of a run file: {'path', 'scene_name', 'attrs', 'branches': {name: branch}}.

    Each branch is a dict of its attrs ('attrs'), its per-point arrays and 'theta', 'profiles' (dict of
    arrays), 'special_points' (list of dicts: the special_points columns) and 'special_unknowns'
    (their X rows). The layout is checked first (``io.layout``).
    Raises FileNotFoundError, IsADirectoryError, or RunFileError for a file that is not a readable run file
    (format balloon-cg/6 or an earlier one of READABLE), naming the file and what is missing or wrong.
    """
    path = Path(path)
    with opened(path, RunFileError) as f:
        check_data(f, path, RunFileError, FINITE)
        return _read_open(f, path) | {"path": str(path)}


def stored_scene(run: dict):
    """The Scene a run file was computed for, rebuilt from its ``scene_toml`` attribute as it was written
    (``scene.tables.parse_stored``: also a setting a new run may no longer start)."""
    return parse_stored(run["attrs"]["scene_toml"], run["scene_name"], written=int(run["attrs"].get("readings", 0)))


def read_run_image(image: bytes, label: str = "run") -> dict:
    """``read_run`` of a file image (``run_image``); 'path' is None and errors name ``label``."""
    with reading(label, RunFileError), h5py.File(io.BytesIO(image), "r") as f, current(f) as named:
        check_data(named, label, RunFileError, FINITE)
        return _read_open(named, label) | {"path": None}


def _read_open(f, label) -> dict:
    fmt = f.attrs.get("format")
    if fmt not in READABLE:
        found = "no format attribute" if fmt is None else f"format {plain(fmt)!r}"
        raise RunFileError(label, f"not a balloon-cg run file ({found}, expected one of {', '.join(READABLE)})")
    require_attrs(f.attrs, label, ROOT_KINDS, ROOT_KINDS, error=RunFileError)
    written = plain(fmt) == FORMAT and carries_checksums(f)  # by this version: every attribute it writes
    if written:
        required = WRITTEN_ROOT | ({} if "two_parameter" in f else VERDICT_KINDS)  # a curve has no verdict
        require_attrs(f.attrs, label, required, required, error=RunFileError)
    if "complete" in f.attrs:
        require_attrs(f.attrs, label, VERDICT_KINDS, VERDICT_KINDS, error=RunFileError)
    if any(k in f.attrs for k in TIMING_KINDS):  # written since issue 28
        require_attrs(f.attrs, label, TIMING_KINDS, TIMING_KINDS, error=RunFileError)
        if len(f.attrs["phase_names"]) != len(f.attrs["phase_seconds"]):
            raise RunFileError(label, f"{len(f.attrs['phase_names'])} phase_names but "
                                      f"{len(f.attrs['phase_seconds'])} phase_seconds")
    attrs = {k: _attr(v) for k, v in f.attrs.items()}
    branches = require_group(f, "branches", label, RunFileError)
    # every run writes its primary branch (a curve file, a run file with /two_parameter curves, has none)
    if "primary" not in branches and not len(f.get("two_parameter", {})):
        raise RunFileError(label, f"missing branch primary (branches: {', '.join(branches) or 'none'}): not a whole "
                                  "run file")
    if plain(fmt) in READABLE[:3]:  # written by /4 and later always (older ones may lack them: OPTIONAL_COLUMNS)
        for name, branch in branches.items():
            missing = [k for k in ("volume", "amount") if isinstance(branch, h5py.Group) and k not in branch]
            if missing:
                raise RunFileError(f"{label}: branch {name}", f"missing dataset {missing[0]}")
    return {"scene_name": attrs["scene_name"], "attrs": attrs, **read_branches(f, label, RunFileError, written),
            "meridian_surface": read_surface_branches(f, label, RunFileError)}


ROOT_KINDS = {"scene_name": "str", "scene_toml": "str", "tolerance": "float", "package_version": "str",
              "generated_digest": "str", "created": "str", "command": "str"}
WRITTEN_ROOT = {"format": "str", "control": "str", "title": "str", "Conventions": "str", "history": "str"}
#                 required (with ROOT_KINDS, and a run's VERDICT_KINDS) in a file with checksums
VERDICT_KINDS = {"complete": "bool", "incomplete_gaps": "str[]", "incomplete_branches": "str[]",
                 "incomplete_messages": "str[]"}
TIMING_KINDS = {"phase_names": "str[]", "phase_seconds": "float[]", "total_seconds": "float"}
COMMON_KINDS = {"stop_reason": "str", "wall_time": "float", "kernel_class": "str", "kernel_signature": "str",
                "M": "float", "chi": "float", "leg_labels": "str[]", "leg_stop_codes": "str[]"}
BRANCH_KINDS = COMMON_KINDS | {"degree": "int", "symmetric": "bool", "pin_translation": "bool", "quadrature": "int",
                               "map_centres": "float[]", "map_widths": "float[]"}
SURFACE_KINDS = COMMON_KINDS | {"m": "int", "parent_branch": "str", "parent_branch_point": "int",
                                "surface_degree": "int", "surface_order": "int", "n_theta": "int", "n_phi": "int",
                                "map_centres": "float[]", "map_widths": "float[]", "parameter": "str"}
SURFACE_COLUMNS = {**{name: ("float", 1) for name in ("pressure", "volume", "lam2_top", "lam2_bottom", "tilt",
                                                       "residual", "error_estimate")},
                   "converged": ("bool", 1), "newton_iterations": ("int", 1), "centroid": ("float", 2),
                   "coefficients": ("float", 2)}
BRANCH_COLUMNS = {**{name: ("float", 1) for name in ("pressure", *POLES, "lam1_equator", "lam2_equator", "residual",
                                                      "error_estimate")},
                  "converged": ("bool", 1), "newton_iterations": ("int", 1), "solved_degree": ("int", 1),
                  "unknowns": ("float", 2)}
PROFILES = {name: ("float", 2) for name in ("lam1", "lam2", "rho", "eta")}
SPECIAL_COLUMNS = {**{name: ("str", 1) for name in SPECIAL_TEXT}, "index": ("int", 1), "m": ("int", 1),
                   **{name: ("float", 1) for name in SPECIAL_NUMBERS}}
OPTIONAL_COLUMNS = {name: ("float", 1) for name in ("volume", "amount", "voltage", "M")}  # absent in older formats
CONDITIONAL_COLUMNS = ("voltage", "M")  # written where electric, on a continuation in M
WRITTEN_BRANCH = {"order": "int", "m": "int", "assessed": "bool", "origin": "str", "gauge": "str", "electric": "bool",
                  "voltage": "float", "parameter": "str"}  # required in a file with checksums (older: optional)
PARENT_KINDS = {"parent_branch": "str", "parent_branch_point": "int"}
SNAP_COLUMNS = {"from_branch": ("str", 1), "to_branch": ("str", 1), "from_index": ("int", 1),
                "to_index": ("int", 1), "pressure": ("float", 1)}
OPTIONAL_SPECIAL = {"voltage": ("float", 1), "M": ("float", 1), "gauge": ("str", 1), "label": ("int", 1)}  # voltage, M:
#                                                               where electric, on a continuation in M;
#                                                               gauge, label: since issue 27 (absent in older files)


def read_branches(parent, where, error=None, written: bool | None = None) -> dict:
    """{'branches': {name: branch dict}, 'snap_throughs': [...]} of an h5py group written by write_branches,
    checked first (``error``, default RunFileError, names ``where`` and what is missing); ``written``: written by
    this version, its whole layout required (default: where ``parent`` carries checksums)."""
    error = error or RunFileError
    group = require_group(parent, "branches", where, error)
    if written is None:
        written = carries_checksums(parent)
    if written:  # a file of this version: its whole layout (older files: what they may hold)
        check_described(parent, where, error)
        require_attrs(group.attrs, f"{where}: branches", ("snap_throughs",), {"snap_throughs": "bool"}, error)
        if bool(group.attrs["snap_throughs"]) != ("snap_throughs" in parent):
            raise error(where, "missing group snap_throughs" if group.attrs["snap_throughs"] else
                               "group snap_throughs where /branches says none were searched")
    for name, branch in group.items():
        branch_m(branch, f"{where}: branch {name}", error)
        if is_surface_group(branch):
            check_surface_branch(branch, f"{where}: branch {name}", error, written)
        else:
            check_branch(branch, f"{where}: branch {name}", error, written)
    check_coordinates(group, where, error)
    snaps = parent.get("snap_throughs")
    if snaps is not None:
        check_columns(snaps, f"{where}: snap_throughs", SNAP_COLUMNS, error)
        _check_snaps(snaps, group, f"{where}: snap_throughs", error)
    return {"branches": labelled({name: _read_branch(group[name]) for name in _branch_order(group)}),
            "snap_throughs": _read_snaps(snaps)}


def labelled(branches: dict) -> dict:
    """The read branches with every special point's ``label``: as stored, or (files written before labels)
    1, 2, … through the branches in their order, as ``write_branches`` numbers them."""
    label = 1
    for branch in branches.values():
        for point in branch["special_points"]:
            point.setdefault("label", label)
            label += 1
    return branches


def _check_snaps(snaps, branches, where, error) -> None:
    """Every snap-through names stored branches and points on them (its target may be none: '' and −1)."""
    for end in ("from", "to"):
        names = snaps[f"{end}_branch"].asstr()[()]
        indices = snaps[f"{end}_index"][()]
        for name, index in zip(names, indices):
            if end == "to" and name == "" and index == -1:
                continue
            if name not in branches:
                raise error(where, f"{end}_branch {name!r} names no stored branch")
            if not 0 <= index < branches[name]["pressure"].shape[0]:
                raise error(where, f"{end}_index {index} is not a point of branch {name!r}")


HELD_SHAPES = ("spheroid", "capsule")  # held_shape: the shapes whose held general basis holds its area centroid


def _check_held(attrs, where, error) -> None:
    """held_shape and held_size together or neither, the shape one of HELD_SHAPES, the size finite and positive (a
    capsule's length may be 0)."""
    held = [k for k in ("held_shape", "held_size") if k in attrs]
    if len(held) == 1:
        raise error(where, f"attribute {held[0]} without {({'held_shape', 'held_size'} - set(held)).pop()}")
    if not held:
        return
    shape, size = str(attrs["held_shape"]), float(attrs["held_size"])
    if shape not in HELD_SHAPES:
        raise error(where, f"attribute held_shape = {shape!r}: must be one of {', '.join(HELD_SHAPES)}")
    if not (np.isfinite(size) and (size > 0 or shape == "capsule" and size == 0)):
        raise error(where, f"attribute held_size = {size!r}: must be finite and positive (a capsule's length ≥ 0)")


def check_branch(group, where, error, written: bool = False) -> None:
    """The attributes and columns of one stored branch (at least one point; unknowns, profiles and special
    points of consistent shapes; ``written``: a file with checksums, also what this version writes,
    ``check_written``)."""
    if not isinstance(group, h5py.Group):
        raise error(where, "is not a group")
    # gauge: since issue 27; joins: since a capsule's piecewise basis (absent: the Legendre basis); element_degrees:
    # a capsule's graded basis (absent: one degree shared by its elements); held_shape, held_size: a held general
    # basis holding its area centroid (a spheroid's aspect, a capsule's length; absent: b_0 = 0)
    require_attrs(group.attrs, where, BRANCH_KINDS, BRANCH_KINDS | {"gauge": "str", "joins": "float[]",
                                                                     "element_degrees": "int[]",
                                                                     "held_shape": "str", "held_size": "float"}, error)
    if written:  # an axisymmetric branch's basis, written by this version: its joins (none: the Legendre basis)
        require_attrs(group.attrs, where, ("joins",), {"joins": "float[]"}, error)
    _check_held(group.attrs, where, error)
    if "parent_branch" in group.attrs:
        require_attrs(group.attrs, where, PARENT_KINDS, PARENT_KINDS, error)
    n = check_columns(group, where, BRANCH_COLUMNS, error, min_rows=1)
    check_columns(group, where, {k: v for k, v in OPTIONAL_COLUMNS.items()
                                 if k in group or (written and k not in CONDITIONAL_COLUMNS)}, error, rows=n)
    check_sizes(group, where, error)
    width = group["unknowns"].shape[1]
    check_scales(group, where, error, {"point": n, "unknown": width}, written)
    t = check_columns(group, where, {"theta": ("float", 1)}, error)
    check_columns(require_group(group, "profiles", where, error), f"{where}: profiles", PROFILES, error, rows=n)
    check_sizes(group["profiles"], f"{where}: profiles", error)
    for name, item in columns_of(group["profiles"]).items():
        if item.shape[1:] != (t,):
            raise error(f"{where}: profiles", f"dataset {name} has shape {item.shape}, expected ({n}, {t})")
    check_special(require_group(group, "special_points", where, error), f"{where}: special_points", width, error,
                  written=written)
    check_stability(group, where, error, n, written)
    check_frequencies(group, where, error, n)


def check_frequencies(group, where, error, n: int, surface: bool = False) -> None:
    """A branch's frequencies group, where present: Ω² per block ``n`` rows (an axisymmetric branch's with the
    perturbation degree and the rigid translations; a ``surface`` branch's per sector and reading alone), at the
    special points one row each."""
    if "frequencies" not in group:
        return
    frequencies = require_group(group, "frequencies", where, error)
    columns = {name: ("float", 2) for name in frequencies if name.startswith(OMEGA2)}
    if not surface:
        columns |= {name: ("float", 1) for name in TRANSLATIONS} | {"perturbation_degree": ("int", 1)}
    check_columns(frequencies, f"{where}: frequencies", columns, error, rows=n)
    special = {name: ("float", 2) for name in frequencies if name.startswith(SPECIAL_OMEGA2)}
    special |= {name: ("float", 4) for name in frequencies if name.startswith(MODES)}
    check_columns(frequencies, f"{where}: frequencies", special, error, rows=len(group["special_points"]["kind"]))
    check_sizes(frequencies, f"{where}: frequencies", error)


def check_stability(group, where, error, n: int, written: bool) -> None:
    """A branch's stability group, where present (``written``: exactly where its ``assessed`` says, with every
    flag's ``meaning``, ``unsettled_points`` and the ``eigenvalue`` scale): flags and lowest eigenvalues ``n``
    rows each."""
    if written:
        require_attrs(group.attrs, where, WRITTEN_BRANCH, WRITTEN_BRANCH, error)
        if bool(group.attrs["assessed"]) != ("stability" in group):
            raise error(where, "missing group stability" if group.attrs["assessed"] else
                               "group stability where attribute assessed says none was assessed")
    if "stability" not in group:
        return
    stability = require_group(group, "stability", where, error)
    flags = {name: ("bool", 1) for name in STABILITY_FLAGS if name in stability}
    lowest = {name: ("float", 2) for name in stability if name.startswith("lowest_")}
    check_columns(stability, f"{where}: stability", flags | lowest, error, rows=n)
    check_sizes(stability, f"{where}: stability", error)
    if written:
        require_attrs(stability.attrs, f"{where}: stability", ("unsettled_points",), error=error)
        for name in flags:
            require_attrs(stability[name].attrs, f"{where}: stability/{name}", ("meaning",), error=error)
        if lowest:
            check_scales(stability, f"{where}: stability", error,
                         {"eigenvalue": max(stability[name].shape[1] for name in lowest)}, written)


def check_scales(group, where, error, lengths: dict, written: bool) -> None:
    """The dimension scales ``lengths`` ({name: length}) of ``group``: each 1-d int of its length, 0, 1, …; required
    where ``written`` (files before scales, balloon-cg/2, have none)."""
    present = {name: length for name, length in lengths.items() if written or name in group}
    for name, length in present.items():
        check_columns(group, where, {name: ("int", 1)}, error, rows=length)
        if not np.array_equal(group[name][()], np.arange(length)):
            raise error(where, f"dataset {name} is not the index 0 … {length - 1}")


def check_special(group, where, width: int, error, extra: dict | None = None, reflections: int = 0,
                  written: bool = False) -> None:
    """The columns of a special_points group (SPECIAL_COLUMNS, OPTIONAL_SPECIAL where present (``written``: gauge
    and label always, and the ``special`` scale), ``extra``), its X rows (``special_unknowns``) ``width`` wide, one
    per special point, and, where present, its sectors (state/sector: ``reflections`` wide, characters ±1 or a
    row of zeros)."""
    n = check_columns(group, where, SPECIAL_COLUMNS | (extra or {}), error)
    check_columns(group, where, {k: v for k, v in OPTIONAL_SPECIAL.items()
                                 if k in group or (written and k not in CONDITIONAL_COLUMNS)}, error, rows=n)
    check_scales(group, where, error, {"special": n}, written)
    check_sizes(group, where, error)
    unknowns = special_unknowns(group, where, error, rows=n)
    if n and unknowns.shape[1] != width:
        raise error(where, f"unknowns has {unknowns.shape[1]} columns, expected {width}")
    if "sector" in unknowns.parent:
        check_columns(unknowns.parent, f"{where}/state", {"sector": ("int", 2)}, error, rows=n)
        sectors = unknowns.parent["sector"][()]
        if sectors.shape[1] != reflections or not all(set(row) <= {-1, 1} or not row.any() for row in sectors):
            raise error(f"{where}/state", f"sector has shape {sectors.shape} and rows {sectors.tolist()}, expected "
                                          f"{reflections} characters ±1 per row (a row of zeros: none)")


def special_unknowns(group, where="", error=FileError, rows: int | None = None):
    """The X rows of a special_points group: its ``state/unknowns`` (format balloon-cg/5 and later), or its ``unknowns``
    (balloon-cg/4 and older, where the 2-D rows sat among the columns); checked 2-d float, ``rows`` long."""
    holder = group if "unknowns" in group and "state" not in group else require_group(group, "state", where, error)
    label = where if holder is group else f"{where}/state"
    check_columns(holder, label, {"unknowns": ("float", 2)}, error, rows=rows)
    check_sizes(holder, label, error)
    return holder["unknowns"]


def branch_m(group, where, error) -> int:
    """The azimuthal number ``m`` of a stored branch: 0 (axisymmetric; also files written before surface
    branches, which have no ``m``), or m ≥ 1 (a surface branch)."""
    if not isinstance(group, h5py.Group):
        raise error(where, "is not a group")
    if "m" not in group.attrs:
        return 0
    require_attrs(group.attrs, where, ("m",), {"m": "int"}, error)
    m = int(group.attrs["m"])
    if m < 0:
        raise error(where, f"attribute m = {m}: must be ≥ 0")
    return m


def is_surface_group(group) -> bool:
    """Whether a stored branch is a surface branch (its basis attributes: an m ≥ 1 branch, or the primary branch
    of a field that is not axisymmetric, m = 0)."""
    return "surface_degree" in group.attrs


def check_surface_branch(group, where, error, written: bool = False) -> None:
    """The attributes and columns of one stored surface branch: its basis (symmetry k × 3 of ±1, characters k of
    ±1) rebuilt, the coefficients as wide as its size, the centroid 3 wide, special points (c, p) rows and
    stability of consistent shapes."""
    from ..surface.loads import LOADS

    require_attrs(group.attrs, where, (*SURFACE_KINDS, "symmetry", "characters"), SURFACE_KINDS, error)
    n = check_columns(group, where, SURFACE_COLUMNS, error, min_rows=1)
    check_columns(group, where, {k: v for k, v in OPTIONAL_COLUMNS.items()
                                 if k in group or (written and k not in CONDITIONAL_COLUMNS)}, error, rows=n)
    check_sizes(group, where, error)
    size = stored_basis(group.attrs, where, error).size
    check_scales(group, where, error, {"point": n, "coefficient": size, "axis": 3}, written)
    if group["coefficients"].shape[1] != size:
        raise error(where, f"coefficients has {group['coefficients'].shape[1]} columns, expected {size} (the size "
                           "of the basis its attributes describe)")
    check_columns(group, where, {name: ("float", 2) for name in LOADS if name in group}, error, rows=n)
    for name in ("centroid", *(name for name in LOADS if name in group)):
        if group[name].shape[1] != 3:
            raise error(where, f"{name} has shape {group[name].shape}, expected ({n}, 3)")
    check_special(require_group(group, "special_points", where, error), f"{where}: special_points", size + 1, error,
                  reflections=len(group.attrs["symmetry"]), written=written)
    check_stability(group, where, error, n, written)
    check_frequencies(group, where, error, n, surface=True)


def stored_basis(attrs, where="", error=FileError):
    """The surface.basis.SphericalBasis of a stored surface branch, from its attributes surface_degree,
    surface_order, symmetry (k × 3 signs), characters (k signs), n_theta, n_phi and the polar coordinate map
    map_centres, map_widths (empty: none) and the reference's aspect (absent in older files: 1, the sphere)
    (``error`` naming ``where`` if they do not make one)."""
    from ..galerkin.coordinate_map import WireMap
    from ..surface.basis import SphericalBasis

    symmetry, characters = (np.asarray(attrs.get(key, np.zeros(0))) for key in ("symmetry", "characters"))
    if symmetry.size == 0:
        symmetry = symmetry.reshape(0, 3)
    if symmetry.ndim != 2 or symmetry.shape[1] != 3 or not np.isin(symmetry, (-1, 1)).all():
        raise error(where, f"attribute symmetry has shape {symmetry.shape} and values {symmetry.ravel().tolist()}, "
                           "expected k × 3 signs ±1 (the reflections the states keep)")
    if characters.shape != (len(symmetry),) or not np.isin(characters, (-1, 1)).all():
        raise error(where, f"attribute characters is {characters.tolist()}, expected {len(symmetry)} signs ±1")
    try:
        centres, widths = (tuple(float(v) for v in attrs.get(key, ())) for key in ("map_centres", "map_widths"))
        return SphericalBasis(int(attrs["surface_degree"]), tuple(tuple(int(s) for s in row) for row in symmetry),
                              tuple(int(c) for c in characters), int(attrs["n_theta"]), int(attrs["n_phi"]),
                              int(attrs["surface_order"]), WireMap(centres, widths) if centres or widths else None,
                              float(attrs.get("aspect", 1.0)))
    except ValueError as e:
        raise error(where, f"the basis attributes do not make a basis: {e}") from None


def _attr(value):
    if isinstance(value, np.ndarray) and value.dtype == object:
        return [v.decode() if isinstance(v, bytes) else v for v in value.tolist()]
    return plain(value)


def _read_branch(group) -> dict:
    data = {name: group[name][()] for name, item in group.items() if isinstance(item, h5py.Dataset)}
    data["attrs"] = {"m": 0} | {k: _attr(v) for k, v in group.attrs.items()}  # m: files before surface branches
    field_acts = float(data["attrs"]["M"]) > 0  # a scene with M > 0 has coils (scene validation)
    if "gauge" not in data["attrs"]:  # files before the free reading (issue 27)
        data["attrs"]["gauge"] = legacy_gauge(data["attrs"], field_acts)
    if "profiles" in group:
        data["profiles"] = {name: item[()] for name, item in columns_of(group["profiles"]).items()}
    sp = group["special_points"]
    data["special_points"] = read_special(sp, field_acts, data["attrs"].get("gauge"))
    data["special_unknowns"] = special_unknowns(sp)[()]
    if "stability" in group:
        data["stability"] = {name: item[()] for name, item in columns_of(group["stability"]).items()}
    if "frequencies" in group:
        for key, prefix in (("frequencies", OMEGA2), ("special_frequencies", SPECIAL_OMEGA2),
                            ("translation_omega2", "translation_"), ("modes", MODES)):
            data[key] = {name.removeprefix(prefix): item[()] for name, item in group["frequencies"].items()
                         if name.startswith(prefix)}
    return data


def columns_of(group) -> dict:
    """{name: dataset} of the datasets of ``group`` that are not its dimension scales (a subgroup's repeated
    coordinates, ``schema.coordinates``, and its own index scales)."""
    return {name: item for name, item in group.items() if isinstance(item, h5py.Dataset) and not item.is_scale}


def check_coordinates(group, where, error) -> None:
    """Every dimension scale below ``group`` that repeats one of an enclosing group's (``schema.coordinates``:
    written since issue 40, absent before) holds the same values as that one."""
    scales = []
    group.visititems(lambda path, item: scales.append((path, item)) if isinstance(item, h5py.Dataset) and
                     item.is_scale else None)
    top = group.parent
    for path, item in scales:
        *groups, name = path.split("/")
        # the enclosing groups from the scale's grandparent out to group.parent, by paths within ``group`` (h5py's
        # ``parent`` looks each one up again from the file's root)
        outers = [group["/".join(groups[:k])] if k else group for k in range(len(groups) - 1, -1, -1)] + [top]
        repeated = next((found for outer in outers if isinstance(found := outer.get(name), h5py.Dataset)),
                        top.get(name))
        if isinstance(repeated, h5py.Dataset) and repeated.is_scale and not np.array_equal(repeated[()], item[()]):
            raise error(where, f"dataset {item.name} does not repeat {repeated.name}, the coordinate it stands for")


def _branch_order(group) -> list:
    """Branch names in the order they were written (the primary branch first)."""
    return sorted(group, key=lambda name: group[name].attrs.get("order", 0))


def _read_snaps(group) -> list:
    if group is None:
        return []
    columns = {k: (group[k].asstr()[()] if k.endswith("branch") else group[k][()]) for k in group}
    n = len(columns.get("pressure", []))
    return [{k: plain(v[i]) for k, v in columns.items()} for i in range(n)]


def read_special(group, field_acts: bool = True, branch_gauge: str | None = None) -> list:
    """Special points written by write_special, as a list of dicts (text columns as str). A file written before
    the free reading (no ``gauge`` column) gets a branch point's from its block (``results.Gauge.of_block``; a
    field acts when ``field_acts``), every other point's its branch's (``branch_gauge``; unknown: held where a
    field acts). A surface branch's points have their ``sector`` (a tuple of characters, () for none) where the file
    stores it (state/sector)."""
    columns = {name: group[name].asstr()[()] for name in SPECIAL_TEXT + ("gauge",) if name in group}
    columns |= {name: group[name][()] for name in ("index", "m", "label") + SPECIAL_NUMBERS + CONDITIONAL_COLUMNS
                if name in group}
    points = [{k: plain(v[i]) for k, v in columns.items()} for i in range(group["kind"].shape[0])]
    if "state" in group and "sector" in group["state"]:  # a surface branch's (files before it: none)
        for s, row in zip(points, group["state"]["sector"][()]):
            s["sector"] = tuple(int(chi) for chi in row) if row.any() else ()
    if "gauge" not in columns:  # an old file (analysis/ imports numba: not for reading a current one)
        from ..analysis.results import Block, Gauge

        blocks = {block.value: block for block in Block if block != Block.NONE}
        fallback = {g.value: g for g in Gauge}.get(branch_gauge, Gauge.HELD if field_acts else Gauge.BOTH)
        for s in points:
            block = blocks.get(s["block"])
            s["gauge"] = (Gauge.of_block(block, field_acts) if block else fallback).value
    return points


def legacy_gauge(attrs: dict, field_acts: bool) -> str:
    """The reading of a branch stored without its ``gauge`` (``results.Branch.gauge`` from its layout; a surface
    branch's ``results.SurfaceBranch.gauge``): both when equator-symmetric or without a field, else held or free
    as its translation is pinned (held: a surface branch)."""
    if not field_acts or attrs.get("symmetric"):
        return "both"
    return "held" if attrs.get("pin_translation", True) else "free"  # a surface branch (m ≥ 1): held
