"""The discrete equilibrium problem: gradient and Hessian of the Ritz energy E(u; P, M).

R(u; P, M, Φ̄) = ∂E/∂u = Σ_q W_q Σ_k ∂π̂/∂s_k ∂s_k/∂u  (s = (λ2, v, η, w) at node q, MODEL.md §2),
J = ∂R/∂u = Hessian of E (symmetric: the axisymmetric second variation), and ∂R/∂P, ∂R/∂M, ∂R/∂Φ̄ for
continuation. A point is an equilibrium when R = 0 at fixed (P, M, Φ̄).
"""
from dataclasses import dataclass, replace

import numpy as np
from numba import njit

from .discretisation import Discretisation, read_only
from .interval import IntervalDiscretisation
from ..model.field import coaxial_table, field_squared_nodes
from ..model.kernels import KernelSet
from ..model.meridian import hoop, joins, meridional_stretch
from ..numerics.newton import finite
from ..scene.energies import StrainEnergy
from ..scene.formula import domain_conditions
from ..scene.tables import Shape
from ..scene.validation import SceneError


# the kernel of ∂R/∂name for a runtime scalar name; any other name: "NAME_gradient" if the class has one
DERIVATIVE_KERNELS = {"P": "pressure_gradient", "M": "field_gradient"}


class NonFiniteState(ArithmeticError):
    """The kernels returned NaN/inf: the state left the physical domain (λ ≤ 0, a wire reached, …)."""


def non_finite(kernel: str):
    """Raise NonFiniteState for the output of ``kernel``."""
    raise NonFiniteState(f"{kernel}: non-finite values (stretch ≤ 0 or the membrane reached a wire)")


@dataclass
class Parameters:
    """Branch parameters P, M, χ, the voltage Φ̄ (a dielectric class), the Ogden moduli μ and exponents α, and a
    strain energy's parameter values ``material`` (in the order of its formula's parameters); None: the scene
    material's. The field names are the generated kernels' argument names (model/kernels.py binds them by name)."""

    P: float
    M: float = 0.0
    chi: float = 1.0
    voltage: float = 0.0
    mu: tuple | None = None
    alpha: tuple | None = None
    material: tuple | None = None

    def with_value(self, name: str, value: float) -> "Parameters":
        other = object.__new__(Parameters)  # a copy with one field replaced (no __init__: called every Newton step)
        other.__dict__.update(self.__dict__)
        if name not in other.__dict__:
            raise TypeError(f"Parameters has no field {name!r}")
        other.__dict__[name] = float(value)
        return other


def in_field(eq, params: Parameters) -> bool:
    """Whether coils act on the membrane of ``eq`` (an Equilibrium or a surface over a meridian: its ``coils``) at
    ``params`` (M ≠ 0): then a translation is no zero mode."""
    return bool(eq.coils.shape[0] and params.M != 0)


