"""Stability of a tube's states for non-axisymmetric perturbations, azimuthal number m ≥ 1 (the m ≥ 1 blocks).

The perturbed tube is x0 + ε δx, δx = R(S) cos mφ e_ρ + T(S) sin mφ e_φ + Z(S) cos mφ e_z (the displacement
amplitudes of codegen/second_variation.py; ' = d/dS). The tube's generated kernel ``azimuthal_hessian`` gives at each
node the 6×6 h with d²E/dε² = ∫_0^L yᵀ h y dS, y = (R, R', Z, Z', T, T'), E per 2π (the pressure's work is the
volume between the end planes). In x = 2S/L − 1, on the interval discretisation's own Gauss rule (galerkin/interval.py):

    sliding ends   R, T = Σ_{k=0}^{N} c_k P_k(x),   Z = Σ_{k=0}^{N−2} c_k (P_{k+2} − P_k)(x)
    plugged ends   R, T, Z = Σ_{k=0}^{N−2} c_k (P_{k+2} − P_k)(x)

(on spectral elements, galerkin/interval_elements.py, R and T on λ2's functions and Z on η's: the discretisation's
``functions``).

The end conditions. A sliding end is a plane of mirror symmetry of the tube, fixed: the perturbation is mirrored
there (R, T even, Z odd about it), so Z = 0 on the end plane, R' = T' = 0 being natural (an end plane that would
tilt, Z = cos φ for m = 1, is not a mirror plane). A plug is rigid and held: it neither tilts nor moves sideways, so
the rim's displacement vanishes, R = T = Z = 0 (for m = 0 a plug of closed ends moves along the axis; no m ≥ 1
motion of a rigid plug keeps it a plug of the reference radius but its tilt and its sideways translation, and both
are held).

The eigenvalues are those of H c = μ G c, G the Gram matrix of ‖δx‖² = ½ ∫_0^L (R² + T² + Z²) dS (per 2π, as E):
the Rayleigh quotient of d²E/dε² over the displacement's L2 norm, basis independent. Zero modes: with sliding ends
and m = 1 the sideways translation of the whole tube (R = 1, T = −1, Z = 0) changes nothing where there is no
field; it is removed there (G c ⊥ it). In a coil's field it is not a zero mode and there are two readings, as the
sphere's (analysis/stability/azimuthal.py): the free tube keeps it (the field may pull the tube sideways, towards
the wire), the held tube (its centroid held: ∫ δx dA = 0, G c ⊥ the translation) removes it. Plugged ends hold it. Under volume control the m ≥ 1 blocks are the same: their perturbations leave the enclosed volume
unchanged to first order (∫ cos mφ dφ = 0), so δV = 0 removes nothing (only m = 0 differs, tube/stability.py).
"""
import functools
from dataclasses import dataclass

import numpy as np

from ..analysis.stability.azimuthal import lowest_eigenvalues
from ..galerkin.discretisation import symmetric_rows
from ..galerkin.equilibrium import Equilibrium, Parameters, in_field
from ..galerkin.interval import IntervalDiscretisation
from ..generated import AZIMUTHAL_PAIRS
from ..numerics import interrupt
from ..numerics.eigen import NO_CONSTRAINT, GramFactor, lowest_of, negative_count, restricted
from ..scene.tables import Ends

_ROW = symmetric_rows(AZIMUTHAL_PAIRS)  # (6, 6): the row of h_ab in the kernel's output
COUNT = 3  # the lowest eigenvalues kept per block and point


@dataclass(frozen=True)
class TubeModes:
    """The m = 1..m_max blocks at each point of a branch: ``lowest`` {m: (points, COUNT)} the lowest eigenvalues μ,
    ``unstable`` {m: (points,)} the number of negative ones (the same under pressure and volume control), of the
    free tube; ``held`` the m = 1 block of the held tube as {"lowest", "unstable"} where it differs from the free one
    (a coil's field on sliding ends: ``readings``), else None; ``crossings`` where an eigenvalue vanishes
    (tube/azimuthal_crossings.AzimuthalCrossing)."""

    lowest: dict
    unstable: dict
    crossings: tuple = ()
    held: dict | None = None


def basis_values(disc: IntervalDiscretisation, x: np.ndarray) -> np.ndarray:
    """(6, x.size, size): the values of y = (R, R', Z, Z', T, T') of each coefficient at the points x of [−1, 1], the
    unknowns ordered (R's, T's, Z's) (module docstring)."""
    length = disc.length
    free, free_slopes, bubbles, slopes = disc.functions(x)  # R and T on λ2's functions, Z on η's (zero at the ends)
    k, b = free.shape[1], bubbles.shape[1]
    ops = np.zeros((6, x.size, 2 * k + b))
    r, t, z = slice(0, k), slice(k, 2 * k), slice(2 * k, 2 * k + b)
    ops[0, :, r], ops[1, :, r] = free, 2 / length * free_slopes
    ops[4, :, t], ops[5, :, t] = free, 2 / length * free_slopes
    ops[2, :, z], ops[3, :, z] = bubbles, 2 / length * slopes
    return ops


@functools.lru_cache(maxsize=16)
def operators(disc: IntervalDiscretisation) -> tuple:
    """(ops, gram): ops (6, n_q, size) the node values of y = (R, R', Z, Z', T, T') per coefficient on the nodes of
    ``disc`` (``basis_values``); gram the (size, size) G."""
    ops = basis_values(disc, disc.x)
    values = ops[[0, 2, 4]]
    gram = 0.5 * np.einsum("aqi,q,aqj->ij", values, disc.weights, values)
    return ops, gram


def mode_profile(disc: IntervalDiscretisation, c: np.ndarray, S: np.ndarray) -> tuple:
    """(R, T, Z) of the perturbation with coefficients c at the reference arclengths S."""
    y = basis_values(disc, 2 * np.asarray(S, dtype=float) / disc.length - 1) @ c
    return y[0], y[4], y[2]


