"""What every stored dataset means: units, long name, and the named dimensions of its axes.

All quantities are nondimensional (MODEL.md §2): lengths in R0, the pressure P = P̄R0/(T0 μ/2), stresses in μ/2,
field in I/(4π R0); their ``units`` attribute is "1" (dimensionless, CF convention) and ``description`` names the
scale (the tilt of a surface branch is in degrees). Indices, counts, flags and labels are not quantities: they
have no ``units`` (``COUNT``). ``describe`` writes the attributes; ``attach_dimensions``
makes ``point``, ``theta``, ``unknown``, ``coefficient``, ``axis`` and ``special`` HDF5 dimension scales
(netCDF-4 dimensions, so xarray with h5netcdf names the axes) and attaches them; ``coordinates`` repeats an
enclosing group's scales in a subgroup, which then opens alone with its coordinates.
"""
import h5py
import numpy as np

from .hdf5 import checksummed

NONDIMENSIONAL = "1"
COUNT = ""  # an index, a count, a flag or a label: no units attribute

#: name: (units, long_name, description)
VARIABLES = {
    "point": (COUNT, "point index", "index of the point along the branch, in continuation order"),
    "theta": ("rad", "material polar angle θ", "material coordinate of the undeformed sphere, 0 at the north pole"),
    "unknown": (COUNT, "unknown index", "Legendre unknowns u (their order: docs/hdf5.md), then P last "
                                                 "(Φ̄ on a voltage continuation)"),
    "special": (COUNT, "special point index", "index of the special point on its branch"),
    "mode_unknown": (COUNT, "mode unknown index", "index into the odd perturbation block of the mode"),
    "snap": (COUNT, "snap-through index", "one row per snap-through under the loading control"),
    "from_branch": ("", "from branch", "the branch whose stable stretch ends"),
    "from_index": (COUNT, "from point", "the last stable point of from_branch"),
    "to_branch": ("", "to branch", "the branch of the lowest-energy stable state at that P (empty: none)"),
    "to_index": (COUNT, "to point", "its point near the same P (-1: none)"),
    "eigenvalue": (COUNT, "eigenvalue index", "0: the lowest eigenvalue of the block, 1: the next, …"),
    "frequency": (COUNT, "frequency index", "0: the lowest natural frequency of the block, 1: the next, …"),
    "component": (COUNT, "displacement component", "0: δρ, 1: δz, 2: δφ (m ≥ 1: the amplitudes of cos mφ, cos mφ, "
                                                    "sin mφ; m = 0: δφ = 0)"),
    "translation_axial": (NONDIMENSIONAL, "Ω² of the rigid axial translation",
                          "½ tᵀKt/tᵀMt of the translation along the axis: the field's stiffness (0 without a field, "
                          "> 0 the field restores the balloon, < 0 it pulls it away; docs/dynamics.md)"),
    "translation_lateral": (NONDIMENSIONAL, "Ω² of the rigid lateral translation",
                            "the same for the translation across the axis (m = 1)"),
    "perturbation_degree": (COUNT, "perturbation degree", "Legendre degree N of the perturbation basis"),
    "coefficient": (COUNT, "coefficient index", "coefficients c of the displacement in the branch's "
                                                         "spherical harmonics, in block order (docs/hdf5.md)"),
    "axis": (COUNT, "Cartesian axis", "0: x, 1: y, 2: z (z the coil axis)"),
    "pressure": (NONDIMENSIONAL, "pressure P", "P = P̄ R0 / (T0 μ/2)"),
    "voltage": (NONDIMENSIONAL, "voltage Φ̄", "Φ̄ = (Φ/H) √(ε/μ): voltage across the thickness (docs/scenes.md)"),
    "M": (NONDIMENSIONAL, "field M", "M = I²/(16π² R0² μ): the coils' field intensity, the parameter of a "
                                     "continuation in M at fixed P (docs/scenes.md)"),
    "volume": (NONDIMENSIONAL, "enclosed volume V", "V / R0³ (4π/3 for the undeformed sphere)"),
    "amount": (NONDIMENSIONAL, "gas amount n", "n = P V, the isothermal ideal gas P V = n in these units: "
                                               "n = N R T / (T0 μ R0² / 2) for N moles at temperature T"),
    "lam2_top": (NONDIMENSIONAL, "λ2 at the north pole", "hoop stretch λ2(θ = 0); on a surface branch √(λ1 λ2) "
                                                           "at the material pole (equal there when axisymmetric)"),
    "lam2_bottom": (NONDIMENSIONAL, "λ2 at the south pole", "hoop stretch λ2(θ = π); on a surface branch √(λ1 λ2) "
                                                           "at the material pole"),
    "coefficients": (NONDIMENSIONAL, "displacement coefficients c", "u = x − X in real spherical harmonics of "
                                                                    "degree ≤ surface_degree (docs/hdf5.md)"),
    "centroid": (NONDIMENSIONAL, "centroid of the enclosed body", "x_c / R0, offset from the held centre"),
    "force": (NONDIMENSIONAL, "net force of the field", "F = ½ χ M (1/2π) ∫∫ ∇H² dA, per 2π in units of μ H R0 "
                                                       "(the hold's reaction is −F; surface/loads.py)"),
    "torque": (NONDIMENSIONAL, "net torque of the field about the centre", "T = ½ χ M (1/2π) ∫∫ x × ∇H² dA, per 2π "
                                                                          "in units of μ H R0² (zero at equilibrium: "
                                                                          "the balloon turns freely)"),
    "tilt": ("degree", "tilt of the body's axis", "angle between e_z and the principal axis of the enclosed "
                                                  "body's second moments that stands apart (the largest, or the "
                                                  "smallest when closer to the middle one), 0 … 90"),
    "eta_top": (NONDIMENSIONAL, "η at the north pole", "axial position η(0) / R0"),
    "eta_bottom": (NONDIMENSIONAL, "η at the south pole", "axial position η(π) / R0"),
    "lam1_equator": (NONDIMENSIONAL, "λ1 at the equator", "meridional stretch λ1(π/2)"),
    "lam2_equator": (NONDIMENSIONAL, "λ2 at the equator", "hoop stretch λ2(π/2)"),
    "converged": (COUNT, "converged", "true: a finite converged Newton solution"),
    "residual": (NONDIMENSIONAL, "residual norm", "max-norm of the Ritz residual at the solution"),
    "error_estimate": (NONDIMENSIONAL, "discretisation error estimate", "change of the pole stretch against a "
                                                                          "higher degree (docs/numerics.md)"),
    "newton_iterations": (COUNT, "Newton iterations", "iterations of the corrector at this point"),
    "solved_degree": (COUNT, "solved Legendre degree", "degree the point was solved at before storage"),
    "unknowns": (NONDIMENSIONAL, "unknowns (u, P)", "Legendre unknowns u of λ2, η (docs/hdf5.md), then P"),
    "lam1": (NONDIMENSIONAL, "meridional stretch λ1(θ)", "λ1 = sqrt(λ2'² ... ) (MODEL.md §1)"),
    "lam2": (NONDIMENSIONAL, "hoop stretch λ2(θ)", "λ2 = ρ / sin θ"),
    "rho": (NONDIMENSIONAL, "radius ρ(θ)", "distance from the axis / R0"),
    "eta": (NONDIMENSIONAL, "axial position η(θ)", "z / R0"),
    "kind": ("", "special point kind", "AUTO label: LP fold in P, TP fold in the pole stretch, LV fold in V, "
                                       "LN fold in n, BP branch point, EP end point, UZ user point"),
    "classification": ("", "classification", "pitchfork, transcritical, ... (docs/hdf5.md); empty if none"),
    "block": ("", "stability block", "the second-variation block whose eigenvalue crosses zero"),
    "gauge": ("", "reading", "held (centre held: b_0 = 0, the net axial force a reaction), free (net axial force "
                             "zero) or both (no field, or no translation component)"),
    "status": ("", "location status", "located (converged extended system) or approximate"),
    "reason": ("", "reason", "why a special point is approximate; empty when located"),
    "stop_code": ("", "stop code", "analysis.results.StopCode of an end point"),
    "note": ("", "note", "for people: the stop message or the mode"),
    "index": (COUNT, "point index", "the special point lies between points index and index + 1"),
    "m": (COUNT, "azimuthal wave number", "m of the crossing mode (0: axisymmetric)"),
    "sector": (COUNT, "symmetry sector", "a secondary branch point of a surface branch: the character ±1 of its "
                                         "crossing mode under each reflection of the branch's symmetry attribute; "
                                         "0 … 0: none"),
    "reflection": (COUNT, "reflection index", "row of the branch's symmetry attribute"),
    "label": (COUNT, "special-point label", "unique in the file (1, 2, … through the branches): what `continue` "
                                            "takes"),
    "uncertainty": (NONDIMENSIONAL, "uncertainty in P", "bracket width in P of an approximate point; 0 if located"),
    "E2": (NONDIMENSIONAL, "normal-form E2", "energy expansion coefficient along the mode (docs/second_variation.md)"),
    "E3": (NONDIMENSIONAL, "normal-form E3", "cubic coefficient"),
    "E4": (NONDIMENSIONAL, "normal-form E4", "quartic coefficient"),
    "mode": (NONDIMENSIONAL, "critical mode", "null vector φ on the odd perturbation block"),
    "stable_pressure": (COUNT, "stable, pressure control", "held at the centre, pressure control"),
    "stable_volume": (COUNT, "stable, volume control", "held at the centre, volume-preserving"),
    "stable_pressure_free": (COUNT, "stable, free, pressure control", "axial translation included"),
    "stable_volume_free": (COUNT, "stable, free, volume control", "axial translation included"),
    "stable_gas": (COUNT, "stable, gas control", "held at the centre, fixed amount of isothermal gas"),
    "stable_gas_free": (COUNT, "stable, free, gas control", "axial translation included"),
}
LOWEST = (NONDIMENSIONAL, "lowest eigenvalue", "smallest eigenvalue of the second-variation block")
OMEGA2 = "omega2_"  # the prefix of the natural frequencies per block (frequencies/omega2_<block>)
FREQUENCY = (NONDIMENSIONAL, "squared natural frequency Ω²", "Ω² = ω² R0² ρ/μ of a mode of the block (ω the angular "
                                                           "frequency, ρ the density, μ the initial shear modulus); "
                                                           "negative: an unstable mode; NaN: the block has fewer modes")
