"""The axisymmetric (m = 0) second variation on a banded basis: the sibling of ``axisymmetric.SecondVariation``'s
Legendre blocks on the C⁰ piecewise polynomials of galerkin/piecewise.py (elements of the wire-mapped coordinate).

The perturbations δλ2 = Σ a_i φ_i, δη = Σ b_i φ_i give the node state (δλ2, δv, δη, δw) with
δv = −(1 − x²) dδλ2/dx and δw = −sin θ dδη/dx (galerkin/discretisation.py), and the Hessian of E/2π

    H_ij = Σ_q W_q Σ_kl h_kl(q) ∂state_k/∂c_i ∂state_l/∂c_j,

h = the generated ``energy_hessian`` at the state, which is evaluated from the equilibrium's own (Legendre) series
at the elements' Gauss nodes; the Gram matrix G of the block's norm likewise (|δx|² = ∫(sin²θ δλ2² + δη²) dx, the
mass matrix, or ∫(δλ2² + δη²) dx: ``stability.norm``) and the volume gradient g = ∂Ṽ/∂c = −Σ_q W_q ∂²π̂/∂P∂state.
Each element's 2(p + 1) functions are consecutive, so H and G are banded (half-bandwidth 2p + 1) and assembled
element by element. The blocks and their constraints are ``SecondVariation``'s: an equator-symmetric state on the
half interval (``even``: δλ2 even, δη odd; ``odd``: the reverse, the odd field's vertex at the equator dropped),
the held reading ∫δη dx = 0 (a constraint row, the mapped Legendre blocks' hold), volume control gᵀc = 0, gas
control H + (P/Ṽ) g gᵀ. The lowest eigenvalues come from shift-invert Lanczos on one banded Cholesky factor per
index set below its pressure block's spectrum (numerics/banded.py), which also proves the signs.
"""
import numpy as np

from ...galerkin.discretisation import HESSIAN_ROW
from ...galerkin.equilibrium import NodeKernels, Parameters
from ...galerkin.piecewise import PiecewiseBasis
from ...generated import HESSIAN_PAIRS
from ...model.meridian import AZIMUTHAL, mass_density
from ...numerics.banded import BandedShiftInvert, BandedSigns
from .azimuthal import perturbation_map
from .flags import EVERY_FLAG, FREE, FREE_FLAGS, FREE_GAS, FREE_VOLUME, HELD, HELD_GAS, HELD_VOLUME, LOWEST

LAMBDA2, ETA = 0, 1  # the fields of a PiecewiseBasis's functions
# ``banded_variation``'s elements: order 12, 1.5 functions per field per Legendre degree. At the paper coil's
# pear_free_2 points of degree 320 on the map 30 elements of order 12 (1.1 per degree) agree with the Legendre
# blocks to within their own error estimates at points 35, 104 and 173 (benchmarks/banded_stability.py), but
# not at points 37–140, where Legendre-320 is not converged (estimates up to 3e-5) and the elements' values lay up
# to 1.6 times those estimates above it (Ritz values: above the converged ones); with 40 (1.5 per degree) every
# stored m = 1 eigenvalue of those 139 points is within the reference rule but one (point 36's second m1_free),
# 1.5e-9 below Legendre-320, whose dense values scatter by 2e-9 over degrees 213–560 (rounding) around the
# elements' −0.0446494742213, the same to 1.3e-12 on 40–120 elements of order 12 and 16 (docs/numerics.md §4)
ORDER, ELEMENT_FUNCTIONS = 12, 1.5


