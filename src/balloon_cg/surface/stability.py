"""Stability of a whole-sphere state: the lowest eigenvalues μ of the second variation, H c = μ G c with G the
displacement norm (1/2π)∫∫|δu|² dA over the reference (``mass_factor``: gram·I in the orthonormal harmonics on the
sphere, ``SphericalBasis.mass`` with the area element S' d(cos θ) dφ on a spheroid; the kinetic energy's mass matrix,
so μ/2 = Ω²: dynamics/surface.py; analysis/stability/azimuthal.py uses the same, so the spectra compare), on the
G-orthogonal complement of the state's exact zero modes, in each symmetry sector of the state's basis
(SphericalBasis.sectors: together the whole space), for a balloon held at its centre or free, under each control
(a ``Reading``), as analysis/stability/axisymmetric.py for axisymmetric modes:
- pressure control: H;
- volume control: H on the perturbations that keep the volume, gᵀc = 0, g = ∂Ṽ/∂c = −∂²E/∂P∂c (Ṽ = V/2π);
- gas control (isothermal ideal gas, P V fixed): H + (P/Ṽ) g gᵀ.
The volume is invariant under the state's reflections, so g lies in its own sector (every character +1): the
other sectors read the same under every control.

Zero modes removed (MODEL.md §8), at the state x:
- relabellings, δx = (w·A_θ/S'²) a_θ + (w·e_φ) a_φ for w = e_k × X: always, about every axis whose rotation maps
  the reference onto itself (SphericalBasis.relabellings: each on the sphere, where S' = 1, the axis on a spheroid);
- rigid rotations δx = e_k × x where the field allows them: every axis at M = 0, the coil axis for coaxial loops,
  none for loops anywhere (``gauge.FieldSymmetry``);
- translations δx = e_k: without a field always (then held and free coincide), with one for a balloon held at its
  centre (``held``); the free balloon keeps them, so that a paramagnetic balloon can slide toward a coil.
A vector that vanishes in a sector is not in it; dependent ones (a rotation and a relabelling on a sphere) are
fine (numerics.eigen.restricted drops them).
"""
import functools
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from .basis import COS, MIRROR_Y, SIN, SphericalBasis
from .equilibrium import SurfaceEquilibrium
from .gauge import FieldSymmetry
from .measures import body_moments
from ..galerkin.equilibrium import Parameters
from ..numerics import eigen, interrupt
from ..scene.loading import Control


class Reading(NamedTuple):
    """A balloon held at its centre or free, under a control."""

    held: bool
    control: Control = Control.PRESSURE

    @property
    def name(self) -> str:
        """'held', 'free', 'held_volume', … (the keys of SurfaceBranch.stability)."""
        base = "held" if self.held else "free"
        return base if self.control == Control.PRESSURE else f"{base}_{self.control.value}"


PRESSURE_READINGS = (Reading(True), Reading(False))
READINGS = tuple(Reading(held, control) for control in Control for held in (True, False))


def field_symmetry(eq: SurfaceEquilibrium, params: Parameters) -> FieldSymmetry:
    """What the field leaves free: nothing acts without coils or at M = 0; coaxial loops leave the rotation about
    their axis; loops anywhere no rigid motion."""
    if not eq.has_field or params.M == 0.0:
        return FieldSymmetry.NONE
    return FieldSymmetry.AXIAL if eq.coaxial else FieldSymmetry.GENERAL


def zero_mode_fields(state: np.ndarray, basis: SphericalBasis, symmetry: FieldSymmetry, held: bool) -> list:
    """The displacement fields (3, nodes) of the exact zero modes removed (module docstring) at the node state of
    ``basis``."""
    units = np.eye(3)[:, :, None]
    reference = basis.nodes["reference"]
    rate = np.repeat(basis.nodes["rate"], basis.n_phi)
    modes = []
    for k in basis.relabellings:
        w = np.cross(units[k], reference[:3], axis=0)
        modes.append(np.einsum("in,in->n", w, reference[3:6]) / rate**2 * state[3:6]
                     + np.einsum("in,in->n", w, reference[6:9]) * state[6:9])
    for k in symmetry.free_rotations:
        modes.append(np.cross(units[k], state[:3], axis=0))
    if held or symmetry == FieldSymmetry.NONE:
        modes += [np.broadcast_to(units[k], state[:3].shape) for k in range(3)]
    return modes


def mode_rows(basis: SphericalBasis, fields: list) -> np.ndarray:
    """The coefficients in ``basis`` of the displacement fields (rows; those outside its space dropped)."""
    out = []
    for f in fields:
        row = 2.0 * np.pi * basis.project(f)
        if np.linalg.norm(row) > 1e-10 * max(1.0, np.abs(f).max()):
            out.append(row)
    return np.array(out).reshape(-1, basis.size)