SPECIAL_OMEGA2 = "special_" + OMEGA2  # ... at the special points (frequencies/special_omega2_<block>)
MODES = "modes_"  # ... their mode shapes at the special points (frequencies/modes_<block>, [dynamics] modes)
PREFIXED = {"lowest_": LOWEST, OMEGA2: FREQUENCY,
            SPECIAL_OMEGA2: (NONDIMENSIONAL, "squared natural frequency Ω² at a special point", FREQUENCY[2]),
            MODES: (NONDIMENSIONAL, "mode shape at a special point", "displacement of the reference meridian "
                    "(δρ, δz, δφ) / R0 of the mode of special_omega2 for a unit modal mass, (1/2π)∫∫|δx|² dA = 1 on "
                    "the reference sphere (docs/dynamics.md); NaN: fewer modes")}


def describe(dataset, name: str | None = None) -> None:
    """Set ``units`` (a quantity's only), ``long_name`` and ``description`` of an h5py dataset from VARIABLES (by
    its own name)."""
    name = name or dataset.name.rsplit("/", 1)[-1]
    prefix = next((p for p in PREFIXED if name.startswith(p)), None)
    units, long_name, description = VARIABLES[name] if prefix is None else PREFIXED[prefix]
    if prefix is not None:
        long_name = f"{long_name}, block {name.removeprefix(prefix)}"
    dataset.attrs.update({"units": units} if units else {})
    dataset.attrs.update({"long_name": long_name, "description": description})


