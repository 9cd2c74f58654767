"""The energy E(c) of a scene on the whole sphere (MODEL.md §8), its gradient (the residual) and Hessian in the
spherical-harmonic coefficients c of the displacement (basis.py), and the residual's parameter derivatives.

    E = Σ_nodes W π(x, a_θ, a_φ; P, M, …),   π = Φ(I, J) − ½ χ M H²(x) − (P/3) x · (a_θ × a_φ),

π, its gradient and Hessian in the 9 node variables from the generated surface kernels of the scene's class
(codegen: the same energy terms as the axisymmetric kernels), H² and its Cartesian derivatives from the coil field
(model/loop.field_squared_cartesian: loops anywhere).

On a reference spheroid (SphericalBasis.aspect c ≠ 1) π is the same function of x and the deformed images
a_1 = ∂x/∂θ / S', a_2 = ∂x/∂φ / sin θ of the reference's orthonormal frame (A_θ/S', A_φ/sin θ), per unit reference
area dA = S' d(cos θ) dφ, S' = √(cos²θ + c² sin²θ): the sphere's kernels (π per unit area of an orthonormal frame;
the pressure's x · (a_1 × a_2) dA is x · (∂x/∂θ × ∂x/∂φ) dθ dφ on any reference) at the node rows (x, a_θ/S', a_φ),
the energy's node rows times S', the gradient's row k times S' f_k and the Hessian's (k, l) times S' f_k f_l,
f = 1/S' on the three a_θ rows and 1 elsewhere.
"""
import numpy as np

from .basis import SphericalBasis
from ..galerkin.discretisation import symmetric_rows
from ..galerkin.equilibrium import NonFiniteState, Parameters
from ..model.loop import CARTESIAN, field_squared_cartesian, loop_table
from ..model.kernels import KernelSet, scene_terms
from ..numerics.newton import finite
from ..scene.tables import Shape
from ..scene.validation import SceneError

# the kernel of ∂R/∂name for a runtime scalar name
DERIVATIVE_KERNELS = {"P": "surface_pressure_gradient", "M": "surface_field_gradient",
                      "voltage": "surface_voltage_gradient"}


