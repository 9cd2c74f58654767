"""The rigid translations of the balloon as oscillators: does the field restore it or pull it away?

For a rigid translation t of the whole membrane, Ω²_t = ½ tᵀKt / tᵀMt (the Rayleigh quotient of K q = ν M q,
``pencil``) is the squared frequency at which the balloon would oscillate as a rigid body about the point where it
is held: along the axis t is δη = 1 (the coefficient b_0 of the m = 0 basis: the state (λ2, v, η, w) moves by
(0, 0, 1, 0)), across it the m = 1 translation R = 1, T = −1 (y = (R, R', Z, Z', T, T') = (1, 0, 0, 0, −1, 0)).
Both are exact in every basis, so tᵀKt = ∫ tᵀ h t d(cos θ) and tᵀMt = ∫ tᵀ m t d(cos θ) from the node kernels
(``energy_hessian``, ``azimuthal_hessian`` at m = 1, the mass densities of generated/inertia.py) on the m = 1
basis's nodes, no assembly. The pressure and the membrane do not see a translation, so Ω²_t is the field's
stiffness alone: 0 without a field (an exact zero mode: a free balloon drifts), > 0 where the field restores the
balloon, < 0 where it pulls it away (a paramagnetic balloon at a field minimum slides toward a coil; the free
reading's instability, MODEL.md §5).
"""
import numpy as np

from ..analysis.stability.azimuthal import azimuthal_hessian, kernel_state_map, perturbation_basis, state_maps
from ..galerkin.discretisation import symmetric_rows
from ..generated import AZIMUTHAL_PAIRS, HESSIAN_PAIRS
from ..model.meridian import AZIMUTHAL, mass_density
from .pencil import PER_EIGENVALUE

# direction: (the node values of its translation, the stiffness kernel and its layout, the mass kernel)
DIRECTIONS = {
    "axial": (np.array([0.0, 0.0, 1.0, 0.0]), "energy_hessian", HESSIAN_PAIRS, "axisymmetric"),
    "lateral": (np.array([1.0, 0.0, 0.0, 0.0, -1.0, 0.0]), "azimuthal_hessian", AZIMUTHAL_PAIRS, "azimuthal"),
}


def _form(pointwise, pairs, t) -> np.ndarray:
    """tᵀ h t at every node from a kernel's upper-triangle rows (``pairs``)."""
    rows = symmetric_rows(pairs)
    return sum(t[k] * t[l] * pointwise[rows[k, l]] for k in range(t.size) for l in range(t.size) if t[k] and t[l])


def translation_omega2(variation, u, params) -> dict:
    """{"axial": Ω²_t along the axis, "lateral": Ω²_t across it} at the equilibrium u of ``variation`` (the pencil's
    m = 0 second variation, dynamics.pencil.mass_variation; module docstring), on the nodes of its equilibrium's
    m = 1 basis of its degree. On a shape without the m = 1 mass kernel (a capsule: model/meridian.AZIMUTHAL)
    the axial one is the Rayleigh quotient of b_0 (δη = 1) on the m = 0 pencil (its quadrature split at the
    capsule's joins), and the lateral one ``lateral_omega2``'s on its m = 1 basis."""
    equilibrium = variation.eq
    geometry = equilibrium.scene.geometry
    if geometry.shape not in AZIMUTHAL:
        t = variation.translation
        return {"axial": PER_EIGENVALUE * variation.matrices(u, params)[0][t, t] / variation.gram[t, t],
                "lateral": lateral_omega2(equilibrium, u, params, variation.basis.degree)}
    b = perturbation_basis(equilibrium, 1, variation.basis.degree)
    nodes = equilibrium.at_nodes(("translation", b), (b.x, b.sin_theta))
    np.dot(np.asarray(u, dtype=float), kernel_state_map(equilibrium.disc, b, False), out=nodes.state.reshape(-1))
    nodes.hold(params)
    out = {}
    for direction, (t, stiffness, pairs, mass) in DIRECTIONS.items():
        h = nodes(stiffness, params, m=1.0) if stiffness == "azimuthal_hessian" else nodes(stiffness, params)
        out[direction] = PER_EIGENVALUE * (b.weights @ _form(h, pairs, t)) / (
            b.weights @ _form(mass_density(geometry, mass, b.x, b.sin_theta), pairs, t))
    return out


def lateral_omega2(equilibrium, u, params, degree: int) -> float:
    """Ω²_t of the translation across the axis as the Rayleigh quotient ½ cᵀHc / cᵀGc of its coefficients c on the
    m = 1 basis of ``degree`` (azimuthal.azimuthal_hessian; H its m = 1 block, G its Gram matrix, the mass
    matrix): c = G⁻¹ (G c), G c the translation's L2 moments (azimuthal.state_maps), exact where the basis holds
    R = 1, T = −1, Z = 0 (a capsule's: D = 2 is a constant on every element)."""
    H, G = azimuthal_hessian(equilibrium, u, params, 1, degree)
    c = np.linalg.solve(G, state_maps(equilibrium.disc, perturbation_basis(equilibrium, 1, degree)).translation)
    return PER_EIGENVALUE * (c @ H @ c) / (c @ G @ c)