def _sectors(eq: SurfaceEquilibrium, c: np.ndarray, params: Parameters, readings, only: tuple | None,
             within: dict | None = None):
    """Yields (sector, H, g, groups, gas weight P/Ṽ) per symmetry sector: its Hessian, g = ∂Ṽ/∂c on the state's
    own sector under a controlled reading (else None), and groups {(zero-mode rows' bytes, control): (rows, the
    readings sharing that matrix)} (a sector without a translation reads the same held and free; one without g
    the same under every control); ``only``: the characters of the sectors wanted (default all); ``within``:
    {characters: a ``sub_basis`` of that sector}, whose perturbations stand for the sector's (Rayleigh–Ritz:
    ``sub_basis``)."""
    state = eq.node_values(c)["state"]
    fields = {held: zero_mode_fields(state, eq.basis, field_symmetry(eq, params), held)
              for held in {r.held for r in readings}}
    controlled = any(r.control != Control.PRESSURE for r in readings)
    weight = params.P / body_moments(eq.basis, state)[0] if controlled else None
    for whole in eq.basis.sectors():
        if not whole.size or (only is not None and whole.characters not in only):
            continue
        sector = (within or {}).get(whole.characters, whole)
        H = eq.hessian(c, params, sector)
        g = -eq.parameter_derivative(c, params, "P", sector) if controlled and _own(sector, eq.basis) else None
        rows_of = {held: mode_rows(sector, modes) for held, modes in fields.items()}
        groups = {}
        for r in readings:
            rows = rows_of[r.held]
            control = r.control if g is not None else Control.PRESSURE
            groups.setdefault((rows.tobytes(), control), (rows, []))[1].append(r)
        yield sector, H, g, groups, weight


def sector_matrices(eq: SurfaceEquilibrium, c: np.ndarray, params: Parameters, readings=PRESSURE_READINGS,
                    only: tuple | None = None):
    """Yields (characters, the readings, A) one matrix at a time: A the standard symmetric matrix of the sector's
    pencil under those readings (module docstring), the zero modes removed (numerics.eigen.restricted: its
    eigenvalues are the μ, its inertia the sector's), one assembly per sector and one matrix for the readings that
    share it (``_sectors``); ``only``: the characters of the sectors wanted (default all)."""
    for sector, H, g, groups, weight in _sectors(eq, c, params, readings, only):
        for (_, control), (rows, shared) in groups.items():
            yield sector.characters, tuple(shared), _reading_matrix(H, mass_factor(sector), rows, control, g, weight)


def _reading_matrix(H, mass: eigen.GramFactor, rows, control: Control, g, weight) -> np.ndarray:
    """The standard matrix of one reading (module docstring): H without the zero modes ``rows``, on gᵀc = 0 under
    volume control, H + (P/Ṽ) g gᵀ under gas control."""
    if control == Control.VOLUME:
        return _restricted(H, mass, rows, g)
    if control == Control.GAS:
        return _restricted(H + weight * np.outer(g, g), mass, rows)
    return _restricted(H, mass, rows)


def restricted_sectors(eq: SurfaceEquilibrium, c: np.ndarray, params: Parameters, readings=PRESSURE_READINGS,
                       only: tuple | None = None) -> dict:
    """{reading: {characters: matrix}} of ``sector_matrices``, all at once."""
    out = {r: {} for r in readings}
    for key, shared, A in sector_matrices(eq, c, params, readings, only):
        for r in shared:
            out[r][key] = A
    return out


