"""The field of circular current loops anywhere (MODEL.md §9), and H² with its Cartesian derivatives.

A loop (centre c, unit normal n, radius a, signed current s) contributes, at x with r = x − c, z' = r·n,
ρ' = |r − z' n| and e = (r − z' n)/ρ', the coaxial closed form (field.coil_field_unit: f = h_ρ, g = h_z and their
(ρ', z') derivatives up to second order) in its own frame:

    h = f e + g n,
    ∂_b h_a = f_ρ e_a e_b + φ (P_ab − e_a e_b) + f_z e_a n_b + g_ρ n_a e_b + g_z n_a n_b,
    ∂_bc h_a = β (e_a P_bc + e_b P_ac + e_c P_ab) + (f_ρρ − 3β) e_a e_b e_c + γ (P_ab n_c + P_ac n_b)
               + (f_ρz − γ) e_a (e_b n_c + e_c n_b) + f_zz e_a n_b n_c
               + n_a [g_ρρ e_b e_c + g_ρz (e_b n_c + e_c n_b) + g_zz n_b n_c + δ (P_bc − e_b e_c)],

with P = I − n nᵀ, φ = f/ρ, β = (f_ρ − f/ρ)/ρ, γ = f_z/ρ, δ = g_ρ/ρ. The field is divergence- and curl-free,
f_ρ + f/ρ + g_z = 0 and f_z = g_ρ, and each component is harmonic, so φ = −(f_ρ + g_z), β = −(f_ρρ + g_ρz),
γ = −(f_ρz + g_zz), δ = −(g_ρρ + g_zz) without a division: these are used nearer the loop's axis than its wire
(ρ' < distance to the wire; exact on the axis, where e = 0), the quotients elsewhere (each form cancels where the
other does not). Loops add as vectors; Q = H² = |h|², Q_b = 2 h·∂_b h, Q_bc = 2 (∂_b h·∂_c h + h·∂_bc h).
Units as field.py: lengths in R0, field with I/(4π R0) removed. NaN within WIRE_TOLERANCE·a of a wire.
"""
import math

import numpy as np
from numba import njit

from .field import FieldError, coil_field_unit

CARTESIAN = ("Q", "Q_x", "Q_y", "Q_z", "Q_xx", "Q_xy", "Q_xz", "Q_yy", "Q_yz", "Q_zz")  # field_squared_cartesian rows
_PAIRS = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))  # (b, c) of the second-derivative rows, in CARTESIAN order
LOOP_COLUMNS = ("centre_x", "centre_y", "centre_z", "normal_x", "normal_y", "normal_z", "radius", "current")


def loop_table(coils) -> np.ndarray:
    """The coils (scene.Coil: centre, unit normal, radius, current) as the contiguous (n, 8) rows LOOP_COLUMNS the
    jitted functions take; FieldError unless every entry is finite, the radius > 0 and the normal of unit length."""
    table = np.array([[*c.centre, *c.normal, c.radius, c.current] for c in coils], dtype=float).reshape(-1, 8)
    bad = (~np.isfinite(table).all(axis=1) | ~(table[:, 6] > 0.0)
           | ~(np.abs(np.linalg.norm(table[:, 3:6], axis=1) - 1.0) <= 1e-12))
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise FieldError(f"coil {j} = {dict(zip(LOOP_COLUMNS, table[j].tolist()))}: the radius must be > 0, the "
                         "normal of unit length and all entries finite")
    return np.ascontiguousarray(table)


