"""The energy of a surface of revolution over (t, φ), its gradient (the residual) and Hessian (the exact Jacobian) in
the coefficients c of tube/surface/meridian.py (MODEL.md §8, §10), per 2π:

    E(c) = Σ_nodes W R S' (π(x, a_S, a_φ) − P v),   π = Φ(I, J) − ½ χ M H²(x) − Φ̄² J²,   I = |a_S|² + |a_φ|²,
    J = |a_S × a_φ|,

π, its gradient and Hessian in the 9 node variables from the scene class's generated surface kernels
(codegen/surface.py, the sphere's, with the scene's terms: ``model/kernels.scene_terms``): the reference frame is
orthonormal in (S, φ/R) as the sphere's in (θ, φ/sin θ), and the density per unit reference area is the same
function of x, a_1, a_2. They are evaluated at P = 0, i.e. without their cone form of the volume, which misses a
tube's end planes; the pressure's work is −P v (tube/surface/volume.py: the volume between a tube's end planes, a
capsule's whole). The node variables are frame components (r, t, z): Φ and the dielectric term see only I and J, and
the coaxial coils' H² (model/loop.field_squared_cartesian, the sphere's) is invariant under rotations about the axis,
so H² and its derivatives at the point (r, t, z) taken as Cartesian are those at the deformed point in the frame's
components (the frame at a node is the Cartesian one turned by φ): exact for coaxial coils, the only ones a tube or a
capsule scene takes (scene/tables.py). A node variable is Σ_j T[·, node, j] c_j (+ a plugged end's 1), so

    ∂E/∂c = Σ_a T_aᵀ (W ∂π/∂q_a),   ∂²E/∂c² = Σ_ab T_aᵀ diag(W ∂²π/∂q_a∂q_b) T_b,   ∂R/∂P = −∂Ṽ/∂c

(sum-factorised over φ: tube/surface/meridian.py ``project``, ``hessian``).
"""
import numpy as np

from . import volume
from .meridian import NODE_VARIABLES, MeridianSurfaceBasis
from ...galerkin.discretisation import symmetric_rows
from ...galerkin.equilibrium import NonFiniteState, Parameters
from ...model.kernels import KernelSet, scene_terms
from ...model.loop import CARTESIAN, field_squared_cartesian, loop_table
from ...numerics.newton import finite
from ...scene.validation import SceneError


def refuse_scene(scene, basis) -> None:
    """SceneError, one line naming the key, its value and what is allowed, for a scene of another shape than the
    basis' meridian's."""
    if scene.geometry.shape != basis.shape:
        raise SceneError(f"geometry.shape = {scene.geometry.shape.value!r}: this surface basis is a "
                         f"{basis.shape.value}'s (allowed: {basis.shape.value!r})")


class MeridianSurfaceEquilibrium:
    """E, ∇E, ∇²E and V/(2π) of a scene (its coaxial coils and voltage included) in a MeridianSurfaceBasis of its
    shape (tube/surface/meridian.py: a TubeSurfaceBasis, a CapsuleSurfaceBasis)."""

    def __init__(self, scene, basis: MeridianSurfaceBasis):
        refuse_scene(scene, basis)
        basis.check_scene(scene)
        self.scene, self.basis = scene, basis
        self.kernels = KernelSet(scene.material, scene_terms(scene)).surface()  # the class's density; P = 0 (docstring)
        self.coils = loop_table(scene.field.coils)
        if tuple(self.kernels.module.SURFACE_STATE) != NODE_VARIABLES:
            raise RuntimeError(f"{self.kernels.module.__name__}: node variables {self.kernels.module.SURFACE_STATE}, "
                               f"tube/surface/meridian.py assembles {NODE_VARIABLES}")
        self._pairs = symmetric_rows(self.kernels.module.SURFACE_PAIRS)
        self._normal = np.repeat(basis.reference_normal(), basis.n_phi, axis=1)

    def node_state(self, c: np.ndarray) -> np.ndarray:
        """The 9 node variables; NonFiniteState where the surface folds over (a_S × a_φ against the reference's
        outward normal)."""
        state = self.basis.node_state(c)
        normal_r = state[4] * state[8] - state[5] * state[7]  # (a_S × a_φ) · e_ρ
        normal_z = state[3] * state[7] - state[4] * state[6]  # (a_S × a_φ) · e_z
        if not (normal_r * self._normal[0] + normal_z * self._normal[1] > 0.0).all():
            raise NonFiniteState("the surface folds over: (a_S × a_φ) · N ≤ 0 at a node")
        return state

    def _values(self, state: np.ndarray) -> dict:
        """The kernels' node rows: the state and, with coils, H² and its derivatives at (r, t, z) (module
        docstring); NonFiniteState where the membrane reaches a wire."""
        if not self.coils.shape[0]:
            return {"state": state}
        field = np.empty((len(CARTESIAN), state.shape[1]))
        field_squared_cartesian(np.ascontiguousarray(state[:3]), self.coils, field)
        if not finite(field):
            raise NonFiniteState("the membrane reached a wire: the coil field is singular there")
        return {"state": state, "field": field}

    def _membrane(self, kernel: str, state: np.ndarray, params: Parameters) -> np.ndarray:
        out = self.kernels.nodes(kernel, self._values(state), params.with_value("P", 0.0))
        if not finite(out):
            raise NonFiniteState(f"{kernel}: non-finite values (a stretch ≤ 0)")
        return out

    def energy(self, c: np.ndarray, params: Parameters) -> float:
        """E/(2π)."""
        state = self.node_state(c)
        pi = self._membrane("surface_energy", state, params)[0] - params.P * volume.density(state)
        return float(self.basis.weights @ pi)

    def volume(self, c: np.ndarray) -> float:
        """V/(2π), the volume between the end planes."""
        return float(self.basis.weights @ volume.density(self.basis.node_state(c)))

    def residual(self, c: np.ndarray, params: Parameters) -> np.ndarray:
        """∂E/∂c."""
        state = self.node_state(c)
        pointwise = self._membrane("surface_gradient", state, params) - params.P * volume.gradient(state)
        return self.basis.project(pointwise * self.basis.weights)

    def node_hessian(self, c: np.ndarray, params: Parameters) -> np.ndarray:
        """(9, 9, nodes): W ∂²π/∂q² at every node, the rows ``hessian`` contracts."""
        state = self.node_state(c)
        pointwise = self._membrane("surface_hessian", state, params)[self._pairs] - params.P * volume.hessian(state)
        return pointwise * self.basis.weights

    def hessian(self, c: np.ndarray, params: Parameters) -> np.ndarray:
        """∂²E/∂c² (the Jacobian of ``residual``)."""
        return self.basis.hessian(self.node_hessian(c, params))

    def parameter_derivative(self, c: np.ndarray, params: Parameters, name: str = "P") -> np.ndarray:
        """∂R/∂P = −∂(V/2π)/∂c (the only continuation parameter built here)."""
        if name != "P":
            raise SceneError(f"continuation.parameter = {name!r}: the surface over (S, φ) is continued in P only "
                             '(allowed: "pressure")')
        state = self.basis.node_state(c)
        return -self.basis.project(volume.gradient(state) * self.basis.weights)