def sector_spectra(eq: SurfaceEquilibrium, c: np.ndarray, params: Parameters, count: int = 6,
                   readings=PRESSURE_READINGS, guesses: dict | None = None, only: tuple | None = None,
                   within: dict | None = None) -> dict:
    """{reading: {characters: the ``count`` lowest μ of the sector}}, one sector at a time in memory. ``guesses``
    (the same layout, the previous point's along a branch) let a large sector follow its lowest eigenvalues: one
    Cholesky factorisation of its matrix with the fewest zero modes removed under pressure control (the lowest
    spectrum of its readings), shifted below the lowest guess (numerics.eigen.ShiftInvert), serves every reading:
    the other zero modes and the volume's gᵀc = 0 are constraints, the gas term a positive rank-one update in that
    matrix's coordinates (numerics.eigen.restricted_rows); the readings' Lanczos runs share each solve
    (numerics.eigen.ShiftInvert.lowest_of_relatives). Without guesses, below FOLLOWING_SIZE, or without a
    shift below the spectrum, each reading's matrix is solved dense (numerics.eigen.lowest_of). ``only``: the
    characters of the sectors wanted (default all): each sector follows its own guesses alone, so the sectors of a
    branch can be read apart (on different cores) with the same numbers. ``within``: {characters: a ``sub_basis``
    of the sector} to read it on instead (upper bounds of its eigenvalues). A signal (numerics.interrupt.check)
    raises Interrupted before each sector and each dense reading."""
    out = {r: {} for r in readings}
    for sector, H, g, groups, weight in _sectors(eq, c, params, readings, only, within):
        interrupt.check()
        key, mass = sector.characters, mass_factor(sector)
        previous = [guesses[r][key][0] for r in readings if guesses and key in guesses.get(r, {})]
        base_rows = min((rows for rows, _ in groups.values()), key=len)
        shifted = None
        if previous and H.shape[0] - eigen.rank_of(base_rows) >= eigen.FOLLOWING_SIZE:
            shifted = eigen.ShiftInvert.below(_restricted(H, mass, base_rows), float(min(previous)))
        relatives = {}  # the readings read through the factorisation, in lockstep
        for group, (rows, _) in groups.items() if shifted is not None else ():
            relative = _relative(H, mass, base_rows, rows, group[1], g, weight)
            if relative is not None:
                relatives[group] = relative
        found = {} if not relatives else dict(zip(relatives, shifted.lowest_of_relatives(
            [(count, *relative) for relative in relatives.values()])))
        for group, (rows, shared) in groups.items():
            values = found.get(group)
            if values is None:
                interrupt.check()
                values = eigen.lowest_of(_reading_matrix(H, mass, rows, group[1], g, weight), count)
            for r in shared:
                out[r][key] = values
    return out


def sub_basis(sector: SphericalBasis, degree: int, order: int) -> SphericalBasis:
    """The perturbations of ``sector`` of degree ≤ ``degree`` and order ≤ ``order``, on its nodes and map: each
    block's first functions (a block's orthonormalisation is triangular, so they span the same space in both), its
    Hessian the sector's principal submatrix. Rayleigh–Ritz: the k-th lowest μ read on it is an upper bound of the
    sector's k-th (its space, less the zero modes' projections, lies in the sector's less the zero modes)."""
    if not 1 <= order <= degree <= sector.degree or order > sector.order:
        raise ValueError(f"sub_basis: degree = {degree}, order = {order}: must satisfy 1 ≤ order ≤ degree, degree "
                         f"≤ {sector.degree}, order ≤ {sector.order} (the sector's)")
    return replace(sector, degree=degree, order=order)


def _relative(H, mass: eigen.GramFactor, base_rows, rows, control: Control, g, weight):
    """(constraints, update) of one reading in the coordinates of the matrix without the zero modes ``base_rows``
    (``sector_spectra``: ``eigen.ShiftInvert.lowest``'s arguments), or None where its matrix is small (solved
    dense, as lowest_following would)."""
    normals = mass.weighed(base_rows)
    extra = np.vstack([mass.weighed(rows)] + ([g[None, :]] if control == Control.VOLUME else []))
    if H.shape[0] - eigen.rank_of(mass.directions(extra)) < eigen.FOLLOWING_SIZE:
        return None
    constraints = eigen.restricted_rows(mass, normals, extra) if extra.size else None
    update = None
    if control == Control.GAS:
        u = eigen.restricted_rows(mass, normals, g[None, :])
        update = (u[0], weight) if len(u) else None
    return constraints, update


def spectra(eq: SurfaceEquilibrium, c: np.ndarray, params: Parameters, count: int = 6,
            readings=PRESSURE_READINGS) -> dict:
    """{reading: the ``count`` lowest μ over every sector, ascending} (module docstring)."""
    return {r: lowest_over(sectors, count) for r, sectors in sector_spectra(eq, c, params, count, readings).items()}


def lowest_over(sectors: dict, count: int) -> np.ndarray:
    """The ``count`` lowest of the sectors' lowest eigenvalues together, ascending."""
    return np.sort(np.concatenate(list(sectors.values())))[:count]


def _restricted(H: np.ndarray, mass: eigen.GramFactor, rows: np.ndarray,
                normal: np.ndarray | None = None) -> np.ndarray:
    """The standard matrix of (H, G) on the G-orthogonal complement of the coefficient vectors ``rows`` and, given,
    on normalᵀc = 0 (numerics.eigen.restricted), G = LLᵀ the factor ``mass`` (``mass_factor``)."""
    normals = [mass.weighed(rows)] if rows.size else []
    if normal is not None:
        normals.append(normal[None, :])
    return eigen.restricted(H, mass, np.vstack(normals) if normals else eigen.NO_CONSTRAINT)


