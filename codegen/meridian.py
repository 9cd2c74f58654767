"""The reference meridian of a scene class: the surface of revolution the membrane is cut from, as data.

A meridian is its hoop radius R(t) and height Z(t) over a parameter t ∈ [t0, t1] with named ends; the kernels see it
through the node values R', R and the metric S' = dS/dt = sqrt(R'² + Z'²) (S the reference arclength):

    sphere     t = θ ∈ [0, π]   R = sin θ,  Z = cos θ,            S' = 1,     ends: two poles
    spheroid   t = θ ∈ [0, π]   R = sin θ,  Z = aspect · cos θ,   S' = sqrt(cos²θ + aspect² sin²θ),  two poles
    tube       t = S ∈ [0, L]   R = 1,      Z = −S,               S' = 1,     ends: planes (sliding) or plugs
    capsule    t = θ ∈ [0, π]   θ = S/κ, κ = 1 + L/π: caps R = sin κθ (θ < θj = π/(2κ), mirrored), cylinder R = 1,
                                S' = κ,     ends: two poles

(aspect = polar over equatorial semi-axis, a runtime argument of the kernels; the tube's length L enters no
kernel). On it the stretches are λ1 = |x'|/S' (meridional) and λ2 = ρ/R (hoop) with ρ = λ2 R, ρ' = λ2 R' + v,
v = λ2' R, and the energy per dt divided by R is π̂ = Φ(λ1, λ2) S' + (the terms' densities): every density per
reference area carries the factor S' (``metric``), the pressure's work does not (the enclosed volume is the
deformed surface's, −½ρ²η' per dt, the meridian running downwards as the sphere's does from its north pole).

A meridian with poles (R = 0 at both ends) has its node at (cos θ, sin θ) = (R', R) of the sphere's kernels, the
Legendre basis in cos θ and the pole series. A tube has no node coordinate at all: R' = 0, R = 1 and S' = 1 are
folded into its kernels (the energy kernels and the m ≥ 1 second variation: no pole series, no first-order system
in θ), and its ends are rows of its discretisation (galerkin/interval.py). The sphere's expressions are those derived before the meridian
was data, so its kernels are byte for byte what they were.

A capsule (a cylinder of length L and radius 1 with hemispherical caps) is discretised as the sphere is, in
x = cos θ with θ its arclength over κ: R and Z are C¹ in θ, only the curvature jumps at the joins θj, π − θj. Its
R ≠ sin θ, so its kernels take the sphere's Galerkin state (v = λ2' sin θ, per d(cos θ)) and turn it into the
meridian's (``galerkin``): v → v R/sin θ and π̂ → π̂ R/sin θ. R(θ) and R'(θ) are piecewise in the node's cos θ
(θ = acos(cos θ)); it has the energy kernels and the m ≥ 1 second variation (``on_meridian``: the sphere node's
form read over (R', R) and turned into the Galerkin density as its energy is), not the pole series nor the
first-order system (``analytic`` is False: R is not analytic across the joins).
"""
from dataclasses import dataclass

import sympy as sp

aspect = sp.Symbol("aspect", positive=True)
length = sp.Symbol("length", nonnegative=True)
_theta = sp.Symbol("theta", real=True)
_cos, _sin = sp.symbols("cos_theta sin_theta", real=True)
_v = sp.Symbol("v", real=True)  # codegen/functional.py's state symbol v = λ2' R


