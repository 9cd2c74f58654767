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
from ..galerkin.interval_elements import ElementInterval
from ..numerics.band_ldlt import ArrowLDLT
from ..numerics.banded import BandedInertia
from ..numerics.eigen import DenseLDLT, GramFactor, negative_count, restricted
from ..scene.loading import Control

COMPRESSED = -1e-8  # a smallest principal stress below this (units of μ/2: the stresses are O(1)) is compression


def unstable_counts(eq: Equilibrium, points, params: Parameters) -> dict:
    """{Control: the number of negative eigenvalues of the second variation at each Y = (u, P) of ``points``
    (``params``: the branch's, P replaced): ∂R/∂u (pressure), on δV = 0 (volume), H + (P/Ṽ) g gᵀ (gas)} (module
    docstring), all three from one LDLᵀ of H (numerics/banded.BandedInertia: on g⊥ one fewer where gᵀH⁻¹g < 0,
    with the rank-one term one fewer where 1 + (P/Ṽ) gᵀH⁻¹g < 0; Haynsworth's inertia additivity): on spectral
    elements H's arrow (``arrow_factor``), else Bunch–Kaufman's. Where that one does not decide (the arrow's banded
    block refused, H singular, g = 0, P < 0 or 1 + (P/Ṽ) gᵀH⁻¹g = 0) by the dense H's, restricted and updated
    matrices' own factorisations."""
    counts = {control: [] for control in Control}
    free = eq.disc.free
    unit = GramFactor(np.ones(free.size), orthogonal=True)
    arrow = eq.disc.arrow_order(free) if isinstance(eq.disc, ElementInterval) else None
    for Y in points:
        at = params.with_value("P", Y[-1])
        gradient = -eq.parameter_derivative(Y[:-1], at, "P")[free]
        weight = Y[-1] / eq.volume(Y[:-1])
        values = _counts_by_one_factor(eq, Y[:-1], at, arrow, gradient, weight)
        if values is None:
            H = eq.jacobian(Y[:-1], at)[np.ix_(free, free)]
            values = (negative_count(H), negative_count(restricted(H, unit, gradient[None, :])),
                      negative_count(H + weight * np.outer(gradient, gradient)))
        for control, value in zip((Control.PRESSURE, Control.VOLUME, Control.GAS), values):
            counts[control].append(value)
    return {control: np.array(values, dtype=int) for control, values in counts.items()}


def _counts_by_one_factor(eq: Equilibrium, u: np.ndarray, at: Parameters, arrow: tuple | None, gradient: np.ndarray,
                          weight: float) -> tuple | None:
    """(pressure, volume, gas) counts from one LDLᵀ of H on the free unknowns (``unstable_counts``): ``arrow`` (an
    ElementInterval's ``arrow_order``) or None (dense); None where it does not decide them."""
    free = eq.disc.free
    norm = float(np.linalg.norm(gradient))
    if norm == 0.0 or weight < 0.0:
        return None
    if arrow is None:
        factor = DenseLDLT(eq.jacobian(u, at)[np.ix_(free, free)])
        factor = None if factor.singular else factor
    else:
        order, _, _ = arrow
        factor, gradient = arrow_factor(eq.sparse_jacobian(u, at), free, arrow), gradient[order]
    if factor is None:
        return None
    inertia = BandedInertia(factor)
    volume = inertia.of(gradient[None, :] / norm, None)[0]
    gas = inertia.of(np.zeros((0, gradient.size)), (gradient, weight))[0]
    return None if gas is None else (factor.negatives, volume, gas)


def arrow_factor(hessian, free: np.ndarray, arrow: tuple) -> ArrowLDLT | None:
    """The ArrowLDLT of the sparse Hessian ``hessian`` on the unknowns ``free`` laid out by ``arrow`` = (order,
    local, bandwidth) (ElementInterval.arrow_order: the banded block first, the global columns last); None where it
    is refused."""
    order, local, width = arrow
    chosen = free[order]
    H = hessian.tocsr()[chosen][:, chosen].tocoo()
    inside = (H.row < local) & (H.col < local) & (H.row >= H.col)
    if np.any(H.row[inside] - H.col[inside] > width):
        raise ValueError(f"the Hessian's banded block passes its half-bandwidth {width}")
    band = np.zeros((width + 1, local))
    np.add.at(band, (H.row[inside] - H.col[inside], H.col[inside]), H.data[inside])
    border = H.tocsc()[:, local:].toarray()
    return ArrowLDLT.factor(band, border[:local], border[local:])


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

    def on(self, eq: Equilibrium) -> "CompressionStop":
        """The same rule on another discretisation's problem ``eq`` (a trace continued on a finer layout: tube/bulge.
        py), whether a taut state was met kept."""
        moved = CompressionStop(eq, self.active)
        moved.taut = self.taut
        return moved
