"""Applied field of coaxial circular current loops, closed form (MODEL.md §3).

Units: lengths in R0, field with the factor I/(4π R0) removed. A loop (radius a, height h, signed current s)
contributes s·h(ρ, z − h; a), where h follows from the stream function ψ = 32 a² ρ² G(m)/S³,
S² = (a + ρ)² + ζ², m = 4aρ/S², G(m) = ((1 − m/2) K(m) − E(m))/m², via h_ρ = −ψ_ζ/ρ, h_z = ψ_ρ/ρ
(derived and emitted by codegen/field.py; no division by ρ, so exact on the axis). At a loop's centre
H = 2π/a.

G and its m-derivatives come from m1 = 1 − m = ((a − ρ)² + ζ²)/S², formed to full relative precision so that
points near a wire keep their digits. For m1 ≥ PIECE_FLOOR: the generated Taylor polynomials of G^(j), j ≤ 3,
about the centre c of m1's piece (codegen/field.py: 8 pieces to each octave of m1, PIECE_TERMS terms, every
dropped tail at most 2^-60 of the value on its piece), at t = m − c = c1 − m1 (exact); closer to a wire: the
closed form in K and N = (1 − m/2) K − E, both from the AGM (N without cancellation). The jitted functions return
NaN within WIRE_TOLERANCE·a of a wire (the solver treats non-finite values as failures); the Python-level
functions raise FieldError there instead.

ρ < 0 is read as the mirror point across the axis (h_ρ odd in ρ, h_z even), so rounding at a pole is harmless;
at ρ = 0 exactly the odd-in-ρ entries are returned as exact zeros, so Q_ρ(0, z) = 0.
"""
import math

import numpy as np
from numba import njit

from .elliptic import loop_elliptic
from ..generated import FIELD_ROWS
from ..generated.coil_field import (
    STREAM_PIECE_CENTRES,
    STREAM_PIECE_GRID,
    STREAM_PIECES,
    coil_field,
    stream_shape_closed,
)

WIRE_TOLERANCE = 1e-12
PIECES_PER_OCTAVE, PIECE_OCTAVES, PIECE_TERMS = STREAM_PIECE_GRID
PIECE_FLOOR = 2.0**-PIECE_OCTAVES  # m1 below it (m > 1 − 2^-12): the AGM
_CENTRES = np.array(STREAM_PIECE_CENTRES)


def derivative_rows(coefficients, terms: int) -> np.ndarray:
    """(pieces, 4, terms): row j of a piece holds the Taylor coefficients a_{k+j} (k + j)!/k!, k < terms, of G^(j),
    from the generated a_k = G^(k)(c)/k! (terms + 3 of them per piece)."""
    a = np.asarray(coefficients, dtype=float).reshape(-1, terms + 3)
    k = np.arange(terms, dtype=float)
    falling = (np.ones(terms), k + 1.0, (k + 1.0) * (k + 2.0), (k + 1.0) * (k + 2.0) * (k + 3.0))
    return np.ascontiguousarray(np.stack([a[:, j:j + terms] * falling[j] for j in range(4)], axis=1))


_ROWS = derivative_rows(STREAM_PIECES, PIECE_TERMS)


class FieldError(ValueError):
    """A field evaluation at (or within WIRE_TOLERANCE·a of) a coil's wire, or an invalid coil table."""


@njit(cache=True)
def _polynomial(c, t, t2, t4):
    """Σ_k c_k t^k, k < PIECE_TERMS (a multiple of 4), by four interleaved Horner chains in t⁴: a quarter of the
    latency (the constant length lets the four calls of stream_shape unroll into one straight line)."""
    p0 = p1 = p2 = p3 = 0.0
    for k in range(PIECE_TERMS - 4, -1, -4):
        p0 = p0 * t4 + c[k]
        p1 = p1 * t4 + c[k + 1]
        p2 = p2 * t4 + c[k + 2]
        p3 = p3 * t4 + c[k + 3]
    return p0 + t * p1 + t2 * (p2 + t * p3)