class NodeKernels:
    """The generated kernels at fixed nodes (cos θ, sin θ) on a node state held in arrays owned here.

    The owner fills ``state`` ((4, n): λ2, v, η, w in the generated STATE order) and calls ``hold(params)``, which
    evaluates the coil field H² and its derivatives at (ρ, η) = (λ2 R, η) into ``field`` (R the meridian's hoop
    radius at the nodes: sin θ but on a capsule, model/meridian.py) and checks the
    material's domain there; ``__call__(kernel, params, **fixed)`` then runs the kernel's node loop on the held
    arrays, its arguments bound once by name with the extra named values ``fixed`` (the azimuthal number m) and
    only the scalar branch parameters refilled, into an output array owned here (valid until the next call of
    the same kernel and fixed values). Material overrides (Parameters.mu, alpha, material) are bound by name at
    every call."""

    def __init__(self, equilibrium: "Equilibrium", geometry: tuple):
        self.eq = equilibrium
        self.geometry = geometry = tuple(read_only(g) for g in geometry)  # one compile of every node loop
        kernels = equilibrium.kernels
        n = geometry[0].shape[0]
        self.state = np.empty((4, n))
        self._rho = np.empty(n)
        self._radius = read_only(np.asarray(hoop(equilibrium.scene.geometry, *geometry), dtype=float))
        self.field = np.zeros((6, n)) if kernels.field_class else np.zeros((6, 0))
        self.values = dict(zip(kernels.module.STATE, self.state), cos_theta=geometry[0], sin_theta=geometry[1],
                            field=self.field if kernels.field_class else None)
        self._templates = {}  # (kernel, fixed values) -> node loop, bound arguments, scalar slots, output

    def hold(self, params: Parameters):
        """The field at the held state (if there are coils), then the domain check (``Equilibrium._check_domain``)."""
        coils = self.eq.coils
        if coils.shape[0]:
            _field_of_state(self.state, self._radius, coils, self._rho, self.field)
        if self.eq._domain_check:
            self.eq._check_domain(self.geometry, tuple(self.state), params)

    def __call__(self, kernel: str, params: Parameters, **fixed) -> np.ndarray:
        return self.evaluate((kernel, tuple(fixed.items())) if fixed else kernel, params)

    def evaluate(self, key, params: Parameters) -> np.ndarray:
        """``__call__`` by key: the kernel's name, or (name, its fixed values as items) (no keyword packing: the
        Equilibrium's Newton iterations call this)."""
        if params.mu is not None or params.alpha is not None or params.material is not None:
            kernel, fixed = (key, ()) if isinstance(key, str) else key
            return self.eq._evaluate(kernel, self.values | dict(fixed), params)
        function, args, slots, out = self._templates.get(key) or self._template(key, params)
        for slot, name in slots:
            args[slot] = float(getattr(params, name))
        function(*args, out)
        return out if finite(out) else non_finite(key if isinstance(key, str) else key[0])

    def _template(self, key, params: Parameters) -> tuple:
        """(the kernel's node loop, its arguments on the held arrays, the fixed values and the scene material as a
        list, the (position, Parameters field) of each scalar branch parameter, its output array)."""
        kernel, fixed = (key, ()) if isinstance(key, str) else key
        kernels = self.eq.kernels
        spec = kernels.module.KERNELS[kernel]
        slots = tuple((i, name) for i, (name, kind, _) in enumerate(spec["args"])
                      if kind == "param" and name not in dict(fixed) and name not in kernels.shape_values)
        entry = (getattr(kernels.module, f"{kernel}_nodes"),
                 list(kernels.arguments(kernel, self.values | dict(fixed), params)), slots,
                 np.empty((len(spec["outputs"]), self.geometry[0].shape[0])))
        self._templates[key] = entry
        return entry