@njit(cache=True)
def _add_loop(x, y, z, loop, h, J, K):
    """Add one loop's h, ∂_b h_a (J[a, b]) and ∂_bc h_a (K[a, b, c], c ≥ b) at the point (x, y, z) (module
    docstring)."""
    n = (loop[3], loop[4], loop[5])
    a, s = loop[6], loop[7]
    r = (x - loop[0], y - loop[1], z - loop[2])
    axial = r[0] * n[0] + r[1] * n[1] + r[2] * n[2]
    e = (r[0] - axial * n[0], r[1] - axial * n[1], r[2] - axial * n[2])
    rho = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
    f, g, f_r, f_z, g_r, g_z, f_rr, f_rz, f_zz, g_rr, g_rz, g_zz = coil_field_unit(rho, axial, a)
    if rho > 0.0:
        e = (e[0] / rho, e[1] / rho, e[2] / rho)
    if 2.0 * a * rho < a * a + axial * axial:  # nearer the axis than the wire: the quotients from the field equations
        phi, beta, gamma, delta = -(f_r + g_z), -(f_rr + g_rz), -(f_rz + g_zz), -(g_rr + g_zz)
    else:
        phi = f / rho
        beta, gamma, delta = (f_r - phi) / rho, f_z / rho, g_r / rho
    for i in range(3):
        h[i] += s * (f * e[i] + g * n[i])
        for j in range(3):
            p_ij = (1.0 if i == j else 0.0) - n[i] * n[j]
            J[i, j] += s * (f_r * e[i] * e[j] + phi * (p_ij - e[i] * e[j]) + f_z * e[i] * n[j]
                            + g_r * n[i] * e[j] + g_z * n[i] * n[j])
            for k in range(j, 3):
                p_ik = (1.0 if i == k else 0.0) - n[i] * n[k]
                p_jk = (1.0 if j == k else 0.0) - n[j] * n[k]
                en = e[j] * n[k] + e[k] * n[j]
                K[i, j, k] += s * (
                    beta * (e[i] * p_jk + e[j] * p_ik + e[k] * p_ij) + (f_rr - 3.0 * beta) * e[i] * e[j] * e[k]
                    + gamma * (p_ij * n[k] + p_ik * n[j]) + (f_rz - gamma) * e[i] * en + f_zz * e[i] * n[j] * n[k]
                    + n[i] * (g_rr * e[j] * e[k] + g_rz * en + g_zz * n[j] * n[k] + delta * (p_jk - e[j] * e[k]))
                )


@njit(cache=True)
def _loops_at(points, i, loops, h, J, K):
    """h, J and K (K[a, b, c] for c ≥ b) of the sum over ``loops`` at the point in column i of ``points``."""
    h[:] = 0.0
    J[:] = 0.0
    K[:] = 0.0
    for j in range(loops.shape[0]):
        _add_loop(points[0, i], points[1, i], points[2, i], loops[j], h, J, K)


@njit(cache=True)
def loop_field(points, loops, out):
    """h = Σ_j s_j h_j at every point (columns of ``points``: x, y, z) into out[0:3, i]; loops a loop_table."""
    h, J, K = np.empty(3), np.empty((3, 3)), np.empty((3, 3, 3))
    for i in range(points.shape[1]):
        _loops_at(points, i, loops, h, J, K)
        out[:, i] = h


@njit(cache=True)
def field_squared_cartesian(points, loops, out):
    """H² and its Cartesian derivatives (rows CARTESIAN) at every point (columns of ``points``: x, y, z), loops a
    loop_table: Q = h·h, Q_b = 2 h_a ∂_b h_a, Q_bc = 2 (∂_b h_a ∂_c h_a + h_a ∂_bc h_a)."""
    h, J, K = np.empty(3), np.empty((3, 3)), np.empty((3, 3, 3))
    for i in range(points.shape[1]):
        _loops_at(points, i, loops, h, J, K)
        out[0, i] = h[0] * h[0] + h[1] * h[1] + h[2] * h[2]
        for b in range(3):
            out[1 + b, i] = 2.0 * (h[0] * J[0, b] + h[1] * J[1, b] + h[2] * J[2, b])
        for row in range(6):
            b, c = _PAIRS[row]
            total = 0.0
            for a in range(3):
                total += J[a, b] * J[a, c] + h[a] * K[a, b, c]
            out[4 + row, i] = 2.0 * total


def loop_distance(points: np.ndarray, loops: np.ndarray) -> np.ndarray:
    """The distance from each point (columns x, y, z) to the nearest wire, √((ρ' − a)² + z'²) in each loop's frame
    (module docstring); inf without loops."""
    out = np.full(points.shape[1], np.inf)
    for loop in loops:
        r = points - loop[:3, None]
        axial = loop[3:6] @ r
        rho = np.linalg.norm(r - axial * loop[3:6, None], axis=0)
        out = np.minimum(out, np.hypot(rho - loop[6], axial))
    return out
