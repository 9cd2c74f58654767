"""The rigid translations of the balloon as oscillators: does the field restore it or pull it away?

For a rigid translation t of the whole membrane, Ω²_t = ½ tᵀKt / tᵀMt (the Rayleigh quotient of K q = ν M q,
frequencies.PER_EIGENVALUE) is the squared frequency at which the balloon would oscillate as a rigid body about the
point where it is held: along the axis t is δη = 1 (the coefficient b_0 of the m = 0 basis), across it the m = 1
translation R = 1, T = −1 (``azimuthal.special_modes``). The pressure and the membrane do not see a translation, so
Ω²_t is the field's stiffness alone: 0 without a field (an exact zero mode: a free balloon drifts), > 0 where the
field restores the balloon, < 0 where it pulls it away (a paramagnetic balloon at a field minimum slides toward a
coil; the free reading's instability, MODEL.md §5).
"""
from ..analysis.azimuthal import azimuthal_hessian, special_modes
from .pencil import PER_EIGENVALUE

DIRECTIONS = ("axial", "lateral")


def translation_omega2(variation, u, params) -> dict:
    """{"axial": Ω²_t along the axis, "lateral": Ω²_t across it} at the equilibrium u (module docstring);
    ``variation`` has the mass matrix as its Gram matrix (frequencies.mass_variation)."""
    H, _ = variation.matrices(u, params)
    t = variation.translation
    degree = variation.basis.degree
    across = special_modes(variation.eq, u, degree)["translation"]
    H1, M1 = azimuthal_hessian(variation.eq, u, params, 1, degree)
    return {"axial": PER_EIGENVALUE * H[t, t] / variation.gram[t, t],
            "lateral": PER_EIGENVALUE * (across @ H1 @ across) / (across @ M1 @ across)}