class BandedVariation:
    """The m = 0 blocks of the second variation at equilibria of ``equilibrium`` on a PiecewiseBasis of
    ``elements`` elements of ``order`` p (``quadrature`` Gauss nodes each; default p + 8) on the perturbation map
    of the scene's stability.basis (module docstring); ``symmetric`` False reads an equator-symmetric state's
    blocks on the whole interval (the blocks of a general state)."""

    def __init__(self, equilibrium, elements: int, order: int, quadrature: int = 0, symmetric: bool | None = None):
        self.eq = equilibrium
        self.symmetric = equilibrium.disc.symmetric if symmetric is None else symmetric and equilibrium.disc.symmetric
        self.basis = b = PiecewiseBasis(elements, order, quadrature or order + 8, perturbation_map(equilibrium),
                                        self.symmetric)
        x = b.x.ravel()
        sin_theta = np.sqrt(1.0 - x * x)
        unit = equilibrium.state_at(np.eye(equilibrium.disc.size), np.arccos(x))
        self.state_map = np.ascontiguousarray(np.concatenate([np.atleast_2d(v) for v in unit], axis=1))
        self._nodes = NodeKernels(equilibrium, (x, sin_theta))
        self.ops = _local_ops(b, sin_theta.reshape(b.x.shape))
        if equilibrium.scene.stability.norm == "displacement":
            norm = mass_density(equilibrium.scene.geometry, "axisymmetric", x, sin_theta)
        else:
            norm = np.zeros((len(HESSIAN_PAIRS), x.size))
            norm[[HESSIAN_ROW[0, 0], HESSIAN_ROW[2, 2]]] = 1.0
        self._gram_local = self._local_matrices(norm)
        hold = np.zeros((4, x.size))
        hold[2] = 1.0  # ∫δη dx
        self._hold_local = self._local_vectors(hold)
        self._layouts = {}

    def _local_matrices(self, pointwise: np.ndarray) -> np.ndarray:
        """Σ_q W_q Σ_kl h_kl(q) D_k D_l per element, (E, L, L), from pointwise entries (10, n_nodes) in
        HESSIAN_PAIRS' rows."""
        E, n_q = self.basis.x.shape
        h = pointwise[HESSIAN_ROW].reshape(4, 4, E, n_q) * self.basis.weights
        partner = np.einsum("kleq,elqj->ekqj", h, self.ops)
        L = self.ops.shape[-1]
        return np.matmul(self.ops.reshape(E, 4 * n_q, L).transpose(0, 2, 1), partner.reshape(E, 4 * n_q, L))

    def _local_vectors(self, pointwise: np.ndarray) -> np.ndarray:
        """Σ_q W_q Σ_k g_k(q) D_k per element, (E, L), from pointwise entries (4, n_nodes)."""
        E, n_q = self.basis.x.shape
        return np.einsum("keq,ekqj->ej", pointwise.reshape(4, E, n_q) * self.basis.weights, self.ops)

    def _layout(self, dropped: tuple) -> "BlockLayout":
        if dropped not in self._layouts:
            self._layouts[dropped] = BlockLayout(self.basis.dofs(dropped))
        return self._layouts[dropped]

    def _state(self, u, params: Parameters):
        np.dot(np.asarray(u, dtype=float), self.state_map, out=self._nodes.state.reshape(-1))
        self._nodes.hold(params)

    def local(self, u, params: Parameters) -> tuple:
        """(the elements' Hessians (E, L, L), their volume gradients (E, L)) at the state u."""
        self._state(u, params)
        hessian = self._local_matrices(self._nodes("energy_hessian", params))
        volume = -self._local_vectors(self._nodes("pressure_gradient", params))
        return hessian, volume

    def _plan(self, field_on: bool) -> list:
        """(name, dropped vertex fields, held, volume, gas, flags) per m = 0 block, as ``SecondVariation._plan``."""
        if self.symmetric:
            plan = [("even", (ETA,), False, False, False, (HELD, FREE)),
                    ("even_volume", (ETA,), False, True, False, (HELD_VOLUME, FREE_VOLUME)),
                    ("even_gas", (ETA,), False, False, True, (HELD_GAS, FREE_GAS)),
                    ("odd_held", (LAMBDA2,), True, False, False, EVERY_FLAG)]
            return plan + ([("odd_free", (LAMBDA2,), False, False, False, FREE_FLAGS)] if field_on else [])
        plan = [("all_held", (), True, False, False, (HELD,) if field_on else (HELD, FREE)),
                ("all_volume_held", (), True, True, False, (HELD_VOLUME,) if field_on else (HELD_VOLUME, FREE_VOLUME)),
                ("all_gas_held", (), True, False, True, (HELD_GAS,) if field_on else (HELD_GAS, FREE_GAS))]
        if field_on:
            plan += [("all_free", (), False, False, False, (FREE,)),
                     ("all_volume_free", (), False, True, False, (FREE_VOLUME,)),
                     ("all_gas_free", (), False, False, True, (FREE_GAS,))]
        return plan

    def _relatives(self, u, params: Parameters, pencil):
        """(name, the pencil's reader, its constraint rows or None, its gas update or None, flags) per m = 0 block at
        the state u, in ``_plan``'s order; ``pencil(H, G, name)`` makes the reader of one index set's pressure block
        (H, G in lower band storage), shared by the blocks of that set."""
        field_on = self.eq.coils.shape[0] > 0 and params.M > 0
        hessian, volume = self.local(u, params)
        weight = params.P / self.eq.volume(u)
        readers = {}
        for name, dropped, held, constrained, gas, flags in self._plan(field_on):
            layout = self._layout(dropped)
            if dropped not in readers:
                readers[dropped] = pencil(layout.band(hessian), layout.band(self._gram_local), name)
            g = layout.vector(volume)
            rows = ([layout.vector(self._hold_local)] if held else []) + ([g] if constrained else [])
            yield name, readers[dropped], np.array(rows) if rows else None, (g, weight) if gas else None, flags

    def lowest(self, u, params: Parameters):
        """(name, the LOWEST eigenvalues, the flags it enters) per m = 0 block at the state u (the order and flags of
        ``SecondVariation._plan``): per index set one banded factor below its pressure block's spectrum
        (``BandedShiftInvert.under``), every block of the set read through it."""
        for name, shifted, rows, update, flags in self._relatives(u, params, BandedShiftInvert.under):
            yield name, shifted.lowest(LOWEST, rows, update), flags

    def positive(self, u, params: Parameters):
        """(name, whether every eigenvalue is positive, the flags it enters) per m = 0 block at the state u, as
        ``lowest`` but from the inertia alone (``BandedSigns``: one banded Cholesky or LDLᵀ per index set)."""
        for name, signs, rows, update, flags in self._relatives(u, params, lambda H, G, _: BandedSigns(H, G)):
            yield name, signs.positive(rows, update), flags

    def lowest_blocks(self, u, params: Parameters) -> dict:
        """{name: the LOWEST eigenvalues} of every m = 0 block (``lowest``)."""
        return {name: values for name, values, _ in self.lowest(u, params)}