class Equilibrium:
    """Residual, Jacobian and parameter derivatives of the Ritz–Galerkin system for one scene."""

    def __init__(self, scene, discretisation: Discretisation | IntervalDiscretisation,
                 kernel_class: str | None = None):
        """``kernel_class``: a generated class by name instead of the material's (model/kernels.KernelSet), e.g.
        the general class, whose exponents are runtime arguments (Parameters.alpha). A tube's scene takes an
        interval discretisation (galerkin/interval.py: its nodes pass the meridian's R' and R as cos θ and sin θ),
        every other scene the Legendre basis in cos θ; a tube on the latter is refused in one line (SceneError)."""
        if (scene.geometry.shape == Shape.TUBE) != isinstance(discretisation, IntervalDiscretisation):
            if scene.geometry.shape == Shape.TUBE:
                raise SceneError('geometry.shape = "tube": this command is not built for a tube yet; a tube\'s '
                                 'branches: balloon-cg run, sweep or continue, its onset in M: balloon-cg critical, '
                                 'one state: balloon-cg solve --hoop-stretch, or balloon_cg.tube.picture.tube_picture '
                                 '(docs/tubes.md)')
            raise ValueError(f"a {scene.geometry.shape.value} is discretised between its poles, not over an interval")
        self.scene = scene
        if isinstance(discretisation, Discretisation) and discretisation.joins != joins(scene.geometry):
            # the quadrature split where the reference curvature jumps (a capsule's joins)
            discretisation = replace(discretisation, joins=joins(scene.geometry))
        self.disc = discretisation
        self.coils = coaxial_table(scene.field.coils)
        self.kernels = KernelSet.of_scene(scene, kernel_class)
        self.geometry = (discretisation.cos_theta, discretisation.sin_theta)
        self._radius = node_radius(scene.geometry, discretisation)  # ``volume``
        self._domain_check = isinstance(scene.material, StrainEnergy) and bool(domain_conditions(scene.material.formula))
        # the node state and field of the last u (``_pointwise``), in arrays owned by ``nodes``, refilled in place
        self.nodes = NodeKernels(self, self.geometry)
        self._held = np.empty(discretisation.size)
        self._holding = False  # whether the nodes' state and field are those of _held (and _held_material's)
        self._held_material = None  # the material values the held state was checked for (its domain check)
        self._at_nodes = {}  # key -> NodeKernels at other nodes (``at_nodes``)

    def _check_domain(self, geometry: tuple, state: tuple, params: Parameters):
        """NonFiniteState if a node's stretches leave the domain of the material at ``params`` (a strain energy
        with log/sqrt terms, e.g. Gent's I1 − 3 < Jm: its kernels stay finite beyond it)."""
        if self._domain_check:
            lam2, v, _, w = state
            lam1 = meridional_stretch(self.scene.geometry, *geometry, lam2, v, w)
            margins = self.kernels.nodes("domain_margins", {"lam1": lam1, "lam2": lam2}, params)
            violation = self.scene.material.domain_violation(margins, lam1, lam2)
            if violation is not None:
                node, what = violation
                raise NonFiniteState(f"the membrane left the domain of {self.scene.material.name} at the node "
                                     f"cos θ = {geometry[0][node]:.6g}: {what}")

    def _evaluate(self, kernel: str, named: dict, params: Parameters) -> np.ndarray:
        out = self.kernels.nodes(kernel, named, params)
        return out if finite(out) else non_finite(kernel)

    def at_nodes(self, key, geometry: tuple) -> NodeKernels:
        """The kernels at other nodes (cos θ, sin θ) = ``geometry`` (a second variation's), by a key that names them."""
        if key not in self._at_nodes:
            self._at_nodes[key] = NodeKernels(self, geometry)
        return self._at_nodes[key]

    def _pointwise(self, kernel, u, params: Parameters):
        """Kernel at the own nodes, into an array owned by ``nodes`` (valid until the next call of the same kernel).
        The state and field of the last u (and material values: its domain check) are reused (Newton asks for R,
        then J)."""
        if take(self._held, u) or not self._holding or params.material != self._held_material:
            self._hold(params)
        return self.nodes.evaluate(kernel, params)

    def _hold(self, params: Parameters):
        """The node state (Discretisation.node_state) and field of the u in ``_held`` into the held arrays, held
        once the domain check passed (with the material values checked)."""
        self._holding = False
        self.disc.node_state(self._held, self.nodes.state)
        self.nodes.hold(params)
        self._holding, self._held_material = True, params.material

    def state_at(self, u, theta: np.ndarray) -> tuple:
        """(λ2, v, η, w) of the solution u at arbitrary interior angles θ."""
        lam2, dlam2, eta, deta = self.disc.evaluate(u, theta)
        return lam2, dlam2 * np.sin(theta), eta, deta

    def energy(self, u, params: Parameters) -> float:
        """E/(2π) (MODEL.md §2)."""
        return float(self.disc.weights @ self._pointwise("energy_density", u, params)[0])

    def residual(self, u, params: Parameters) -> np.ndarray:
        return self.disc.gradient(self._pointwise("energy_gradient", u, params))

    def jacobian(self, u, params: Parameters) -> np.ndarray:
        return self.disc.hessian(self._pointwise("energy_hessian", u, params))

    def hessian_product(self, u, params: Parameters, w: np.ndarray) -> np.ndarray:
        """J w = (∂R/∂u) w without assembling J (an interval discretisation's ``hessian_product``)."""
        return self.disc.hessian_product(self._pointwise("energy_hessian", u, params), w)

    def derivative_kernel(self, name: str) -> str | None:
        """The generated kernel of ∂π̂/∂s_k∂name for the runtime scalar ``name`` (``DERIVATIVE_KERNELS``, else
        ``NAME_gradient``), or None if the scene's class has none."""
        kernel = DERIVATIVE_KERNELS.get(name, f"{name}_gradient")
        return kernel if kernel in self.kernels.module.KERNELS else None

    def parameter_derivative(self, u, params: Parameters, name: str, out: np.ndarray | None = None) -> np.ndarray:
        """∂R/∂name from its generated kernel (``derivative_kernel``: P, M, voltage, …; ∂R/∂M is zero without coils,
        ∂R/∂voltage without the dielectric term), into ``out`` if given."""
        if (name == "M" and not self.coils.shape[0]) or (name == "voltage" and not self.kernels.electric):
            out = np.empty(self.disc.size) if out is None else out
            out[:] = 0.0
            return out
        kernel = self.derivative_kernel(name)
        if kernel is None:
            raise ValueError(f"no generated derivative of the residual in {name!r} for kernel class "
                             f"{self.kernels.name}")
        return self.disc.gradient(self._pointwise(kernel, u, params), out)

    def bordered_jacobian(self, u, params: Parameters, name: str) -> np.ndarray:
        """[∂R/∂u  ∂R/∂name] (n × (n + 1)) for the map X = (u, name) of a continuation or a constrained solve (one
        state evaluation serves both parts; the Hessian is assembled into its leading columns)."""
        n = self.disc.size
        out = np.empty((n, n + 1))
        self.disc.hessian(self._pointwise("energy_hessian", u, params), out)
        self.parameter_derivative(u, params, name, out[:, n])
        return out

    def sparse_jacobian(self, u, params: Parameters, name: str | None = None):
        """``jacobian`` (or with ``name``, ``bordered_jacobian``) as a scipy.sparse matrix, for a discretisation with
        a sparse Hessian (spectral elements: ``sparse_hessian``)."""
        pointwise = self._pointwise("energy_hessian", u, params)
        column = None if name is None else self.parameter_derivative(u, params, name)
        return self.disc.sparse_hessian(pointwise, column)

    def volume(self, u) -> float:
        """Enclosed volume / (2π) (``enclosed_volume``)."""
        return enclosed_volume(self.disc, u, self._radius)


