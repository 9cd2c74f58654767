"""Stability of a tube's states (m = 0): the spectra of the mirror blocks of ∂R/∂u and the number of unstable directions
under pressure control (all of u's unknowns: a held λ̄ is not one), under volume control (on δV = ∇V·δu = 0, ∇V =
−∂R/∂P) and under gas control (P V = n fixed: the energy E − n ln V, whose Hessian at fixed n is ∂²E + (n/V²) ∇V∇Vᵀ, per
2π with Ṽ = V/2π: H + (P/Ṽ) g gᵀ, g = ∇Ṽ = −∂R/∂P, a positive rank-one update: stable under pressure ⇒ under gas ⇒ under
volume control, as on the sphere, analysis/stability/axisymmetric.py), by the inertia of a Bunch–Kaufman factorisation
(numerics/eigen.py: ``restricted`` removes the constraint); and where the membrane is compressed (``smallest_stress``):
a membrane wrinkles where a principal stress is negative, its Ritz problem is not elliptic there and the states and
eigenvalues computed there do not converge in the degree (docs/tubes.md: the plugged tube's necks); in a coil field a
trace stops where its states turn compressed (``CompressionStop``: there they measurably do not converge,
docs/tubes.md)."""
import numpy as np

from .results import IntervalStop
from ..galerkin.equilibrium import Equilibrium, Parameters
from ..model import meridian
from ..model.stresses import dielectric_stress, elastic_stresses
from ..numerics.continuation import Stop
from ..numerics.banded import BandedInertia
from ..numerics.eigen import DenseLDLT, GramFactor, negative_count, restricted
from ..scene.loading import Control

COMPRESSED = -1e-8  # a smallest principal stress below this (units of μ/2: the stresses are O(1)) is compression


def unstable_counts(eq: Equilibrium, points, params: Parameters) -> dict:
    """{Control: the number of negative eigenvalues of the second variation at each Y = (u, P) of ``points``
    (``params``: the branch's, P replaced): ∂R/∂u (pressure), on δV = 0 (volume), H + (P/Ṽ) g gᵀ (gas)} (module
    docstring), all three from one LDLᵀ of H (numerics/banded.BandedInertia: on g⊥ one fewer where gᵀH⁻¹g < 0,
    with the rank-one term one fewer where 1 + (P/Ṽ) gᵀH⁻¹g < 0; Haynsworth's inertia additivity); where H is
    singular (a zero pivot), g = 0, P < 0 or 1 + (P/Ṽ) gᵀH⁻¹g = 0, by the restricted and updated matrices' own
    factorisations."""
    counts = {control: [] for control in Control}
    free = eq.disc.free
    unit = GramFactor(np.ones(free.size), orthogonal=True)
    for Y in points:
        at = params.with_value("P", Y[-1])
        H = eq.jacobian(Y[:-1], at)[np.ix_(free, free)]
        gradient = -eq.parameter_derivative(Y[:-1], at, "P")[free]
        weight = Y[-1] / eq.volume(Y[:-1])
        counts_of = _counts_by_one_factor(H, gradient, weight)
        values = counts_of or (negative_count(H), negative_count(restricted(H, unit, gradient[None, :])),
                               negative_count(H + weight * np.outer(gradient, gradient)))
        for control, value in zip((Control.PRESSURE, Control.VOLUME, Control.GAS), values):
            counts[control].append(value)
    return {control: np.array(values, dtype=int) for control, values in counts.items()}


def _counts_by_one_factor(H: np.ndarray, gradient: np.ndarray, weight: float) -> tuple | None:
    """(pressure, volume, gas) counts from the LDLᵀ of H (``unstable_counts``), None where it does not decide them."""
    factor = DenseLDLT(H)
    norm = float(np.linalg.norm(gradient))
    if factor.singular or norm == 0.0 or weight < 0.0:
        return None
    inertia = BandedInertia(factor)
    volume = inertia.of(gradient[None, :] / norm, None)[0]
    gas = inertia.of(np.zeros((0, H.shape[0])), (gradient, weight))[0]
    return None if gas is None else (factor.negatives, volume, gas)


def spectrum(eq: Equilibrium, Y: np.ndarray, index: np.ndarray, params: Parameters) -> np.ndarray:
    """The eigenvalues (ascending) of the Hessian ∂R/∂u at Y = (u, P) restricted to the unknowns ``index``
    (``params``: the branch's, P replaced)."""
    H = eq.jacobian(Y[:-1], params.with_value("P", Y[-1]))
    return np.linalg.eigvalsh(H[np.ix_(index, index)])


def smallest_stress(eq: Equilibrium, u: np.ndarray, voltage: float | None = None) -> float:
    """The smallest principal stress over the quadrature nodes of the state u: the elastic λ1Φ_1, λ2Φ_2 plus, under a
    voltage (``voltage``; None: the scene's), the dielectric −2Φ̄²λ1²λ2² (model/stresses.py); below COMPRESSED the
    membrane is compressed somewhere (module docstring)."""
    disc, scene = eq.disc, eq.scene
    lam2, v, _, w = disc.node_state(u)
    lam1 = meridian.meridional_stretch(scene.geometry, disc.cos_theta, disc.sin_theta, lam2, v, w)
    dielectric = dielectric_stress(scene.voltage if voltage is None else voltage, lam1, lam2)
    return float(min(np.min(stress + dielectric) for stress in elastic_stresses(scene.material, lam1, lam2)))


class CompressionStop:
    """The stop rule of a trace in a coil field: called with each point's state u, it returns
    Stop(IntervalStop.COMPRESSED) at the first compressed one (``smallest_stress`` below COMPRESSED) after a taut one
    (the start at P = 0 in a field may be compressed: the coil pulls the middle out), else None; ``active`` False:
    never (no field)."""

    def __init__(self, eq: Equilibrium, active: bool):
        self.eq, self.active, self.taut = eq, active, False

    def __call__(self, u: np.ndarray) -> Stop | None:
        if not self.active:
            return None
        stress = smallest_stress(self.eq, u)
        if stress >= COMPRESSED:
            self.taut = True
            return None
        if self.taut:
            return Stop(IntervalStop.COMPRESSED, f"the membrane turned compressed in the field (smallest principal "
                                                 f"stress {stress:.3g}): beyond, a membrane wrinkles and the traced "
                                                 "states do not converge in the degree")
        return None