def translation(disc: IntervalDiscretisation) -> np.ndarray:
    """The coefficients of the m = 1 sideways translation R = 1, T = −1, Z = 0 (sliding ends: P_0 in R and T)."""
    k = disc.hoops
    c = np.zeros(2 * k + disc.degree - 1)
    c[0], c[k] = 1.0, -1.0
    return c


def node_hessian(eq: Equilibrium, u: np.ndarray, params: Parameters, m: int) -> np.ndarray:
    """The kernel's h (21 pairs, n_q) at the nodes of ``eq.disc`` for the state u."""
    disc = eq.disc
    nodes = eq.at_nodes("tube_azimuthal", (disc.cos_theta, disc.sin_theta))
    disc.node_state(u, out=nodes.state)
    nodes.hold(params)
    return nodes("azimuthal_hessian", params, m=float(m))


def hessian(eq: Equilibrium, u: np.ndarray, params: Parameters, m: int) -> np.ndarray:
    """H = Σ_q W_q yᵀ h y: d²E/dε² = cᵀ H c."""
    ops, _ = operators(eq.disc)
    h = node_hessian(eq, u, params, m)[_ROW] * eq.disc.weights  # (6, 6, n_q)
    flat = ops.reshape(-1, ops.shape[2])
    return flat.T @ np.einsum("abq,bqj->aqj", h, ops).reshape(-1, ops.shape[2])


def readings(eq: Equilibrium, params: Parameters, m: int) -> tuple:
    """The readings of the m-th block that differ (held: True, free: False): both for m = 1 on sliding ends in a
    field, else the free one alone (it is the held one: the translation is removed or held by the plugs)."""
    return (False, True) if m == 1 and eq.disc.ends == Ends.SLIDING and in_field(eq, params) else (False,)


def removed_modes(eq: Equilibrium, params: Parameters, m: int, held: bool = False) -> np.ndarray | None:
    """The coefficient rows of the removed modes (module docstring): the translation for m = 1 on sliding ends without
    a field, or in a field for the ``held`` tube; else None."""
    disc = eq.disc
    if m != 1 or disc.ends != Ends.SLIDING or (in_field(eq, params) and not held):
        return None
    return translation(disc)[None, :]


def zero_modes(eq: Equilibrium, params: Parameters, m: int, held: bool = False) -> np.ndarray:
    """The rows G c of the removed modes (``removed_modes``), NO_CONSTRAINT where there are none."""
    removed = removed_modes(eq, params, m, held)
    return NO_CONSTRAINT if removed is None else removed @ operators(eq.disc)[1]


def critical_mode(eq: Equilibrium, u: np.ndarray, params: Parameters, m: int, order: int,
                  held: bool = False) -> np.ndarray:
    """The eigenvector number ``order`` (ascending, from 0) of the m-th block of a reading at the state u, its
    removed modes excluded (analysis/stability/azimuthal.lowest_eigenvalues): at a located zero of that eigenvalue
    (tube/azimuthal_crossings.py) the mode the non-axisymmetric branch is born along. Coefficients on the basis of
    ``operators``, cᵀGc = 1, its largest entry positive (the sign is reproducible, not the eigensolver's)."""
    _, gram = operators(eq.disc)
    vectors = lowest_eigenvalues(hessian(eq, u, params, m), gram, order + 1, removed_modes(eq, params, m, held),
                                 vectors=True)[1]
    vector = vectors[:, order] / np.sqrt(vectors[:, order] @ gram @ vectors[:, order])
    return vector * np.sign(vector[np.argmax(np.abs(vector))])


def block(eq: Equilibrium, u: np.ndarray, params: Parameters, m: int, held: bool = False) -> np.ndarray:
    """The m-th block of a reading (held or free) as the standard symmetric matrix of the pencil (H, G) with the
    zero modes removed (numerics/eigen.restricted): its eigenvalues are the μ, its inertia the block's."""
    return blocks(eq, u, params, m, (held,))[held]


def blocks(eq: Equilibrium, u: np.ndarray, params: Parameters, m: int, which=(False,)) -> dict:
    """``block`` of each reading in ``which`` (held: True, free: False) from one assembly of H."""
    H = hessian(eq, u, params, m)
    return {held: restricted(H, _factor(eq.disc), zero_modes(eq, params, m, held)) for held in which}


@functools.lru_cache(maxsize=16)
def _factor(disc: IntervalDiscretisation) -> GramFactor:
    return GramFactor(operators(disc)[1])


def branch_modes(eq: Equilibrium, points, params: Parameters, m_max: int, count: int = COUNT) -> TubeModes:
    """``TubeModes`` of the points Y = (u, P) of a branch (``params``: the branch's, P replaced); a signal stops it
    at the next point (numerics/interrupt.Interrupted)."""
    found = {}  # (m, held): (lowest, unstable)
    for m in range(1, m_max + 1):
        which = readings(eq, params, m)
        values, negatives = {held: [] for held in which}, {held: [] for held in which}
        for Y in points:
            interrupt.check()
            for held, A in blocks(eq, Y[:-1], params.with_value("P", Y[-1]), m, which).items():
                negatives[held].append(negative_count(A))
                values[held].append(lowest_of(A, count))
        for held in which:
            found[m, held] = (np.array(values[held], dtype=float).reshape(len(points), count),
                              np.array(negatives[held], dtype=int))
    held = found.get((1, True))
    return TubeModes({m: found[m, False][0] for m in range(1, m_max + 1)},
                     {m: found[m, False][1] for m in range(1, m_max + 1)},
                     held=None if held is None else {"lowest": held[0], "unstable": held[1]})