@functools.lru_cache(maxsize=8)
def mass_factor(sector: SphericalBasis) -> eigen.GramFactor:
    """The factor of G, the displacement norm (1/2π)∫∫|δu|² dA over the reference in the coefficients of
    ``sector`` (module docstring), built once per basis (it holds no state): ``_mass_on``."""
    return _mass_on(sector)


def _mass_on(basis: SphericalBasis, E: np.ndarray | None = None) -> eigen.GramFactor:
    """The factor of G on the columns E of ``basis`` (default all): the scaling of gram·I on the sphere (the basis
    is orthonormal; so are E's columns), on a spheroid the Cholesky factors of M = ``SphericalBasis.mass`` block by
    block (M is block-diagonal in the basis' blocks), or that of Eᵀ M E."""
    if basis.aspect == 1.0:
        return eigen.GramFactor(np.full(basis.size if E is None else E.shape[1], basis.gram()), orthogonal=True)
    M = basis.mass()
    if E is None:
        return eigen.GramFactor(M, blocks=tuple(b.slice for b in basis.blocks))
    return eigen.GramFactor(E.T @ M @ E)


def _own(sector: SphericalBasis, basis: SphericalBasis) -> bool:
    """Whether ``sector`` is the state's own (its characters those of the state's basis)."""
    return sector.characters == basis.characters


def azimuthal_family(basis: SphericalBasis, m: int) -> np.ndarray:
    """E_m: orthonormal columns spanning the cos mφ family δx = R cos mφ e_ρ + T sin mφ e_φ + Z cos mφ e_z in a basis
    with the mirror y → −y (MODEL.md §5; analysis/stability/azimuthal.py's space at the same degree; with more reflections,
    the part of it they keep):
    Z in the z blocks of order m, U = R + T in the pairs (x cos, y sin) of order m + 1, D = R − T in the pairs
    (x cos, −y sin) of order m − 1 (δx_x + i δx_y = ½ U e^{i(m+1)φ} + ½ D e^{−i(m−1)φ})."""
    if MIRROR_Y not in basis.symmetry or basis.characters[basis.symmetry.index(MIRROR_Y)] != 1:
        raise ValueError(f"azimuthal_family: needs a mirror-invariant basis, not symmetry {basis.symmetry} "
                         f"with characters {basis.characters}")
    find = {(b.component, b.m, b.t): b for b in basis.blocks}
    columns = []
    if (2, m, COS) in find:
        b = find[2, m, COS]
        columns += [{b.offset + i: 1.0} for i in range(len(b.degrees))]
    for order, sign in ((m + 1, 1.0), (m - 1, -1.0)):
        x, y = find.get((0, order, COS)), find.get((1, order, SIN))
        if x is None:
            continue
        if y is not None and x.degrees != y.degrees:
            raise ValueError(f"azimuthal_family: the reflections {basis.symmetry} split the pair (x cos, y sin) of "
                             f"order {order}")
        for i in range(len(x.degrees)):
            columns.append({x.offset + i: 1.0} if y is None else
                           {x.offset + i: np.sqrt(0.5), y.offset + i: sign * np.sqrt(0.5)})
    E = np.zeros((basis.size, len(columns)))
    for k, column in enumerate(columns):
        for row, value in column.items():
            E[row, k] = value
    return E


def azimuthal_spectrum(eq: SurfaceEquilibrium, c: np.ndarray, params: Parameters, m: int, held: bool = True,
                       count: int = 6) -> np.ndarray:
    """The lowest μ of the whole-sphere Hessian restricted to the cos mφ family (``azimuthal_family``) at an
    axisymmetric state c of a mirror-invariant basis, its zero modes removed as ``restricted_sectors`` removes them:
    the whole-sphere counterpart of analysis/stability/azimuthal.spectrum."""
    E = azimuthal_family(eq.basis, m)
    H = E.T @ eq.hessian(c, params) @ E
    fields = zero_mode_fields(eq.node_values(c)["state"], eq.basis, field_symmetry(eq, params), held)
    rows = mode_rows(eq.basis, fields) @ E if m == 1 else np.zeros((0, E.shape[1]))
    rows = rows[np.linalg.norm(rows, axis=1) > 1e-10] if rows.size else rows
    return eigen.lowest_of(_restricted(H, _mass_on(eq.basis, E), rows), count)