def banded_variation(equilibrium, degree: int, symmetric: bool) -> "BandedVariation | None":
    """The banded sibling of the Legendre blocks of perturbation degree N at ``equilibrium``: elements of order
    ORDER, as many as give about ELEMENT_FUNCTIONS·N functions per field on the whole interval (half as many on the
    half interval of an equator-symmetric state). None on a capsule (its piecewise discretisation; of length 0, the
    sphere's, without the m ≥ 1 mass kernel the sibling's blocks take: ``meridian.AZIMUTHAL``), whose m ≥ 1 blocks
    have their own elements (capsule_basis.py)."""
    if equilibrium.disc.joins or equilibrium.scene.geometry.shape not in AZIMUTHAL:
        return None
    half = symmetric and equilibrium.disc.symmetric
    elements = max(1, int(np.ceil(ELEMENT_FUNCTIONS * degree / ORDER / (2 if half else 1))))
    return BandedVariation(equilibrium, elements, ORDER, symmetric=half)


def _local_ops(basis: PiecewiseBasis, sin_theta: np.ndarray) -> np.ndarray:
    """∂(δλ2, δv, δη, δw)/∂c of each element's 2(p + 1) local functions (local 2r + field) at its nodes,
    shape (E, 4, n_q, 2(p + 1)): δv = −(1 − x²) dδλ2/dx, δw = −sin θ dδη/dx."""
    E, n_q = basis.x.shape
    ops = np.zeros((E, 4, n_q, 2 * (basis.order + 1)))
    ops[:, 0, :, 0::2] = basis.phi
    ops[:, 1, :, 0::2] = -(sin_theta ** 2)[:, :, None] * basis.dphi_dx
    ops[:, 2, :, 1::2] = basis.phi
    ops[:, 3, :, 1::2] = -sin_theta[:, :, None] * basis.dphi_dx
    return ops


class BlockLayout:
    """Scatter of element matrices and vectors into lower band storage (numerics/banded.py) and global vectors, for
    one numbering of the functions (``PiecewiseBasis.dofs``: −1 for a dropped one)."""

    def __init__(self, dofs: np.ndarray):
        self.size = int(dofs.max()) + 1
        i, j = dofs[:, :, None], dofs[:, None, :]
        lower = (i >= j) & (j >= 0)
        i, j = np.broadcast_to(i, lower.shape), np.broadcast_to(j, lower.shape)
        self.bandwidth = int((i - j)[lower].max())
        self._matrix = lower.ravel()
        self._positions = ((i - j) * self.size + j)[lower]
        kept = dofs >= 0
        self._vector, self._indices = kept.ravel(), dofs[kept]

    def band(self, local: np.ndarray) -> np.ndarray:
        """The assembled symmetric matrix in lower band storage, (bandwidth + 1, size), in Fortran order (LAPACK's:
        scipy's band routines copy any other array on every call)."""
        return np.asfortranarray(np.bincount(self._positions, weights=local.ravel()[self._matrix],
                                             minlength=(self.bandwidth + 1) * self.size).reshape(self.bandwidth + 1,
                                                                                                  self.size))

    def vector(self, local: np.ndarray) -> np.ndarray:
        return np.bincount(self._indices, weights=local.ravel()[self._vector], minlength=self.size)
