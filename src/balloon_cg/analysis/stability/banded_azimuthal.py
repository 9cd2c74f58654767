"""The azimuthal (m ≥ 1) second variation on the banded basis: the sibling of azimuthal.py's associated Legendre
blocks on the C⁰ elements of galerkin/piecewise.py, at the nodes of an m = 0 ``BandedVariation``.

The regular perturbations (azimuthal.py) are Z ∈ sin^m θ · C^∞, U = R + T ∈ sin^{m+1} θ · C^∞ and
D = R − T ∈ sin^{m−1} θ · C^∞. On the map s = h(x) = cos σ, (1 − s²)/(1 − x²) is smooth and positive, so the
functions of order j are

    f = sin^j σ · φ(s),     df/dθ = −h'(x) sin θ (sin^j σ φ'(s) − j s sin^{j−2} σ φ(s)),

φ the elements' C⁰ piecewise polynomials in s (the mapped Legendre basis has P̄_k^j(s) = sin^j σ · polynomial):
Z of order m, U of m + 1, D of m − 1, R = (U + D)/2, T = (U − D)/2, three fields interleaved per element function
(half-bandwidth 3p + 2). The kernel ``azimuthal_hessian`` gives the 6×6 h of y = (R, R', Z, Z', T, T') at each
node, the Gram matrix is the mass matrix of ‖δx‖² (generated/inertia.py), both assembled element by element. On
an equator-symmetric state the block splits into its reflection classes (``AzimuthalBasis.classes``): class 0
(R, T even in x, Z odd) and class 1 (the reverse); on the half interval a field odd in x has its vertex at s = 0
dropped (sin^j σ is even). The special modes (translation, rotation, relabelling: azimuthal.special_modes) are
removed by their constraint rows G c = ½ ∫ (R δR + T δT + Z δZ) S' dx, as ``azimuthal.restricted_blocks`` does,
per reading (held, free: ``azimuthal.excluded_modes``).
"""
import numpy as np

from ...galerkin.discretisation import symmetric_rows
from ...generated import AZIMUTHAL_PAIRS
from ...model.meridian import hoop, mass_density, metric
from ...numerics.banded import BandedShiftInvert, BandedSigns
from .azimuthal import MODE_CLASS, merged_parts, excluded_modes
from .banded import BandedVariation, BlockLayout

Z_FIELD, U_FIELD, D_FIELD = range(3)  # the fields of the interleaved functions (local 3r + field)
FIELDS = 3