class SurfaceEquilibrium:
    """E, ∇E and ∇²E of one scene in a SphericalBasis; ``kernels``: the surface KernelSet (default: the scene's)."""

    def __init__(self, scene, basis: SphericalBasis, kernels=None):
        geometry = scene.geometry
        if geometry.shape not in (Shape.SPHERE, Shape.SPHEROID):
            raise SceneError(f"geometry.shape = {geometry.shape.value!r}: the whole-sphere engine takes a sphere or a "
                             'spheroid (allowed: "sphere", "spheroid")')
        if basis.aspect != geometry.aspect:
            raise ValueError(f"basis aspect = {basis.aspect:g}: the scene's reference has aspect "
                             f"{geometry.aspect:g} (allowed: the scene's)")
        self.scene, self.basis = scene, basis
        self.coils = loop_table(scene.field.coils)
        # the sphere's class on either reference (module docstring)
        self.kernels = kernels if kernels is not None else KernelSet(scene.material, scene_terms(scene)).surface()
        self._frame = _frame_scales(basis, len(self.kernels.module.SURFACE_STATE), self.kernels.module.SURFACE_PAIRS)
        self.has_field = self.coils.shape[0] > 0
        self.coaxial = all(coil.is_coaxial for coil in scene.field.coils)  # H² is axisymmetric about z at any M
        self._pairs = symmetric_rows(self.kernels.module.SURFACE_PAIRS)
        self._held = None  # the coefficients whose node state (and field) are in _named, kernel outputs in _outputs
        self._outputs = {}

    def node_values(self, c: np.ndarray) -> dict:
        """{'state': the 9 node rows of x = X + u, 'field': H² and its derivatives (field classes)} at ``c``;
        NonFiniteState if the surface folds over (J ≤ 0 at a node) or reaches a wire."""
        if self._held is not None and np.array_equal(self._held, c):
            return self._named
        self._outputs = {}
        state = self.basis.node_state(c)
        named = {"state": state}
        if self.has_field:
            field = np.empty((len(CARTESIAN), state.shape[1]))
            field_squared_cartesian(np.ascontiguousarray(state[:3]), self.coils, field)
            if not finite(field):
                raise NonFiniteState("the membrane reached a wire: the coil field is singular there")
            named["field"] = field
        if not _oriented(state, self.basis.nodes["reference"]):
            raise NonFiniteState("the surface folds over: a_θ × a_φ is zero or turns against the reference normal "
                                 "at a node")
        self._held, self._named = np.array(c), named
        return named

    def _nodes(self, kernel: str, c: np.ndarray, params: Parameters) -> np.ndarray:
        """The kernel's node rows at c, kept for the held state and parameters (stability asks for the same
        Hessian rows once per symmetry sector)."""
        values = self.node_values(c)
        key = _key(kernel, params)
        if key not in self._outputs:
            if self._frame is None:
                out = self.kernels.nodes(kernel, values, params)
            else:  # a spheroid's frame (module docstring)
                out = self.kernels.nodes(kernel, {**values, "state": self.basis.framed(values["state"])}, params)
                out = out * self._frame[out.shape[0]]
            if not finite(out):
                raise NonFiniteState(f"{kernel}: non-finite values (stretch ≤ 0 or the membrane reached a wire)")
            self._outputs[key] = out
        return self._outputs[key]

    def energy(self, c: np.ndarray, params: Parameters) -> float:
        """E per 2π."""
        pi = self._nodes("surface_energy", c, params)[0].reshape(self.basis.n_theta, self.basis.n_phi)
        return float(self.basis.nodes["weights"] @ pi.sum(axis=1))

    def residual(self, c: np.ndarray, params: Parameters) -> np.ndarray:
        """∂E/∂c."""
        return self.basis.project(self._nodes("surface_gradient", c, params))

    def hessian(self, c: np.ndarray, params: Parameters, basis: SphericalBasis | None = None) -> np.ndarray:
        """∂²E/∂c² at the state c, in ``basis`` (default the state's own; another one on the same nodes, e.g. a
        symmetry sector: the second variation against perturbations of that space)."""
        rows = self._nodes("surface_hessian", c, params)
        key = _key("fourier of surface_hessian", params)  # kept with the rows: every sector contracts the same table
        if key not in self._outputs:
            self._outputs[key] = self.basis.fourier_table(rows)
        return (basis or self.basis).hessian(self._outputs[key], self._pairs)

    def hessian_product(self, c: np.ndarray, params: Parameters, w: np.ndarray) -> np.ndarray:
        """∂²E/∂c² w without the matrix: the node Hessian D (the rows ``hessian`` assembles) applied to the node
        rows δs = ∂s/∂c w of the displacement w, then projected, Σ_jk W_j (∂s/∂c)ᵀ D δs (the same quadrature as
        ``hessian``: equal to it times w up to rounding, at the cost of a residual)."""
        rows = self._nodes("surface_hessian", c, params)
        delta = self.basis.node_displacement(w)
        return self.basis.project(np.einsum("kln,ln->kn", rows[self._pairs], delta))

    def parameter_derivative(self, c: np.ndarray, params: Parameters, name: str,
                             basis: SphericalBasis | None = None) -> np.ndarray:
        """∂R/∂name for a continuation parameter (P; M with a field; the voltage of a dielectric class), in
        ``basis`` (default the state's own; another on the same nodes, as for ``hessian``)."""
        kernel = DERIVATIVE_KERNELS.get(name)
        if kernel is None or kernel not in self.kernels.module.KERNELS:
            raise ValueError(f"no generated derivative of the surface residual in {name!r} for this scene class")
        return (basis or self.basis).project(self._nodes(kernel, c, params))


def _frame_scales(basis: SphericalBasis, rows: int, pairs) -> dict | None:
    """{kernel output rows: their scales}, 1 → S', 9 → S' f_k, 45 → S' f_k f_l, of a spheroid's frame (module
    docstring); None on the sphere (S' = 1: the kernels' rows as they are)."""
    if basis.aspect == 1.0:
        return None
    rate = np.repeat(basis.nodes["rate"], basis.n_phi)
    f = np.ones((rows, rate.size))
    f[3:6] = 1.0 / rate
    return {1: rate[None, :], rows: rate * f, len(pairs): np.array([rate * f[k] * f[l] for k, l in pairs])}


def _key(kernel: str, params: Parameters) -> tuple:
    """What a kernel's node rows at the held state depend on besides it."""
    return kernel, params.P, params.M, params.chi, params.voltage, params.mu, params.alpha, params.material


def _oriented(state: np.ndarray, reference: np.ndarray) -> bool:
    """(a_θ × a_φ) · X > 0 at every node: the area element is positive and keeps the reference sphere's outward
    orientation (the kernels see only J = |a_θ × a_φ|, blind to a fold-over)."""
    normal = np.cross(state[3:6], state[6:9], axis=0)
    return bool((np.einsum("in,in->n", normal, reference[:3]) > 0.0).all())