#: short name of a second parameter: its long name (others: "second parameter KEY", KEY its scene key)
PARAMETERS = {"M": "field intensity M", "chi": "magnetic susceptibility χ",
              "alpha1": "Ogden exponent α1 (μ1 keeps Σ μ_i α_i = 4)"}


def describe_parameter(dataset, key: str) -> None:
    """``units``, ``long_name`` and ``description`` of a second parameter's values stored under its short name
    (``key``: its scene key, as ``analysis.critical.second_parameter`` names it)."""
    name = dataset.name.rsplit("/", 1)[-1]
    dataset.attrs.update({"units": NONDIMENSIONAL, "long_name": PARAMETERS.get(name, f"second parameter {key}"),
                          "description": f"the continued second parameter, scene key {key} (docs/hdf5.md)"})


def scale(group, name: str, length: int = 0, values=None):
    """A dimension scale ``name`` in ``group`` (described): ``values``, or the index 0 … length − 1."""
    dataset = checksummed(group, name, np.arange(length, dtype=np.int64) if values is None else values)
    dataset.make_scale(name)
    describe(dataset)
    return dataset


def coordinates(group, *dimensions) -> tuple:
    """The dimension scales ``dimensions`` of an enclosing group repeated in ``group`` (same names and values), so
    that ``group`` opened alone (``xarray.open_dataset(..., group=...)``, a netCDF-4 group) carries its coordinates;
    returned in order, to attach its datasets to."""
    return tuple(scale(group, d.name.rsplit("/", 1)[-1], values=d[()]) for d in dimensions)


