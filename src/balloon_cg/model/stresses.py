"""Elastic Cauchy membrane stresses of the Ogden membrane (MODEL.md §6) and the dielectric part (the taut test on
them: analysis/branches/primary.py)."""

from .membrane import stretch_derivatives
from ..scene.energies import StrainEnergy


def elastic_stresses(material, lam1, lam2):
    """Elastic Cauchy membrane stresses (σ_θ, σ_φ) = (λ1 ∂Φ/∂λ1, λ2 ∂Φ/∂λ2), λ3 = 1/(λ1λ2) eliminated:

    σ_θ = Σ μ_i (λ1^α_i − (λ1λ2)^(−α_i)),   σ_φ = Σ μ_i (λ2^α_i − (λ1λ2)^(−α_i))   (units of μ/2)
    for Ogden; for any other strain energy Φ_1, Φ_2 come from its kernels (model/membrane.py).
    """
    if isinstance(material, StrainEnergy):
        d = stretch_derivatives(material, lam1, lam2)
        return lam1 * d["phi_1"], lam2 * d["phi_2"]
    lam3 = 1.0 / (lam1 * lam2)
    terms = list(zip(material.mu, material.alpha))
    sigma_theta = sum(mu * (lam1**alpha - lam3**alpha) for mu, alpha in terms)
    sigma_phi = sum(mu * (lam2**alpha - lam3**alpha) for mu, alpha in terms)
    return sigma_theta, sigma_phi


def dielectric_stress(voltage: float, lam1, lam2):
    """The dielectric part of both principal stresses, λ_i ∂(−Φ̄² λ1² λ2²)/∂λ_i = −2 Φ̄² λ1² λ2² (units of μ/2):
    the Maxwell stress −ε E² of the true field E = (Φ/H) λ1 λ2 across the thickness."""
    return -2.0 * voltage**2 * (lam1 * lam2) ** 2