@njit(cache=True)
def stream_shape(m, m1):
    """(G, G', G'', G''') at m, with m1 = 1 − m (pass 1.0 - m unless 1 − m is known more accurately)."""
    if m1 >= PIECE_FLOOR:
        fraction, exponent = math.frexp(m1)  # m1 = f·2^e, ½ ≤ f < 1: octave −e, piece by f
        piece = -exponent * PIECES_PER_OCTAVE + int((fraction - 0.5) * (2 * PIECES_PER_OCTAVE))
        if piece < 0:  # m1 = 1 (on the axis): the top piece of octave 0
            piece = PIECES_PER_OCTAVE - 1
        t = _CENTRES[piece] - m1  # = m − c, exact (Sterbenz)
        t2 = t * t
        t4 = t2 * t2
        rows = _ROWS[piece]
        return (_polynomial(rows[0], t, t2, t4), _polynomial(rows[1], t, t2, t4),
                _polynomial(rows[2], t, t2, t4), _polynomial(rows[3], t, t2, t4))
    k, n = loop_elliptic(m, m1)
    return stream_shape_closed(m, m1, k, n)


@njit(cache=True)
def coil_field_unit(rho, zeta, a):
    """The 12 numbers (h_ρ, h_z, ∂_ρh_ρ, ∂_ζh_ρ, ∂_ρh_z, ∂_ζh_z, ∂_ρρh_ρ, ∂_ρζh_ρ, ∂_ζζh_ρ, ∂_ρρh_z,
    ∂_ρζh_z, ∂_ζζh_z) of a unit-current loop of radius a at (ρ, ζ = z − h); NaN on the wire."""
    r = abs(rho)
    d2 = (r - a) * (r - a) + zeta * zeta
    if not d2 > (WIRE_TOLERANCE * a) ** 2:
        nan = math.nan
        return (nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan)
    s2 = (a + r) * (a + r) + zeta * zeta
    g0, g1, g2, g3 = stream_shape(4.0 * a * r / s2, d2 / s2)
    h = coil_field(r, zeta, a, g0, g1, g2, g3)
    if rho > 0.0:
        return h
    if rho == 0.0:  # the odd-in-ρ entries vanish; the closed form leaves ~1e-16 rounding residues there
        return (0.0, h[1], h[2], 0.0, 0.0, h[5], 0.0, h[7], 0.0, h[9], 0.0, h[11])
    return (-h[0], h[1], h[2], -h[3], -h[4], h[5], -h[6], h[7], -h[8], h[9], -h[10], h[11])


@njit(cache=True)
def coil_sum(rho, z, coils):
    """Σ_j s_j · coil_field_unit(ρ, z − h_j, a_j) over rows (a_j, h_j, s_j) of ``coils``: the 12 numbers."""
    t = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for j in range(coils.shape[0]):
        h = coil_field_unit(rho, z - coils[j, 1], coils[j, 0])
        s = coils[j, 2]
        t = (
            t[0] + s * h[0], t[1] + s * h[1], t[2] + s * h[2], t[3] + s * h[3],
            t[4] + s * h[4], t[5] + s * h[5], t[6] + s * h[6], t[7] + s * h[7],
            t[8] + s * h[8], t[9] + s * h[9], t[10] + s * h[10], t[11] + s * h[11],
        )  # fmt: skip
    return t


SQUARED = ("Q", "Q_r", "Q_z", "Q_rr", "Q_rz", "Q_zz")  # what _squared returns: H² and its (ρ, z) derivatives
_ROW_SOURCE = np.array([SQUARED.index(name) for name in FIELD_ROWS])  # field row k <- entry _ROW_SOURCE[k]


@njit(cache=True)
def _squared(rho, z, coils):
    """SQUARED for Q = H² = h_ρ² + h_z² at (ρ, z), coils a checked coil_table; chain rule:
    Q_ρ = 2(h_ρ ∂_ρh_ρ + h_z ∂_ρh_z), Q_ρz = 2(∂_ρh_ρ ∂_zh_ρ + h_ρ ∂_ρzh_ρ + ∂_ρh_z ∂_zh_z + h_z ∂_ρzh_z)."""
    f, g, f_r, f_z, g_r, g_z, f_rr, f_rz, f_zz, g_rr, g_rz, g_zz = coil_sum(rho, z, coils)
    return (
        f * f + g * g,
        2.0 * (f * f_r + g * g_r),
        2.0 * (f * f_z + g * g_z),
        2.0 * (f_r * f_r + f * f_rr + g_r * g_r + g * g_rr),
        2.0 * (f_r * f_z + f * f_rz + g_r * g_z + g * g_rz),
        2.0 * (f_z * f_z + f * f_zz + g_z * g_z + g * g_zz),
    )


