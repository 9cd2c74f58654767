"""Stability of a whole-sphere state under pressure control: the lowest eigenvalues μ of the second variation,
H c = μ G c with G the displacement norm (1/2π)∫∫|δu|² dA (analysis/azimuthal.py uses the same, so the spectra
compare), on the G-orthogonal complement of the state's exact zero modes, in each symmetry sector of the state's
basis (SphericalBasis.sectors: together the whole space).

Zero modes removed (MODEL.md §8), at the state x:
- relabellings, δx = (w·e_θ) a_θ + (w·e_φ) a_φ for w = e_k × X: always (every axis);
- rigid rotations δx = e_k × x where the field allows them: every axis at M = 0, the coil axis for coaxial loops;
- translations δx = e_k: without a field always (then held and free coincide), with one for a balloon held at its
  centre (``held``); the free balloon keeps them, so that a paramagnetic balloon can slide toward a coil.
A vector that vanishes in a sector is not in it; dependent ones (a rotation and a relabelling on a sphere) are
fine (numerics.eigen.restricted drops them).
"""
import numpy as np

from .basis import COS, MIRROR_Y, SIN, SphericalBasis
from .equilibrium import SurfaceEquilibrium
from ..galerkin.equilibrium import Parameters
from ..numerics import eigen


def in_field(eq: SurfaceEquilibrium, params: Parameters) -> bool:
    """Whether a field acts (coils and M ≠ 0): then only the rotation about the coil axis is free."""
    return eq.has_field and params.M != 0.0


def zero_mode_fields(state: np.ndarray, reference: np.ndarray, field: bool, held: bool) -> list:
    """The displacement fields (3, nodes) of the exact zero modes removed (module docstring) at the node state."""
    units = np.eye(3)[:, :, None]
    modes = []
    for k in range(3):
        w = np.cross(units[k], reference[:3], axis=0)
        modes.append(np.einsum("in,in->n", w, reference[3:6]) * state[3:6]
                     + np.einsum("in,in->n", w, reference[6:9]) * state[6:9])
    for k in (2,) if field else (0, 1, 2):
        modes.append(np.cross(units[k], state[:3], axis=0))
    if held or not field:
        modes += [np.broadcast_to(units[k], state[:3].shape) for k in range(3)]
    return modes


def mode_rows(basis: SphericalBasis, fields: list) -> np.ndarray:
    """The coefficients in ``basis`` of the displacement fields (rows; those outside its space dropped)."""
    rows = np.zeros((9, fields[0].shape[1])) if fields else None
    out = []
    for f in fields:
        rows[:3] = f
        row = 2.0 * np.pi * basis.project(rows)
        if np.linalg.norm(row) > 1e-10 * max(1.0, np.abs(f).max()):
            out.append(row)
    return np.array(out).reshape(-1, basis.size)


def restricted_sectors(eq: SurfaceEquilibrium, c: np.ndarray, params: Parameters, readings=(True, False),
                       only: tuple | None = None) -> dict:
    """{held: {characters: the standard symmetric matrix of the sector's pencil with the zero modes removed}} for
    each reading (held: True, free: False) from one assembly per sector (numerics.eigen.restricted; its eigenvalues
    are the μ, its inertia the sector's); ``only``: the characters of the one sector wanted."""
    state = eq.node_values(c)["state"]
    sectors = [sector for sector in eq.basis.sectors() if sector.size and only in (None, sector.characters)]
    hessians = [eq.hessian(c, params, sector) for sector in sectors]
    made = {}  # (sector, constraint rows) -> matrix: the readings share a sector without a translation
    out = {}
    for held in readings:
        fields = zero_mode_fields(state, eq.basis.nodes["reference"], in_field(eq, params), held)
        out[held] = {}
        for k, (sector, H) in enumerate(zip(sectors, hessians)):
            rows = mode_rows(sector, fields)
            key = (k, rows.tobytes())
            if key not in made:
                made[key] = _restricted(H, sector.gram(), rows)
            out[held][sector.characters] = made[key]
    return out


def sector_spectra(eq: SurfaceEquilibrium, c: np.ndarray, params: Parameters, count: int = 6,
                   readings=(True, False)) -> dict:
    """{held: {characters: the ``count`` lowest μ of the sector}}; a matrix both readings share is solved once."""
    lowest, out = {}, {}
    for held, sectors in restricted_sectors(eq, c, params, readings).items():
        for A in sectors.values():
            if id(A) not in lowest:
                lowest[id(A)] = eigen.lowest_of(A.copy(), count)
        out[held] = {key: lowest[id(A)] for key, A in sectors.items()}
    return out


def spectra(eq: SurfaceEquilibrium, c: np.ndarray, params: Parameters, count: int = 6,
            readings=(True, False)) -> dict:
    """{held: the ``count`` lowest μ over every sector, ascending} (module docstring)."""
    return {held: lowest_over(sectors, count) for held, sectors in sector_spectra(eq, c, params, count, readings).items()}


def lowest_over(sectors: dict, count: int) -> np.ndarray:
    """The ``count`` lowest of the sectors' lowest eigenvalues together, ascending."""
    return np.sort(np.concatenate(list(sectors.values())))[:count]


def _restricted(H: np.ndarray, gram: float, rows: np.ndarray) -> np.ndarray:
    """The standard matrix of (H, gram·I) on the G-orthogonal complement of the coefficient vectors ``rows``
    (numerics.eigen.restricted; the basis is orthonormal, so G = gram·I)."""
    diagonal = np.full(H.shape[0], gram)
    factor = eigen.GramFactor(np.diag(diagonal), orthogonal=True)
    return eigen.restricted(H, factor, rows * diagonal if rows.size else eigen.NO_CONSTRAINT)


def azimuthal_family(basis: SphericalBasis, m: int) -> np.ndarray:
    """E_m: orthonormal columns spanning the cos mφ family δx = R cos mφ e_ρ + T sin mφ e_φ + Z cos mφ e_z in a basis
    with the mirror y → −y and no other reflection (MODEL.md §5; analysis/azimuthal.py's space at the same degree):
    Z in the z blocks of order m, U = R + T in the pairs (x cos, y sin) of order m + 1, D = R − T in the pairs
    (x cos, −y sin) of order m − 1 (δx_x + i δx_y = ½ U e^{i(m+1)φ} + ½ D e^{−i(m−1)φ})."""
    if basis.symmetry != (MIRROR_Y,) or basis.characters != (1,):
        raise ValueError(f"azimuthal_family: needs the mirror-invariant basis, not symmetry {basis.symmetry} "
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
    the whole-sphere counterpart of analysis/azimuthal.spectrum."""
    E = azimuthal_family(eq.basis, m)
    H = E.T @ eq.hessian(c, params) @ E
    fields = zero_mode_fields(eq.node_values(c)["state"], eq.basis.nodes["reference"], in_field(eq, params), held)
    rows = mode_rows(eq.basis, fields) @ E if m == 1 else np.zeros((0, E.shape[1]))
    rows = rows[np.linalg.norm(rows, axis=1) > 1e-10] if rows.size else rows
    return eigen.lowest_of(_restricted(H, eq.basis.gram(), rows), count)
