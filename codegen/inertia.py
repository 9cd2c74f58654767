"""Inertia of the membrane: the mass matrices of small oscillations from the kinetic energy (MODEL.md §11).

The membrane's kinetic energy is ½ ρ T0 ∫ |u̇|² dA over the reference surface (the gas massless). In the units of
the energy (lengths over R0, per 2π; docs/dynamics.md) it is the functional

    T = ½ (1/2π) ∫∫ |δẋ|² sin θ dθ dφ = ∫_{-1}^{1} t(θ) d(cos θ),

a quadratic form in the velocity of the perturbation. Its density t is derived here in the variables of each
second-variation block, from the same kinematics, so that the mass matrix M = ∂²T/∂q̇² is assembled on the same
basis as the Hessian K and the small oscillations q = q̂ e^{iωt} solve K q̂ = ω² M q̂:

- m = 0 (axisymmetric, codegen/equations.py: the state (λ2, v, η, w)): the mid-surface is λ2 R e_ρ + η e_z (R the
  reference hoop radius, sin θ on the sphere), so δx = R δλ2 e_ρ + δη e_z and t = ½ (R² λ̇2² + η̇²);
- m ≥ 1 (codegen/second_variation.py: y = (R, R', Z, Z', T, T')): δx is the ε-coefficient of its ``surface()``,
  R cos mφ e_ρ + T sin mφ e_φ + Z cos mφ e_z, and the φ-average gives t = ¼ (R² + T² + Z²).

On a reference meridian with poles (codegen/meridian.py) the area element is dA = R S' dθ dφ, S' = dS/dθ the
meridian's metric: per d(cos θ) = sin θ dθ, t carries S' R/sin θ, the factor S' as every energy density does and
R/sin θ as the meridian turns a density into the Galerkin state's (``Meridian.galerkin``: 1 where R = sin θ, the
sphere and the spheroid; a capsule's R/sin θ) (``per_area``; the sphere's S' = 1 leaves its kernels as they were,
another meridian's kernels are ``<meridian>_*`` and take its scalars; the m ≥ 1 kernels only on a meridian with
the m ≥ 1 second variation, ``analytic``). The kernels return ∂²t over the pairs of each block's variables (the
layouts of ``energy_hessian`` and ``azimuthal_hessian``); they depend on the node (and the meridian's scalars)
alone, so they form one module for every scene class, ``generated/inertia.py``.
"""
import sympy as sp

from .equations import HESSIAN_PAIRS, pair_labels
from .functional import STATE, cos_theta, eta, lam2, sin_theta
from .kernels import Arg, Kernel
from .meridian import MERIDIANS, SPHERE, Meridian
from .second_variation import PAIRS, PERTURBATION, dot, epsilon_order, phi_average, surface

TITLE = "Mass matrices of the membrane's kinetic energy for the second-variation blocks (MODEL.md §11)."


def axisymmetric_density(meridian: Meridian = SPHERE):
    """t(θ) of an axisymmetric perturbation per unit reference area: ½|δx|², δx = ∂x/∂(λ2, η)·δ(λ2, η),
    x = λ2 R e_ρ + η e_z, R the meridian's at the node (the perturbation symbols are the state's own: t is quadratic
    in them)."""
    x = (lam2 * meridian.hoop(cos_theta, sin_theta), 0, eta)
    return sp.expand(dot(x, x) / 2)


def azimuthal_density():
    """t(θ) of a cos mφ perturbation per d(cos θ): the φ-average of ½|δx|², δx the ε-coefficient of the straight
    Cartesian line of codegen/second_variation.py (the same kinematics as its Hessian)."""
    x, _, _ = surface()
    moved = tuple(epsilon_order(c, 1) for c in x)
    return phi_average(dot(moved, moved) / 2)


def per_area(density, meridian: Meridian):
    """A density per unit reference area as one per d(cos θ) dφ: times S' R/sin θ (dA = R S' dθ dφ; the R/sin θ by
    ``Meridian.galerkin``, which leaves a density without v alone but for that factor)."""
    return sp.expand(meridian.galerkin(density * meridian.metric(cos_theta, sin_theta), cos_theta, sin_theta))


def _mass_entries(density, variables, pairs):
    return tuple(sp.diff(density, variables[i], variables[j]) for i, j in pairs)


def kernel_name(block: str, meridian: Meridian) -> str:
    """The mass kernel of ``block`` ('axisymmetric' or 'azimuthal') on ``meridian``: '<block>_mass' on the sphere,
    '<meridian>_<block>_mass' on another."""
    return f"{block}_mass" if meridian.name == SPHERE.name else f"{meridian.name}_{block}_mass"


def inertia_kernels(meridian: Meridian = SPHERE) -> list[Kernel]:
    """The mass kernels of ``meridian``: m = 0, and m ≥ 1 where it has that second variation (``analytic``)."""
    args = (Arg.node(cos_theta), Arg.node(sin_theta), *map(Arg.param, meridian.parameters))
    sine = meridian.hoop(cos_theta, sin_theta) == sin_theta  # R = sin θ: the sphere's δx
    area = ("" if meridian.name == SPHERE.name else f" S' (the {meridian.name}'s area element)" if sine
            else f" S' R/sin θ (the {meridian.name}'s area element, R its hoop radius)")
    hoop = "sin²θ" if sine else "R²"
    kernels = [Kernel(kernel_name("axisymmetric", meridian),
                      f"∂²t/∂(λ2, v, η, w)² of the kinetic energy T = ∫ t d(cos θ), t = ½({hoop} λ̇2² + η̇²){area} "
                      "(m = 0), upper triangle row by row (the layout of energy_hessian).",
                      args, _mass_entries(per_area(axisymmetric_density(meridian), meridian), STATE, HESSIAN_PAIRS),
                      pair_labels(STATE, HESSIAN_PAIRS))]
    if meridian.analytic:
        kernels.append(Kernel(kernel_name("azimuthal", meridian),
                              f"∂²t/∂y² of the kinetic energy T = ∫ t d(cos θ), t = ¼(Ṙ² + Ṫ² + Ż²){area} (m ≥ 1), "
                              "y = (R, R', Z, Z', T, T'), upper triangle row by row (the layout of azimuthal_hessian).",
                              args, _mass_entries(per_area(azimuthal_density(), meridian), PERTURBATION, PAIRS),
                              pair_labels(PERTURBATION, PAIRS)))
    return kernels


def inertia_module():
    """(title, inputs, kernels) for ``generated/inertia.py``: the mass kernels of every meridian with poles (a
    tube's nodes take the sphere's: R = 1, S' = 1 in the places of sin θ and 1)."""
    return (TITLE, {"kinetic_energy": "1/2 rho T0 |du/dt|^2 dA over the reference surface"},
            [k for meridian in MERIDIANS.values() if meridian.poles for k in inertia_kernels(meridian)])