@njit(cache=True)
def field_squared(rho, z, coils):
    """H² and its derivatives at (ρ, z) in the rows the kernels' field argument takes (generated FIELD_ROWS:
    Q, Q_ρ, Q_z, Q_ρρ, Q_ρz, Q_zz), bound by name to SQUARED; coils a checked coil_table."""
    q = _squared(rho, z, coils)
    out = np.empty(_ROW_SOURCE.shape[0])
    for k in range(_ROW_SOURCE.shape[0]):
        out[k] = q[_ROW_SOURCE[k]]
    return out


@njit(cache=True)
def field_squared_nodes(rho, z, coils, out):
    """field_squared at every node i of the arrays rho, z; row k (FIELD_ROWS) goes to out[k, i]."""
    for i in range(rho.shape[0]):
        q = _squared(rho[i], z[i], coils)
        for k in range(_ROW_SOURCE.shape[0]):
            out[k, i] = q[_ROW_SOURCE[k]]


@njit(cache=True)
def _components_nodes(rho, z, coils, out):
    """(h_ρ, h_z) at every node i into out[0:2, i]."""
    for i in range(rho.shape[0]):
        t = coil_sum(rho[i], z[i], coils)
        out[0, i] = t[0]
        out[1, i] = t[1]


def coil_table(coils) -> np.ndarray:
    """``coils`` as a contiguous float (n, 3) array of rows (radius > 0, height, signed current), all finite.

    The jitted functions assume a table checked here (a radius ≤ 0 gives garbage there, not an error)."""
    table = np.ascontiguousarray(coils, dtype=float)
    if table.ndim != 2 or table.shape[1] != 3:
        raise FieldError(f"coils: shape {table.shape}: must be (n, 3) rows of (radius, height, current)")
    bad = ~np.isfinite(table).all(axis=1) | ~(table[:, 0] > 0.0)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise FieldError(f"coil {j} = {tuple(table[j].tolist())}: radius must be > 0 and all entries finite")
    return table


def coaxial_table(coils) -> np.ndarray:
    """The coils (scene.Coil) as the coil_table rows (radius, height, current) of the axisymmetric solver; FieldError
    naming the first coil that is not coaxial (its field is not axisymmetric)."""
    for k, c in enumerate(coils):
        if not c.is_coaxial:
            raise FieldError(f"coil {k} is not coaxial (centre {list(c.centre)}, normal {list(c.normal)}): "
                             "non-axisymmetric fields are traced on the whole sphere, not yet available")
    return coil_table(np.array([[c.radius, c.height, c.current] for c in coils], dtype=float).reshape(-1, 3))


def _coil_distances(rho, z, table):
    """Broadcast (ρ, z) and the distances to each wire, shape (..., n)."""
    r, zz = np.broadcast_arrays(np.asarray(rho, dtype=float), np.asarray(z, dtype=float))
    return r, zz, np.hypot(np.abs(r)[..., None] - table[:, 0], zz[..., None] - table[:, 1])


def wire_distance(rho, z, coils):
    """Distance √((|ρ| − a_j)² + (z − h_j)²) from (ρ, z) to the nearest wire (arrays broadcast)."""
    return _coil_distances(rho, z, coil_table(coils))[2].min(axis=-1, initial=np.inf)


def field_components(rho, z, coils):
    """(h_ρ, h_z) at the points (ρ, z) (arrays broadcast); FieldError at a point on a wire."""
    table = coil_table(coils)
    r, zz, distance = _coil_distances(rho, z, table)
    on_wire = distance <= WIRE_TOLERANCE * table[:, 0]
    if on_wire.any():
        *point, j = np.argwhere(on_wire)[0].tolist()
        a, height, _ = table[j].tolist()
        raise FieldError(
            f"point (rho, z) = ({float(r[tuple(point)])!r}, {float(zz[tuple(point)])!r}) lies on the wire of "
            f"coil {j} (radius {a!r}, height {height!r}), where the field is singular: keep the shape away from "
            "the coils"
        )
    out = np.empty((2, r.size))
    _components_nodes(np.ascontiguousarray(r.ravel()), np.ascontiguousarray(zz.ravel()), table, out)
    return out[0].reshape(r.shape), out[1].reshape(r.shape)