def node_radius(geometry, disc) -> np.ndarray | None:
    """The meridian's R at the nodes of ``disc`` where it is not sin θ (a capsule's), else None
    (``enclosed_volume``)."""
    return hoop(geometry, disc.cos_theta, disc.sin_theta) if geometry.shape == Shape.CAPSULE else None


def enclosed_volume(disc: Discretisation, u, radius: np.ndarray | None = None) -> float:
    """Enclosed volume / (2π) = −∂E/∂P = −∫ ½ ρ² η' dθ, ρ = λ2 R (MODEL.md §2: the pressure term is −P V/(2π)),
    per d(cos θ) −½ λ2² η' R²/sin θ; ``radius``: the meridian's R at the nodes where it is not sin θ (a capsule's)."""
    lam2, _, _, w = disc.node_state(u)
    if radius is None:
        return float(-disc.weights @ (0.5 * lam2**2 * w * disc.sin_theta))
    return float(-disc.weights @ (0.5 * lam2**2 * w * radius**2 / disc.sin_theta))


@njit(cache=True)
def _field_of_state(state, radius, coils, rho, out):
    """field_squared_nodes at (ρ, z) = (λ2 R, η) of the node state (λ2, v, η, w), ρ into ``rho``."""
    for i in range(rho.shape[0]):
        rho[i] = state[0, i] * radius[i]
    field_squared_nodes(rho, state[2], coils, out)


@njit(cache=True)
def take(held, u) -> bool:
    """held ← u (1-D arrays of one size); whether an entry changed (one call: the Equilibrium's test for a new
    state)."""
    if held.shape[0] != u.shape[0]:
        raise ValueError("the state has the wrong number of unknowns")
    changed = False
    for i in range(u.shape[0]):
        if held[i] != u[i]:
            held[i] = u[i]
            changed = True
    return changed