class BandedAzimuthal:
    """The m-th block of the second variation at the nodes of the m = 0 ``variation`` (module docstring)."""

    def __init__(self, variation: BandedVariation, m: int):
        if m < 1:
            raise ValueError(f"m = {m}: the azimuthal blocks need m ≥ 1")
        self.variation, self.m = variation, m
        b, eq = variation.basis, variation.eq
        x = b.x
        sin_theta = np.sqrt(1.0 - x * x)
        self.ops = _azimuthal_ops(b, m, x, sin_theta)
        self._rows = symmetric_rows(eq.kernels.module.AZIMUTHAL_PAIRS)
        mass = mass_density(eq.scene.geometry, "azimuthal", x.ravel(), sin_theta.ravel())
        self._gram_local = self._local_matrices(mass, symmetric_rows(AZIMUTHAL_PAIRS))
        # the L2 moments' node weights: ½ w_q S'_q for (R, T, Z)
        self._moment_weights = 0.5 * b.weights * metric(eq.scene.geometry, x, sin_theta)
        self._sin_theta = sin_theta
        self._layouts = {}

    def _local_matrices(self, pointwise: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Σ_q W_q Σ_kl h_kl(q) D_k D_l per element, (E, L, L), h in the rows ``rows[k, l]`` of ``pointwise``."""
        E, n_q = self.variation.basis.x.shape
        h = pointwise[rows].reshape(6, 6, E, n_q) * self.variation.basis.weights
        partner = np.einsum("kleq,elqj->ekqj", h, self.ops)
        L = self.ops.shape[-1]
        return np.matmul(self.ops.reshape(E, 6 * n_q, L).transpose(0, 2, 1), partner.reshape(E, 6 * n_q, L))

    def _parts(self) -> list:
        """(reflection class or None, the fields whose vertex at s = 0 is dropped) of each uncoupled part."""
        if not self.variation.symmetric:
            return [(None, ())]
        odd_class_0 = (Z_FIELD,)  # class 0: R, T (U, D) even in x, Z odd
        return [(0, odd_class_0), (1, (U_FIELD, D_FIELD))]

    def _layout(self, dropped: tuple) -> BlockLayout:
        if dropped not in self._layouts:
            self._layouts[dropped] = BlockLayout(self.variation.basis.dofs(dropped, FIELDS))
        return self._layouts[dropped]

    def _mode_moments(self, params) -> np.ndarray:
        """G c of the special modes (azimuthal.MODES order) per element, (3, E, L), from the held node state."""
        lam2, v, eta, deta = self.variation._nodes.state.reshape(4, *self.variation.basis.x.shape)
        x, s = self.variation.basis.x, self._sin_theta
        dlam2 = v / s  # v = λ2' sin θ
        one, zero = np.ones_like(x), np.zeros_like(x)
        radius = hoop(self.variation.eq.scene.geometry, x, s)  # R: sin θ on a sphere
        fields = ((one, -one, zero), (eta, -eta, -lam2 * radius), (lam2 * x + dlam2 * s, -lam2 * x, deta))
        ops = self.ops[:, [0, 4, 2]]  # (E, 3: R, T, Z, n_q, L)
        return np.array([np.einsum("feq,efqj->ej", np.array(mode) * self._moment_weights, ops) for mode in fields])

    def _readings(self, u, params, readings, pencil):
        """(the part's reader, {held: its special modes' constraint rows or None}) per uncoupled part of the m-th
        block, the variation's state held at u; ``pencil(H, G, name)`` makes a part's reader from its matrices in
        lower band storage."""
        variation = self.variation
        variation._state(u, params)
        h = variation._nodes("azimuthal_hessian", params, m=float(self.m))
        hessian = self._local_matrices(h, self._rows)
        moments = self._mode_moments(params) if self.m == 1 else None
        for cls, dropped in self._parts():
            layout = self._layout(dropped)
            reader = pencil(layout.band(hessian), layout.band(self._gram_local), f"m{self.m}")
            rows = {}
            for held in readings:
                modes = [k for k in (excluded_modes(variation.eq, params, held) if self.m == 1 else ())
                         if cls is None or MODE_CLASS[k] == cls]
                rows[held] = np.array([layout.vector(moments[k]) for k in modes]) if modes else None
            yield reader, rows

    def lowest_readings(self, u, params, count: int, readings=(True, False)) -> dict:
        """{held: the ``count`` lowest eigenvalues} of the m-th block for each reading (held: True, free: False),
        the variation's state held at u: per part one banded factor below its spectrum (``BandedShiftInvert.under``),
        each reading's special modes removed by constraint rows (``BandedShiftInvert.lowest``)."""
        found = {held: [] for held in readings}
        for shifted, rows in self._readings(u, params, readings, BandedShiftInvert.under):
            for held in readings:
                found[held].append(shifted.lowest(count, rows[held]))
        return {held: merged_parts(values, count) for held, values in found.items()}

    def positive_readings(self, u, params, readings=(True, False)) -> dict:
        """{held: whether every eigenvalue of the m-th block is positive} for each reading, from the inertia alone
        (``BandedSigns``: one banded Cholesky or LDLᵀ per part)."""
        positive = {held: True for held in readings}
        for signs, rows in self._readings(u, params, readings, lambda H, G, _: BandedSigns(H, G)):
            for held in readings:
                positive[held] = positive[held] and signs.positive(rows[held])
        return positive


def _azimuthal_ops(basis, m: int, x: np.ndarray, sin_theta: np.ndarray) -> np.ndarray:
    """∂(R, R', Z, Z', T, T')/∂c of each element's 3(p + 1) local functions (local 3r + field) at its nodes, shape
    (E, 6, n_q, 3(p + 1)) (module docstring; ' = d/dθ)."""
    E, n_q = x.shape
    mapping = basis.mapping
    s = basis.s
    slope = np.ones_like(x) if mapping is None else mapping.ds_dx(x.ravel()).reshape(x.shape)
    sin_sigma = np.sqrt(1.0 - s * s)
    # dφ/ds = dφ/dx / h'
    phi, dphi_ds = basis.phi, basis.dphi_dx / slope[:, :, None]
    ops = np.zeros((E, 6, n_q, FIELDS * (basis.order + 1)))
    for field, order in ((Z_FIELD, m), (U_FIELD, m + 1), (D_FIELD, m - 1)):
        power = sin_sigma ** order
        value = power[:, :, None] * phi
        # df/dθ = −h' sin θ (sin^j σ φ' − j s sin^{j−2} σ φ)
        inner = power[:, :, None] * dphi_ds
        if order:
            inner = inner - (order * s * sin_sigma ** (order - 2))[:, :, None] * phi
        derivative = -(slope * sin_theta)[:, :, None] * inner
        columns = slice(field, None, FIELDS)
        if field == Z_FIELD:
            ops[:, 2, :, columns], ops[:, 3, :, columns] = value, derivative
        else:  # R = (U + D)/2, T = (U − D)/2
            sign = 1.0 if field == U_FIELD else -1.0
            ops[:, 0, :, columns], ops[:, 1, :, columns] = 0.5 * value, 0.5 * derivative
            ops[:, 4, :, columns], ops[:, 5, :, columns] = 0.5 * sign * value, 0.5 * sign * derivative
    return ops