@dataclass(frozen=True)
class Meridian:
    """The sphere; subclasses change ``radius`` and ``height`` (and name their runtime scalars in ``parameters``)."""

    name = "sphere"
    parameters: tuple = ()
    poles = True  # both ends on the axis (R = 0): the Legendre basis in cos θ
    analytic = True  # R, Z analytic in θ: the pole series, the first-order system

    @property
    def node_symbols(self) -> tuple:
        """The node coordinates its kernels take: (cos θ, sin θ) for a meridian with poles, none for a tube."""
        return (_cos, _sin) if self.poles else ()

    def radius(self, t):
        """R(t)."""
        return sp.sin(t)

    def height(self, t):
        """Z(t)."""
        return sp.cos(t)

    def _at_node(self, expr, c, s):
        return expr.subs({sp.cos(_theta): c, sp.sin(_theta): s})

    def hoop(self, c, s):
        """R at the node (cos θ, sin θ) = (c, s)."""
        return self._at_node(self.radius(_theta), c, s)

    def hoop_rate(self, c, s):
        """R' = dR/dt at the node."""
        return self._at_node(sp.diff(self.radius(_theta), _theta), c, s)

    def metric(self, c, s):
        """S' = dS/dt = sqrt(R'² + Z'²) at the node (c, s), derived from R and Z (simplified: the sphere's and the
        tube's are 1)."""
        speed = sp.trigsimp(sp.sqrt(sp.diff(self.radius(_theta), _theta) ** 2
                                    + sp.diff(self.height(_theta), _theta) ** 2))
        return self._at_node(speed, c, s)

    def galerkin(self, density, c, s):
        """The energy density per d(cos θ) of the Galerkin state from the meridian's π̂ (its v = λ2' R): the same on
        a meridian with R = sin θ (sphere, spheroid) or without node coordinates (tube)."""
        return density

    def rate(self, c, s):
        """The meridian's v = λ2' R in the Galerkin state's (v = λ2' sin θ): v itself but on a capsule."""
        return _v

    def on_meridian(self, density):
        """A density written for the sphere's node, whose (cos θ, sin θ) are its (R', R) (codegen/second_variation.py),
        as the meridian's Galerkin density: unchanged where R = sin θ (sphere, spheroid)."""
        return density

    def _at_radius(self, density):
        """``density`` with the sphere's node (cos θ, sin θ) read as this meridian's (R', R) at the node."""
        return density.xreplace({_cos: self.hoop_rate(_cos, _sin), _sin: self.hoop(_cos, _sin)})

    def inputs(self) -> dict:
        """Its entries in a module's header: none for the sphere (its modules' headers stay as they were)."""
        return {} if self.name == SPHERE.name else {"shape": self.name}

    def title(self) -> str | None:
        if self.name == SPHERE.name:
            return None
        if not self.parameters:
            return f"{self.name} reference"
        return f"{self.name} reference (parameters {', '.join(map(str, self.parameters))})"


@dataclass(frozen=True)
class Spheroid(Meridian):
    name = "spheroid"
    parameters: tuple = (aspect,)

    def height(self, t):
        return aspect * sp.cos(t)


@dataclass(frozen=True)
class Tube(Meridian):
    """The circular cylinder of radius 1 over its arclength t = S (no poles: its ends are the discretisation's)."""

    name = "tube"
    poles = False
    analytic = False

    def radius(self, t):
        return sp.S.One

    def height(self, t):
        return -t

    def on_meridian(self, density):
        return self._at_radius(density)


@dataclass(frozen=True)
class Capsule(Meridian):
    """The cylinder of radius 1 and ``length`` L with hemispherical caps, over θ = S/κ ∈ [0, π] (κ = 1 + L/π, S the
    arclength from the north pole): the caps' R = sin κθ up to θj = π/(2κ), the cylinder's R = 1, Z running down
    from L/2 + 1; S' = κ. L = 0 is the sphere."""

    name = "capsule"
    parameters: tuple = (length,)
    analytic = False

    @staticmethod
    def _rate():
        return 1 + length / sp.pi

    def _cap(self, c, north, south, middle):
        """Piecewise over the node: ``north``(θ) on the north cap (cos θ > cos θj), ``south``(π − θ) on the south
        cap, ``middle`` on the cylinder."""
        joint = sp.cos(sp.pi / (2 * self._rate()))
        return sp.Piecewise((north(sp.acos(c)), c > joint), (south(sp.acos(-c)), c < -joint), (middle, True))

    def radius(self, t):
        kappa = self._rate()
        return sp.Piecewise((sp.sin(kappa * t), kappa * t < sp.pi / 2),
                            (sp.sin(kappa * (sp.pi - t)), kappa * (sp.pi - t) < sp.pi / 2), (1, True))

    def height(self, t):
        kappa = self._rate()
        return sp.Piecewise((length / 2 + sp.cos(kappa * t), kappa * t < sp.pi / 2),
                            (-length / 2 - sp.cos(kappa * (sp.pi - t)), kappa * (sp.pi - t) < sp.pi / 2),
                            (length / 2 - kappa * t + sp.pi / 2, True))

    def hoop(self, c, s):
        kappa = self._rate()
        return self._cap(c, lambda t: sp.sin(kappa * t), lambda t: sp.sin(kappa * t), sp.S.One)

    def hoop_rate(self, c, s):
        kappa = self._rate()
        return self._cap(c, lambda t: kappa * sp.cos(kappa * t), lambda t: -kappa * sp.cos(kappa * t), sp.S.Zero)

    def metric(self, c, s):
        return self._rate()

    def rate(self, c, s):
        return _v * self.hoop(c, s) / s

    def galerkin(self, density, c, s):
        """π̂ R/sin θ with v → v R/sin θ (the module docstring)."""
        return density.subs(_v, self.rate(c, s)) * (self.hoop(c, s) / s)

    def on_meridian(self, density):
        """The sphere node's form over (R', R), per dθ over R, turned into the Galerkin density (``galerkin``)."""
        return self.galerkin(self._at_radius(density), _cos, _sin)


SPHERE = Meridian()
SPHEROID = Spheroid()
TUBE = Tube()
CAPSULE = Capsule()
MERIDIANS = {m.name: m for m in (SPHERE, SPHEROID, TUBE, CAPSULE)}
