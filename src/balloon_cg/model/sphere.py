"""The exact M = 0 solution (MODEL.md §4): a sphere of radius λ under pressure

    P(λ) = 2 Σ_i μ_i (λ^(α_i − 3) − λ^(−2α_i − 3)),

i.e. λ2 ≡ λ, η = λ cos θ (Legendre coefficients a_0 = λ, b_1 = λ), membrane stress σ = Σ μ_i (λ^α_i − λ^(−2α_i)).
For any other strain energy P = 2 Φ_1(λ, λ)/λ² and σ = λ Φ_1(λ, λ) (Φ_1 from model/membrane.py).

The dielectric term −Φ̄² λ1² λ2² of Φ adds −2Φ̄² λ³ to Φ_1 on the sphere, so P(λ; Φ̄) = P(λ; 0) − 4 Φ̄² λ, and at a
fixed pressure the sphere of radius λ is held by the voltage Φ̄ = sqrt((P(λ; 0) − P)/(4λ)) where that is real.
"""
import numpy as np

from .membrane import stretch_derivatives
from ..scene.energies import StrainEnergy


def sphere_pressure(material, stretch, voltage: float = 0.0):
    """P(λ; Φ̄) of the sphere of radius ``stretch`` (module docstring)."""
    electric = 4 * voltage**2 * np.asarray(stretch, dtype=float)
    if isinstance(material, StrainEnergy):
        return _scalar_or_array(2 * _phi1(material, stretch) / np.asarray(stretch, dtype=float) ** 2 - electric,
                                stretch)
    mu = np.asarray(material.mu)[:, None]
    alpha = np.asarray(material.alpha)[:, None]
    lam = np.atleast_1d(np.asarray(stretch, dtype=float))[None, :]
    value = 2.0 * np.sum(mu * (lam ** (alpha - 3) - lam ** (-2 * alpha - 3)), axis=0) - np.atleast_1d(electric)
    return value if np.ndim(stretch) else float(value[0])


def sphere_voltage(material, stretch: float, pressure: float) -> float:
    """Φ̄ ≥ 0 holding the sphere of radius ``stretch`` at ``pressure``; ValueError where none does (P(λ; 0) < P)."""
    excess = sphere_pressure(material, stretch) - pressure
    if excess < 0:
        raise ValueError(f"the sphere of stretch {stretch:g} holds P = {excess + pressure:.6g} without a voltage, "
                         f"less than P = {pressure:g}, and a voltage only lowers it")
    return float(np.sqrt(excess / (4 * stretch)))


def sphere_stress(material, stretch):
    """Equal principal Cauchy membrane stresses of the inflated sphere (elastic part, MODEL.md §6)."""
    if isinstance(material, StrainEnergy):
        return _scalar_or_array(np.asarray(stretch, dtype=float) * _phi1(material, stretch), stretch)
    mu = np.asarray(material.mu)[:, None]
    alpha = np.asarray(material.alpha)[:, None]
    lam = np.atleast_1d(np.asarray(stretch, dtype=float))[None, :]
    value = np.sum(mu * (lam**alpha - lam ** (-2 * alpha)), axis=0)
    return value if np.ndim(stretch) else float(value[0])


def _phi1(material, stretch):
    return stretch_derivatives(material, stretch, stretch)["phi_1"]


def _scalar_or_array(value, stretch):
    return value if np.ndim(stretch) else float(value)
