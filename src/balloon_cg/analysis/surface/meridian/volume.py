"""The volume a tube encloses between its end planes, per 2π, as a density on the reference surface (MODEL.md §10):

    V/(2π) = (1/2π) ∫∫ v dS dφ,   v = ½ x_h · (a_S × a_φ),   x_h = (r, t, 0) the horizontal part of x,

the flux of the field x_h/2 (divergence 1) through the lateral surface: the end planes z = const add nothing
(x_h ⊥ e_z), so it is exact while the ends stay in their planes (tube/surface/basis.py). On an axisymmetric state
v = −½ ρ² η' (galerkin/equilibrium.enclosed_volume's density); tube/azimuthal.py's second variation uses the same form.
In the frame components of basis.NODE_VARIABLES (q_0, q_1 = r, t; q_3..5 = a_S; q_6..8 = a_φ) v is the trilinear

    v = ½ (q_0 q_4 q_8 − q_0 q_5 q_7 + q_1 q_5 q_6 − q_1 q_3 q_8),

whose node gradient and Hessian are exact.
"""
import numpy as np

TERMS = ((1.0, 0, 4, 8), (-1.0, 0, 5, 7), (1.0, 1, 5, 6), (-1.0, 1, 3, 8))  # (sign, i, j, k) of ½ s q_i q_j q_k


def density(state: np.ndarray) -> np.ndarray:
    """v at every node of ``state`` (9, nodes)."""
    return 0.5 * sum(s * state[i] * state[j] * state[k] for s, i, j, k in TERMS)


def gradient(state: np.ndarray) -> np.ndarray:
    """(9, nodes): ∂v/∂q."""
    out = np.zeros_like(state)
    for s, i, j, k in TERMS:
        out[i] += 0.5 * s * state[j] * state[k]
        out[j] += 0.5 * s * state[i] * state[k]
        out[k] += 0.5 * s * state[i] * state[j]
    return out


def hessian(state: np.ndarray) -> np.ndarray:
    """(9, 9, nodes): ∂²v/∂q²."""
    out = np.zeros((9, 9, state.shape[1]))
    for s, i, j, k in TERMS:
        for a, b, c in ((i, j, k), (i, k, j), (j, k, i)):
            out[a, b] += 0.5 * s * state[c]
            out[b, a] += 0.5 * s * state[c]
    return out