def attach_dimensions(group, axes: dict) -> None:
    """Attach to every dataset in ``group`` the scales of its axes (``axes``: {dataset name or ndim: (scale, …)},
    the name first) and describe it; the scales themselves are left alone."""
    for name, item in group.items():
        if isinstance(item, h5py.Dataset) and not item.is_scale:
            for axis, dimension in enumerate(axes.get(name) or axes[item.ndim]):
                item.dims[axis].attach_scale(dimension)
            describe(item)


#: Datasets whose every value is finite (a stored point is a converged solution, its measures and shape; a
#: special point's state and pole values; a curve's q and mode): the readers refuse NaN or inf in them. The others
#: may hold NaN (E2, E3, E4 of a point that has no normal form, critical_q) or are bounds and estimates
#: (uncertainty, error_estimate, the lowest eigenvalues).
FINITE = frozenset({"pressure", "voltage", "M", "volume", "amount", "lam2_top", "lam2_bottom", "eta_top", "eta_bottom",
                    "lam1_equator", "lam2_equator", "residual", "unknowns", "coefficients", "centroid", "tilt",
                    "force", "torque", "theta", "lam1", "lam2", "rho", "eta", "q", "mode"})
SCALE_ATTRIBUTES = ("CLASS", "NAME")  # HDF5 dimension scales (netCDF-4 dimensions); and REFERENCE_LIST (the
#                                       datasets attached), but on a branch's theta (``stands_alone``)


def stands_alone(scale) -> bool:
    """Whether the dimension scale ``scale`` is a branch's θ: the coordinate of the branch's group, attached to no
    dataset (its profiles and frequencies attach their own copies, ``coordinates``), so without REFERENCE_LIST."""
    return scale.name.rsplit("/", 1)[-1] == "theta" and isinstance(scale.parent.get("profiles"), h5py.Group)


def check_described(group, path, error) -> None:
    """Every dataset below ``group`` as ``describe``, ``scale`` and ``attach_dimensions`` write it, for a file
    written with checksums (io.layout.carries_checksums): checksummed where it can be (layout.can_checksum), a
    dimension scale with its SCALE_ATTRIBUTES and REFERENCE_LIST (a branch's θ none: ``stands_alone``), every other
    dataset with DIMENSION_LIST, and each with long_name,
    description and, a quantity's (VARIABLES), units; ``error`` naming the dataset otherwise."""
    from .layout import can_checksum, naming

    items = []
    group.visititems(lambda name, item: items.append((name, item)) if isinstance(item, h5py.Dataset) else None)
    prefix = group.name.rstrip("/")
    for where, item in items:
        where = f"{prefix}/{where}"  # the path it was reached by (not item.name: HDF5 searches for a name)
        if can_checksum(item.dtype, item.size) and not item.fletcher32:
            raise error(path, f"dataset {where} has no Fletcher32 checksum (every dataset of this file has: "
                              "rewritten after it was written)")
        name = where.rsplit("/", 1)[-1]
        with naming(f"dataset {where}", path, error):  # a damaged attribute (CLASS) is not a datatype
            is_scale = h5py.h5ds.is_scale(item.id)
            keys = set(item.attrs)
        units = (LOWEST if name.startswith("lowest_") else VARIABLES.get(name, (COUNT,)))[0]
        scale_needs = (() if stands_alone(item) else ("REFERENCE_LIST",)) if is_scale else ()
        needed = (SCALE_ATTRIBUTES + scale_needs if is_scale else ("DIMENSION_LIST",) if item.ndim else ()) + (
            "long_name", "description") + (("units",) if units else ())
        missing = [key for key in needed if key not in keys]
        if missing:
            raise error(path, f"dataset {where} is missing its attribute{'s' if len(missing) > 1 else ''} "
                              f"{', '.join(missing)}")
