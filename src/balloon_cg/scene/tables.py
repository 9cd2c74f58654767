"""Scenes: a balloon described in a TOML file (material, applied field, continuation and numerical settings).

Every table but ``[material]`` may be omitted (defaults apply). Invalid input raises one SceneError whose
one-line message names the file (or scene), the dotted key, the value and what is allowed.
"""

import enum
import errno
import math
import os
import re
import stat
import tomllib
from dataclasses import asdict, dataclass, fields, replace
from dataclasses import field as dataclass_field
from pathlib import Path

from .validation import SceneError, did_you_mean, number, show, show_key, table
from .energies import StrainEnergy
from .events import Event, check_on_shape, events_from_list
from .loading import Control, Loading, loading_from_table, moved_stop_volume
from .materials import ALPHA1, MAX_EXPONENT, Material, alpha1_terms, material_from_table, modified_name

__all__ = [
    "Coil", "Field", "Electric", "Geometry", "Shape", "Ends", "ContinuationParameter", "Continuation", "Solver",
    "Stability", "Output", "Loading", "Control", "Scene", "SceneError",
    "parse_scene", "parse_stored", "startable", "load_scene",
]


@dataclass(frozen=True)
class Coil:
    """A circular current loop (MODEL.md §9): radius a, signed current s (circulating positively about n), centre c
    and unit normal n. Coaxial with the balloon when c = (0, 0, h) and n = e_z: the scene's ``height`` form (a loop
    on the axis with normal −e_z is stored so, its current reversed: the same loop)."""

    radius: float
    current: float
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0)
    normal: tuple[float, float, float] = (0.0, 0.0, 1.0)

    @classmethod
    def coaxial(cls, radius: float, height: float, current: float) -> "Coil":
        """The loop of radius a coaxial with the balloon, its plane at height h."""
        return cls(radius, current, (0.0, 0.0, height))

    @property
    def height(self) -> float:
        """The height of the loop's centre (of its plane, for a coaxial loop)."""
        return self.centre[2]

    @property
    def is_coaxial(self) -> bool:
        """True when the loop's centre lies on the balloon's axis and its normal is e_z."""
        return self.centre[:2] == (0.0, 0.0) and self.normal == (0.0, 0.0, 1.0)

    def to_table(self) -> dict:
        """The scene's [[field.coils]] table: {radius, height, current} for a coaxial loop (as written before
        loops anywhere existed), else {radius, centre, normal, current}."""
        if self.is_coaxial:
            return {"radius": self.radius, "height": self.height, "current": self.current}
        return {"radius": self.radius, "centre": list(self.centre), "normal": list(self.normal),
                "current": self.current}


@dataclass(frozen=True)
class Field:
    """The applied field: coupling χ, intensity M (section 2 of MODEL.md) and the coils producing it."""

    chi: float = 1.0
    M: float = 0.0
    coils: tuple[Coil, ...] = ()

    @property
    def is_axisymmetric(self) -> bool:
        """True when every coil is coaxial with the balloon (or none acts, M = 0): the axisymmetric solver traces
        the primary branch; otherwise the whole-sphere one does (analysis.surface.primary)."""
        return self.M == 0 or all(c.is_coaxial for c in self.coils)

    @property
    def is_equator_symmetric(self) -> bool:
        """True when the coils are coaxial and mirror-symmetric about z = 0, so that H² is even in z.

        Every coil (a, h, s) needs a partner (a, −h, ±s); the sign must be + for all pairs (h_z even)
        or − for all pairs (h_ρ even). A coil at h = 0 is its own partner, with sign +.
        """
        if not all(c.is_coaxial for c in self.coils):
            return False
        same_sign = set()
        for c in self.coils:
            partner = next(
                (d for d in self.coils
                 if d.radius == c.radius and d.height == -c.height and abs(d.current) == abs(c.current)),
                None,
            )
            if partner is None:
                return False
            same_sign.add(partner.current == c.current)
        return len(same_sign) <= 1


@dataclass(frozen=True)
class Electric:
    """An ideal dielectric elastomer membrane under the nondimensional voltage Φ̄ = (Φ/H)√(ε/μ) across its
    thickness: the energy gains −Φ̄² λ1² λ2² (units μ/2, MODEL.md §2; docs/scenes.md). ``voltage`` is held fixed
    along a pressure continuation; a voltage continuation starts from the sphere's voltage instead."""

    voltage: float = 0.0


class Shape(enum.StrEnum):
    """The reference surface the membrane is cut from (``Geometry.shape``)."""

    SPHERE = "sphere"
    SPHEROID = "spheroid"
    TUBE = "tube"
    CAPSULE = "capsule"


class Ends(enum.StrEnum):
    """How a tube ends (``Geometry.ends``): "sliding", planes of symmetry the meridian meets at a right angle (its
    radius free there), or "plugged", rigid plugs of the reference radius; both closed: no axial force beyond the
    pressure's on the ends (docs/tubes.md)."""

    SLIDING = "sliding"
    PLUGGED = "plugged"


@dataclass(frozen=True)
class Geometry:
    """The reference surface (docs/scenes.md, [geometry]): the unit sphere, a spheroid of equatorial semi-axis 1
    and polar semi-axis ``aspect`` (< 1 oblate, > 1 prolate; 1 is the sphere), the axis that of the coils, or a
    circular cylinder of radius 1 and ``length`` with ``ends``, or a capsule: the cylinder of ``length`` closed by
    hemispherical caps of radius 1 (length 0: the sphere), its cylinder discretised as one spectral element or
    cut into elements of at most ``element_length`` (model/meridian.joins). Lengths stay in units of the
    equatorial radius; the reference meridian is model/meridian.py's."""

    shape: Shape = Shape.SPHERE
    aspect: float = 1.0
    length: float | None = None  # a tube's or a capsule's cylinder's
    ends: Ends | None = None  # a tube's
    axial_stretch: float | None = None  # a tube's ends held at the distance λL (None: closed, the distance free)
    element_length: float | None = None  # a capsule's longest cylinder element (None: the cylinder one element)
    element_degrees: str | None = None  # a capsule's: GRADED, a degree per element from its own tail (None: shared)

    def to_table(self) -> dict:
        """Its [geometry] table (a spheroid's keeps the text it had before tubes)."""
        if self.shape == Shape.TUBE:
            held = {} if self.axial_stretch is None else {"axial_stretch": self.axial_stretch}
            return {"shape": self.shape.value, "length": self.length, "ends": self.ends.value} | held
        if self.shape == Shape.CAPSULE:
            split = {} if self.element_length is None else {"element_length": self.element_length}
            graded = {} if self.element_degrees is None else {"element_degrees": self.element_degrees}
            return {"shape": self.shape.value, "length": self.length} | split | graded
        return {"shape": self.shape.value, "aspect": self.aspect}

    @property
    def reference_volume(self) -> float:
        """V0/R0³ enclosed by the reference surface: 4π/3 · aspect (sphere, spheroid), πL + 4π/3 (capsule), πL
        (tube)."""
        cylinder = 0.0 if self.length is None else math.pi * self.length
        return cylinder if self.shape == Shape.TUBE else cylinder + 4 * math.pi / 3 * self.aspect

    def describe(self) -> str:
        """'sphere', 'spheroid of aspect 1.5', 'capsule of length 40', 'tube of length 10 with sliding ends',
        '... held at 1.5 L'."""
        if self.shape == Shape.TUBE:
            held = "" if self.axial_stretch is None else f" held at {self.axial_stretch:g} L"
            return f"tube of length {self.length:g} with {self.ends.value} ends{held}"
        if self.shape == Shape.CAPSULE:
            return f"capsule of length {self.length:g}"
        if self.shape == Shape.SPHERE:
            return "sphere"
        return f"{self.shape.value} of aspect {self.aspect:g}"


class ContinuationParameter(enum.StrEnum):
    """The parameter a primary branch is continued in: P at fixed Φ̄, or Φ̄ at fixed P."""

    PRESSURE = "pressure"
    VOLTAGE = "voltage"


@dataclass(frozen=True)
class Continuation:
    """Branch following, parameterised by the pole stretch λ2(0).

    The branch starts at the sphere inflated to ``start_stretch`` and stops when the stretch passes
    ``stop_stretch``, falls below ``min_stretch``, P passes ``stop_pressure`` (None: no limit), after
    ``max_points`` points, or when the membrane comes within ``wire_gap`` of a coil wire. Arclength steps
    start at ``step`` and stay in [step_min, step_max]. ``symmetry``: "equator" imposes η(π − θ) = −η(θ)
    (needs equator-symmetric coils), "none" never does, "auto" does when the field allows it.
    ``parameter``: "pressure" (P varies), or "voltage" (Φ̄ varies at the fixed P = ``pressure``, needs
    [electric]; it stops when Φ̄ passes ``stop_voltage``, None: no limit). ``stop_field``: the field M where a
    continuation in M at fixed P (``continue --parameter M``) stops, None: no limit. ``stop_volume``: the enclosed
    volume V/R0³ where a branch ends (landed on exactly), under every control and on every shape (a tube's V0 = πL,
    a sphere's 4π/3), None: no limit (``loading.stop_volume`` is its old name).
    """

    start_stretch: float = 1.01
    stop_stretch: float = 5.0
    min_stretch: float = 1.001
    stop_pressure: float | None = None
    step: float = 0.05
    step_min: float = 1e-7
    step_max: float = 0.25
    max_points: int = 300
    symmetry: str = "auto"
    wire_gap: float = 0.02
    parameter: ContinuationParameter = ContinuationParameter.PRESSURE
    pressure: float | None = None
    stop_voltage: float | None = None
    stop_field: float | None = None
    stop_volume: float | None = None


@dataclass(frozen=True)
class Solver:
    """Discretisation: Legendre ``degree``, Gauss points (``quadrature``, 0 = automatic), Newton settings.

    The degree grows by half (up to ``max_degree``) whenever the spectral error estimate of a point exceeds
    ``max_error``; a branch that would need more stops there, saying so. A tube's bulge branch (switched at an odd
    branch point) follows ``tube_resolution``: "elements" (the default) traces it on spectral elements whose layout
    is refined locally until every point is resolved, at most tube/front.element_cap unknowns per field;
    "flag" at the scene's degree, its points past ``max_error`` flagged; "refine" retraces it at growing degree until
    it is resolved, stopping "unresolved" at ``max_degree`` (tube/resolution.py). Other shapes never read it.
    """

    degree: int = 40
    quadrature: int = 0
    tol: float = 1e-11
    max_newton: int = 25
    max_degree: int = 320
    max_error: float = 1e-9
    tube_resolution: str = "elements"


@dataclass(frozen=True)
class Stability:
    """Second variation: Legendre ``degree`` of the perturbations, the largest azimuthal number ``m_max`` and the
    perturbation ``basis``: "legendre" (polynomials of x = cos θ) or "mapped" (of the mapped coordinate s(x) of a
    branch's wire map; the same as "legendre" on a branch without one), and the ``norm`` the m = 0 eigenvalues are
    relative to: "unknowns" ∫(δλ2² + δη²) d(cos θ) or "displacement" ∫(sin²θ δλ2² + δη²) d(cos θ) = |δx|², the
    m ≥ 1 blocks' norm (flags and branch points do not depend on it). ``banded_from``: the blocks (m = 0 and m ≥ 1) of a
    point assessed at perturbation degree N ≥ it are read on the banded sibling basis (C⁰ elements on the same map,
    analysis/stability/banded.py); 0: never; the default 225 (below it the dense blocks are as fast or faster:
    docs/numerics.md §6). ``banded_flags_from``: the same for the flags alone (the check degree's, from the blocks'
    inertia), default 60 (the banded inertia is the cheaper from ~45: benchmarks/banded_crossover.py)."""

    degree: int = 20
    m_max: int = 1
    basis: str = "mapped"
    norm: str = "displacement"
    banded_from: int = 225
    banded_flags_from: int = 60


STABILITY_BASES = ("legendre", "mapped")
TUBE_RESOLUTIONS = ("flag", "refine", "elements")  # solver.tube_resolution
STABILITY_NORMS = ("unknowns", "displacement")


@dataclass(frozen=True)
class Surface:
    """The non-axisymmetric branches born at the m ≥ 1 branch points (MODEL.md §8): at the ``branches`` "first" one
    of the primary branch, "all", or "none"; spherical-harmonic ``degree`` L of the whole-sphere basis;
    ``max_points`` per branch."""

    branches: str = "first"
    degree: int = 16
    max_points: int = 30


SURFACE_BRANCHES = ("first", "all", "none")


def default_surface(shape, field, electric, stability) -> Surface:
    """The [surface] table a scene without one has: ``Surface()`` ("first"), except ``branches = "none"`` on a tube
    without the m ≥ 1 zeros they start from (stability.m_max = 0; ``_surface_reads`` refuses "first" there),
    and on a tube in a coil's field or under a voltage, where "first" is taken when asked for but is not the default:
    a trace there may refine to the basis's cap for tens of minutes (a plugged tube in a coil's field), and with
    stability.m_max ≥ 2 the first zero can be the slack state's near P = 0 (docs/tubes.md "The tube over (S, φ)");
    "none" on a capsule and a spheroid, where "first" and "all" are taken when asked for but are not the default (a
    capsule's trace over (θ, φ) refines to hundreds or thousands of dense unknowns: minutes per point, docs/tubes.md
    "The engine over any meridian"; docs/shapes.md "The spheroid's surface branches")."""
    if shape in (Shape.CAPSULE, Shape.SPHEROID):
        return Surface(branches="none")
    built = not field.coils and electric is None and stability.m_max >= 1
    return Surface(branches="none") if shape == Shape.TUBE and not built else Surface()


def _surface_reads(surface: Surface, geometry, field, stability, continuation) -> None:
    """SceneError for [surface] branches asked where none can be traced: on a capsule of length 0 without a field
    (the m = 1 rigid rotation and the relabelling are two zero modes its one reference row cannot tell apart:
    analysis/surface/meridian/capsule.py ``gauge_rows``; the sphere's shape traces them), on a tube or a capsule
    without the m ≥ 1 zeros they start from (stability.m_max = 0; tube/surface/branch.py), on a capsule continued
    in the voltage (its meridian engine traces in P at a fixed Φ̄: analysis/surface/meridian/trace.py)."""
    if surface.branches == "none":
        return
    asked, shape = f"surface.branches = {show(surface.branches)}", geometry.shape
    if shape == Shape.CAPSULE and geometry.length == 0 and not (field.coils and field.M != 0):
        raise SceneError(f"{asked}: a capsule of length 0 without a field (its m = 1 rigid rotation and relabelling "
                         f'are both zero modes); allowed: "none", geometry.length > 0, coils with M ≠ 0, or '
                         f'geometry.shape = "sphere"')
    if shape in (Shape.TUBE, Shape.CAPSULE) and stability.m_max < 1:
        raise SceneError(f"{asked}: a {shape.value}'s non-axisymmetric branches start at the m ≥ 1 zeros located "
                         f'with stability.m_max ≥ 1, not {stability.m_max}; allowed: "none" with stability.m_max = 0')
    if shape == Shape.CAPSULE and continuation.parameter == ContinuationParameter.VOLTAGE:
        raise SceneError(f'{asked}: a capsule\'s non-axisymmetric branches are traced in P, not on a branch '
                         f'continued in the voltage (continuation.parameter = "voltage"); allowed: "none", or '
                         f'continuation.parameter = "pressure"')


@dataclass(frozen=True)
class Dynamics:
    """Natural frequencies (MODEL.md §11, docs/dynamics.md): with ``frequencies`` the lowest ``count`` Ω² of every
    second-variation block, m = 0..``m_max``, at every point of every axisymmetric branch (of every symmetry sector
    and reading of a surface branch); with ``modes`` also their mode shapes at the special points."""

    frequencies: bool = False
    count: int = 3
    m_max: int = 1
    modes: bool = False


@dataclass(frozen=True)
class Output:
    """Sampling of the reported shapes and fields: ``theta_points`` values of θ on [0, π]."""

    theta_points: int = 181
    memory_limit: float = 2.0  # GiB: the bound on products of keys (_check_products)


_TABLES = ("material", "field", "continuation", "solver", "stability", "output", "loading", "electric", "surface",
           "events", "geometry", "dynamics")
MAX_NESTING = 8  # docs/scenes.md, Bounds: arrays/tables within one another (a scene needs 3)
MAX_QUADRATURE = 1000  # Gauss points (automatic at degree 400: 608)
# docs/scenes.md, Bounds: ranges that keep the computation finite (the paper's values are far inside them)
MAX_COILS = 64
MAX_COIL_DISTANCE = 1e3  # |radius|, |height| of a coil
MAX_CURRENT = 1e3  # |current| of a coil (relative currents: only ratios and M matter)
MAX_M = 1e3  # field.M (the paper's isolas close near M = 0.003; critical curves in M pass M = 4)
MAX_CHI = 100.0
MAX_VOLTAGE = 10.0  # electric.voltage, continuation.stop_voltage (a sphere's voltage peaks below 1)
MAX_STRETCH = 100.0  # continuation.start_stretch, stop_stretch
MIN_ASPECT, MAX_ASPECT = 0.1, 10.0  # geometry.aspect of a spheroid
MIN_LENGTH, MAX_LENGTH = 0.1, 1000.0  # geometry.length of a tube (in reference radii)
CLOSED = "closed"  # geometry.axial's one value: the default, the ends' distance free (axial_stretch left out)
# geometry.element_length of a capsule (reference radii), and the most cylinder elements it may cut (each adds
# basis functions before any polynomial degree: model/meridian.cylinder_elements)
MIN_ELEMENT, MAX_ELEMENTS = 1.0, 41
GRADED = "graded"  # geometry.element_degrees of a capsule: a degree per element (analysis/branches/graded.py)
MIN_AXIAL, MAX_AXIAL = 1.0, 5.0  # geometry.axial_stretch: a tube's ends held at λL (below 1 the membrane would be
#                                  compressed axially at P = 0)
MIN_STEP, MAX_STEP = 1e-12, 10.0  # continuation.step_min .. step_max
MAX_WIRE_GAP = 10.0
MIN_TOLERANCE = 1e-15  # solver.tol, solver.max_error (below rounding no Newton step converges)
PROFILE_ARRAYS = 8  # doubles per (point, θ) while a branch's profiles are computed (io.run_file, galerkin.profiles)
MAX_SCENE_BYTES = 1 << 20  # a scene file (a scene needs a few hundred bytes)


@dataclass(frozen=True)
class Scene:
    """A validated scene: the membrane's material, the coils' field, the continuation, the solver, stability and
    output settings (docs/scenes.md); ``text`` is the TOML it was parsed from (provenance). Frozen: change it with
    ``with_overrides``.

    Examples
    --------
    >>> scene = bc.Scene.from_toml("spom1_two_coils_M0.002")
    >>> scene.field.M, scene.material.name
    >>> print(scene.to_toml())
    """

    name: str
    material: Material | StrainEnergy
    field: Field
    continuation: Continuation
    solver: Solver
    stability: Stability
    output: Output
    electric: Electric | None  # None: no dielectric term in the kernels
    text: str = dataclass_field(repr=False)
    loading: Loading = Loading()
    surface: Surface = Surface()
    events: tuple[Event, ...] = ()  # [[events]]: points wanted where a stored quantity reaches a value (UZ)
    geometry: Geometry = Geometry()  # [geometry]: the reference surface
    dynamics: Dynamics = Dynamics()

    @property
    def voltage(self) -> float:
        """The voltage Φ̄ of [electric] (MODEL.md's dimensionless voltage across the membrane), 0 without one."""
        return 0.0 if self.electric is None else self.electric.voltage

    @classmethod
    def from_toml(cls, path) -> "Scene":
        """The scene of a TOML file.

        Parameters
        ----------
        path : str or Path
            A TOML file, or the name of a shipped scene (``"spom1"``: ``shipped_scenes()``).

        Returns
        -------
        Scene
            Named after the file stem (``load_scene``).

        Raises
        ------
        SceneError
            An invalid scene (one line naming the key, the value and what is allowed).
        FileNotFoundError
            No such file and no shipped scene of that name.
        """
        return load_scene(path)

    def to_dict(self) -> dict:
        """The normalised, fully defaulted scene as plain dicts, lists and numbers (presets expanded); the
        [loading], [surface] and [dynamics] tables only when they are not the default, so older scenes keep their
        text."""
        m, f = self.material, self.field
        return {
            "material": m.to_table() if isinstance(m, StrainEnergy) else
            {"name": m.name, "mu": list(m.mu), "alpha": list(m.alpha)},
            "field": {"chi": f.chi, "M": f.M, "coils": [c.to_table() for c in f.coils]},
            "continuation": asdict(self.continuation),
            "solver": {k: v for k, v in asdict(self.solver).items()  # tube_resolution on tubes and where set: older
                       if k != "tube_resolution" or v != Solver.tube_resolution  # texts stay; a tube's says it
                       or self.geometry.shape == Shape.TUBE},
            "stability": asdict(self.stability),
            "output": {k: v for k, v in asdict(self.output).items()  # memory_limit only when set: older texts stay
                       if k != "memory_limit" or v != Output.memory_limit},
            **({} if self.loading == Loading() else {"loading": {**asdict(self.loading),
                                                                  "control": self.loading.control.value}}),
            **({} if self.electric is None else {"electric": asdict(self.electric)}),
            **({} if self.surface == default_surface(self.geometry.shape, f, self.electric, self.stability)
               else {"surface": asdict(self.surface)}),
            **({"events": [e.to_table() for e in self.events]} if self.events else {}),
            **({} if self.geometry == Geometry() else {"geometry": self.geometry.to_table()}),
            **({} if self.dynamics == Dynamics() else {"dynamics": asdict(self.dynamics)}),
        }

    def __repr__(self):
        """One line: the name, the material, the coils and M, the loading and where the continuation stops
        (``to_toml()`` holds everything)."""
        c, coils = self.continuation, len(self.field.coils)
        field = f"{coils} coil{'s' * (coils != 1)}, M = {self.field.M:g}" if coils else "no field"
        voltage = "" if self.electric is None else f", voltage {self.electric.voltage:g}"
        stop = f"stop_stretch {c.stop_stretch:g}"
        if c.parameter == ContinuationParameter.VOLTAGE:
            stop = "in the voltage" + ("" if c.stop_voltage is None else f" to {c.stop_voltage:g}")
        shape = "" if self.geometry == Geometry() else f", {self.geometry.describe()}"
        return (f"Scene({self.name!r}: {self.material.name}{shape}, {field}{voltage}, {self.loading.control.value} "
                f"control, {stop})")

    def to_toml(self) -> str:
        """TOML text of ``to_dict()``; parsing it gives back this scene (apart from ``text``)."""
        return _to_toml(self.to_dict())

    def canonical_key(self, key: str) -> str:
        """The dotted key for a key as the command line takes it.

        Parameters
        ----------
        key : str
            A dotted key (returned as it is), or a bare name of a key of one table (``M`` -> ``field.M``;
            ``preset`` -> ``material.preset``).

        Returns
        -------
        str

        Raises
        ------
        SceneError
            A bare name that no table, or several, have.
        """
        if "." in key or key == ALPHA1:
            return key
        data = self.to_dict()
        tables = ["material"] if key == "preset" else [t for t, content in data.items() if key in content]
        if len(tables) > 1:
            raise SceneError(f"{key}: a bare name must name a key of exactly one scene table; {key!r} is in tables "
                             f"{', '.join(tables)} (write one of {', '.join(f'{t}.{key}' for t in tables)})")
        if not tables:
            names = [k for content in data.values() if isinstance(content, dict) for k in content] + [ALPHA1]
            raise SceneError(f"{key}: not a scene key{did_you_mean(key, names)} (a dotted key such as field.M, "
                             f"or a bare name of one table's key, or {ALPHA1}: docs/scenes.md)")
        return f"{tables[0]}.{key}"

    def with_overrides(self, overrides: dict[str, object], name: str | None = None) -> "Scene":
        """A re-validated copy with keys set.

        ``material.preset`` replaces the whole material (applied first, whatever the order: the other material
        keys change the new one).

        Parameters
        ----------
        overrides : dict
            Dotted keys, e.g. ``{"field.M": 0.003, "field.coils[0].radius": 3.5}``, or bare names of one table
            as on the command line (``{"M": 0.003}``: ``canonical_key``); a value None restores the default.
        name : str, optional
            The copy's name; default: this name after what changed physically (each field, material or loading
            key's token, ``_M0.002``, ``_radius4``, takes the new value or is appended; numerical keys keep the
            name).

        Returns
        -------
        Scene

        Raises
        ------
        SceneError
            An unknown key, a key given twice, or a value out of range.

        Examples
        --------
        >>> bc.Scene.from_toml("spom1_two_coils_M0.002").with_overrides({"M": 0.003}).name
        """
        data = self.to_dict()
        try:
            canonical = {}
            for key, value in overrides.items():
                if self.canonical_key(key) in canonical:
                    raise SceneError(f"{key}: {self.canonical_key(key)} is given twice")
                canonical[self.canonical_key(key)] = value
            overrides = canonical
            preset = overrides.get("material.preset")
            if preset is not None:  # first, in any order: it replaces the material the other material keys change
                _assign(data, "material.preset", preset)
                if any(_PARAMETER_KEY.fullmatch(key) or key == ALPHA1 for key in overrides):  # its terms, written out
                    data = _build(data, self.name, "").to_dict()
            base = material_from_table(dict(data["material"])) if preset is not None else self.material
            for key, value in overrides.items():
                if key != "material.preset" or preset is None:
                    _assign(data, key, value)
            scene = startable(_build(data, name or renamed(self.name, overrides), ""))
            if "material.name" not in overrides:  # the values computed with, never a preset's name they left
                scene = replace(scene, material=replace(scene.material, name=modified_name(base, scene.material)))
        except SceneError as e:
            raise SceneError(f"{self.name}: {e}") from None
        return replace(scene, text=scene.to_toml())


def renamed(name: str, overrides: dict[str, object]) -> str:
    """``name`` with a ``_<key><value>`` token per scalar field, material or loading override (key: the last part
    of the dotted key, with its list index past 0: ``radius3.5``, ``radius1=3.5``; a string: itself, reduced to
    filename-safe characters): an existing token of that key is updated, else one is appended. Lists and tables
    (``field.coils``, ``material.mu``) leave the name alone."""
    for key, value in overrides.items():
        physical = key.split(".")[0] in ("field", "material", "loading", "electric", "geometry", ALPHA1)
        if not physical or value is None or isinstance(value, (list, tuple, dict)):
            continue
        if isinstance(value, str):  # a preset or a material name
            name = f"{name}_{re.sub(r'[^A-Za-z0-9.+-]+', '-', value).strip('-').lower()}"
            continue
        name = _with_token(name, key, value)
    return name


def output_stem(name: str, overrides: dict[str, object]) -> str:
    """The file stem of a scene run with ``overrides`` (the command line's --set and --unset), ``name`` the scene's
    name (``renamed`` after its physical keys): a ``_<key><value>`` token also for every scalar key the name does
    not show, numerical keys (``_stop_stretch3``, ``_degree60``) and list entries (``_alpha3``), and
    ``_<key>default`` for a key restored to its default; a preset or material name is in ``name`` already."""
    for key, value in overrides.items():
        physical_text = isinstance(value, str) and key.split(".")[0] in ("field", "material", "loading", "electric",
                                                                          "geometry")
        if not physical_text and not isinstance(value, (list, tuple, dict)):
            name = _with_token(name, key, value)
    return name


def _with_token(name: str, key: str, value) -> str:
    """``name`` with its ``_<key><value>`` token (key: the last part of the dotted key, with its list index past
    0) updated, or appended; a value None reads ``default``."""
    indices = "".join(i for i in re.findall(r"\[(\d+)\]", key) if i != "0")
    short = re.sub(r"\[\d+\]", "", key.split(".")[-1]) + (f"{indices}=" if indices else "")
    text = "default" if value is None else str(value)
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        text = f"{value:g}"
    elif isinstance(value, str):  # a file name's characters
        text = re.sub(r"[^A-Za-z0-9.+-]+", "-", value).strip("-").lower()
    token = re.compile(rf"(^|_){re.escape(short)}(-?[0-9][0-9.eE+-]*|default)(?=_|$)")
    return token.sub(lambda m: f"{m.group(1)}{short}{text}", name, count=1) if token.search(name) \
        else f"{name}_{short}{text}"


ELEMENTS_SINCE = 3  # the readings revision (io.legacy.READINGS) of the first files whose tubes' default
#                    solver.tube_resolution is "elements"; a tube's text stored before it without the key ran "flag"


def parse_scene(text: str, name: str = "scene", written: int | None = None) -> Scene:
    """Parse and validate a scene from TOML text.

    Parameters
    ----------
    text : str
        The scene's TOML (docs/scenes.md).
    name : str, optional
        The scene's name (default ``"scene"``).
    written : int, optional
        The readings revision of the file that stored ``text`` (io.legacy.READINGS; None: a new scene): its
        defaults are that revision's (``ELEMENTS_SINCE``).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        Invalid TOML or an invalid scene (one line naming the key, the value and what is allowed).
    """
    return _parse(text, name, name, written=written)


def parse_stored(text: str, name: str = "scene", written: int | None = None) -> Scene:
    """The scene a file stores (its ``scene_toml``), read as it was written: ``parse_scene`` without the checks of
    what a new run may start (``startable``), so that a file written before one of them is still read (inspect,
    plot, load) and says what it was computed with, under the defaults of the file's readings revision
    ``written``; SceneError for text that is no scene."""
    return _parse(text, name, name, new=False, written=written)


def startable(scene: Scene) -> Scene:
    """``scene``, or SceneError for what a new run of it may not start: a stop at or below the reference volume
    (``_stop_volume_above_reference``), [surface] branches where none can be traced (``_surface_reads``). Checked on
    new input (``parse_scene``, ``load_scene``, ``Scene.with_overrides``) and where ``continue`` starts from a file's
    scene; not on a file's stored text (``parse_stored``)."""
    _stop_volume_above_reference(scene.continuation.stop_volume, scene.geometry)
    _surface_reads(scene.surface, scene.geometry, scene.field, scene.stability, scene.continuation)
    return scene


def load_scene(path) -> Scene:
    """Read a scene file.

    Parameters
    ----------
    path : str or Path
        A TOML file; a bare name that is not a file (``"spom1"``, ``"spom1.toml"``) names a scene shipped with the
        package (``shipped_scenes()``).

    Returns
    -------
    Scene
        Named after the file stem (error messages name the file).

    Raises
    ------
    SceneError
        An invalid scene.
    FileNotFoundError
        No such file and no shipped scene of that name (the nearest names suggested).
    """
    if str(path) == "":
        raise FileNotFoundError(errno.ENOENT, "an empty scene path (give a scene file or a shipped scene's name)",
                                "''")
    path = Path(path)
    shipped = path.name.removesuffix(".toml")
    if not path.exists() and path.parent == Path("."):
        if shipped not in shipped_scenes():
            near = did_you_mean(shipped, [*shipped_scenes(), *(p.name for p in Path(".").glob("*.toml"))])
            raise FileNotFoundError(errno.ENOENT, f"no such file, nor the name of a scene shipped with the package"
                                    f"{near} ({', '.join(sorted(shipped_scenes()))})", str(path))
        path = shipped_scenes()[shipped]
    return _parse(_read_text(path), path.stem, path.name)


def _read_text(path: Path) -> str:
    """The text of the scene file ``path``: a regular file (not a folder, FIFO or device, which could block or
    never end) of at most MAX_SCENE_BYTES, in UTF-8."""
    with open(path, "rb", opener=lambda name, flags: os.open(name, flags | os.O_NONBLOCK)) as handle:
        if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):
            raise SceneError(f"{path}: not a regular file (a scene is a TOML file)")
        data = handle.read(MAX_SCENE_BYTES + 1)
    if len(data) > MAX_SCENE_BYTES:
        raise SceneError(f"{path.name}: larger than {MAX_SCENE_BYTES // 1024} KiB (a scene needs a few hundred bytes)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise SceneError(f"{path.name}: not UTF-8 text ({e})") from None


def shipped_scenes() -> dict[str, Path]:
    """The scenes shipped with the package (the repository's scenes/ folder).

    Returns
    -------
    dict
        {name: path of its TOML file}.
    """
    from importlib import resources

    folder = resources.files("balloon_cg.scenes")
    return {item.name.removesuffix(".toml"): Path(str(item)) for item in folder.iterdir() if item.name.endswith(".toml")}


def _parse(text: str, name: str, source: str, new: bool = True, written: int | None = None) -> Scene:
    """The scene of the TOML ``text`` (errors prefixed with ``source``), ``startable`` unless it is a file's stored
    text (``new`` False: ``parse_stored``), with the defaults of readings revision ``written`` (None: this one's)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{source}: invalid TOML: {e}") from None
    except RecursionError:
        raise SceneError(f"{source}: invalid TOML: arrays or tables nested deeper than {MAX_NESTING} levels") from None
    try:
        _check_nesting(data)
        scene = _build(_as_written(data, written), name, text)
        return startable(scene) if new else scene
    except SceneError as e:
        raise SceneError(f"{source}: {e}") from None


def _as_written(data: dict, written: int | None) -> dict:
    """``data`` with the defaults of readings revision ``written`` where they differ from this version's: a tube's
    solver.tube_resolution "flag" before ``ELEMENTS_SINCE``."""
    geometry, solver = data.get("geometry"), data.get("solver", {})
    if (written is None or written >= ELEMENTS_SINCE or not isinstance(geometry, dict) or not isinstance(solver, dict)
            or geometry.get("shape") != Shape.TUBE.value or "tube_resolution" in solver):
        return data
    return {**data, "solver": {**solver, "tube_resolution": "flag"}}


def _check_nesting(data) -> None:
    """SceneError when arrays/tables nest deeper than MAX_NESTING (a scene needs 3: [[field.coils]] keys)."""
    stack = [(data, 1, "")]
    while stack:
        value, depth, key = stack.pop()
        if depth > MAX_NESTING:
            raise SceneError(f"{key or 'the scene'}: arrays or tables nested deeper than {MAX_NESTING} levels")
        items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
        for k, v in items:
            if isinstance(v, (dict, list)):
                stack.append((v, depth + 1, key or str(k)))


def _build(data: dict, name: str, text: str) -> Scene:
    for key, value in data.items():
        if key not in _TABLES:
            where = f"[{show_key(key)}]: unknown table" if isinstance(value, dict) else \
                f"{show_key(key)} = {show(value)}: unknown top-level key"
            raise SceneError(f"{where}; allowed tables: {', '.join(_TABLES)}")
    if "material" not in data:
        raise SceneError('material: the [material] table is missing (give preset = "NAME", or mu and alpha)')
    material = material_from_table(data["material"])
    field = _field(data.get("field", {}))
    electric = None if "electric" not in data else _electric(data["electric"])
    loading_table, continuation_table = moved_stop_volume(data.get("loading", {}), data.get("continuation", {}))
    loading = loading_from_table(loading_table)
    continuation = _continuation(continuation_table, field, electric)
    if loading.control != Control.PRESSURE and continuation.parameter == ContinuationParameter.VOLTAGE:
        raise SceneError(f'loading.control = "{loading.control.value}": a voltage continuation '
                         '(continuation.parameter = "voltage") is at fixed pressure; allowed: "pressure"')
    output = _output(data.get("output", {}))
    _check_products(continuation, output)
    geometry = _geometry(data.get("geometry", {}), field)
    dynamics = _dynamics(data.get("dynamics", {}))
    solver = _solver(data.get("solver", {}))
    if geometry.shape != Shape.TUBE and solver.tube_resolution != Solver.tube_resolution:
        raise SceneError(f'solver.tube_resolution = "{solver.tube_resolution}": only for geometry.shape = "tube" (the '
                         "other shapes' branches are always refined to solver.max_error)")
    if geometry.shape == Shape.TUBE and dynamics.modes:
        raise SceneError("dynamics.modes = true: a tube's mode shapes are not stored yet; allowed: false")
    events = events_from_list(data.get("events", []))
    check_on_shape(events, geometry.shape, geometry.ends, geometry.axial_stretch is not None)
    stability = _stability(data.get("stability", {}))
    if geometry.shape == Shape.TUBE and continuation.parameter == ContinuationParameter.VOLTAGE:
        _tube_voltage_reads(field, stability, dynamics, events)
    surface = _surface(data.get("surface", {}), default_surface(geometry.shape, field, electric, stability))
    return Scene(
        name=name,
        material=material,
        field=field,
        continuation=continuation,
        solver=solver,
        stability=stability,
        output=output,
        electric=electric,
        text=text,
        loading=loading,
        surface=surface,
        events=events,
        geometry=geometry,
        dynamics=dynamics,
    )


def _stop_volume_above_reference(stop_volume: float | None, geometry: Geometry) -> None:
    """SceneError for a continuation.stop_volume at or below the reference volume (a stop that ends the branch at its
    start: V/R0³ given as V/V0)."""
    v0 = geometry.reference_volume
    if stop_volume is not None and stop_volume <= v0:
        raise SceneError(f"continuation.stop_volume = {show(stop_volume)}: at or below the reference volume {v0:g} "
                         f"(the {geometry.describe()}; V/R0³, not V/V0); must be > {v0:g}")


def _tube_voltage_reads(field, stability, dynamics, events) -> None:
    """SceneError for what a tube's voltage continuation (tube/voltage.py) does not read yet: coils, the m ≥ 1 blocks,
    natural frequencies, user events (one line naming the key and what is allowed)."""
    what = "a tube's voltage continuation (continuation.parameter = \"voltage\") reads"
    if field.M > 0 and field.coils:
        raise SceneError(f"field.M = {field.M:g}: {what} no coil field yet; allowed: 0")
    if stability.m_max != 0:
        raise SceneError(f"stability.m_max = {stability.m_max}: {what} the m = 0 stability only for now; allowed: 0")
    if dynamics.frequencies:
        raise SceneError(f"dynamics.frequencies = true: {what} no natural frequencies yet; allowed: false")
    if events:
        raise SceneError(f"events: {len(events)} [[events]]: {what} no user points yet; allowed: none")


def _getter(data: dict, prefix: str, cls):
    """get(key, ok, allowed, integer=False): the checked number at ``prefix.key``; missing or None: cls's default."""

    def get(key, ok, allowed, integer=False):
        raw = data.get(key)
        raw = getattr(cls, key) if raw is None else raw
        if raw is None:
            return None
        x = number(f"{prefix}.{key}", raw, integer=integer, allowed=allowed)
        if not ok(x):
            raise SceneError(f"{prefix}.{key} = {show(raw)}: must be {allowed}")
        return x

    return get


def _keys(cls) -> tuple[str, ...]:
    return tuple(f.name for f in fields(cls))


def _field(data) -> Field:
    data = table("field", data, _keys(Field))
    get = _getter(data, "field", Field)
    chi = get("chi", lambda x: 0 <= x <= MAX_CHI, f"in [0, {MAX_CHI:g}]")
    M = get("M", lambda x: 0 <= x <= MAX_M, f"in [0, {MAX_M:g}]")
    coils = data.get("coils")
    coils = [] if coils is None else coils
    if not isinstance(coils, list):
        raise SceneError(f"field.coils = {show(coils)}: must be an array of tables [[field.coils]]")
    if len(coils) > MAX_COILS:
        raise SceneError(f"field.coils: {len(coils)} coils; at most {MAX_COILS}")
    coils = tuple(_coil(f"field.coils[{i}]", c) for i, c in enumerate(coils))
    if M > 0 and not coils:
        raise SceneError(f"field.M = {show(data['M'])} needs at least one [[field.coils]]")
    seen = {}
    for i, c in enumerate(coils):
        j = seen.setdefault((c.radius, c.centre, max(c.normal, tuple(-x for x in c.normal))), i)
        if j != i:
            same = f"radius = {show(c.radius)} and height = {show(c.height)}" if c.is_coaxial else \
                f"radius = {show(c.radius)}, centre = {show(c.centre)} and normal = ±{show(c.normal)}"
            raise SceneError(f"field.coils[{i}]: same {same} as field.coils[{j}]: coils must be distinct (merge "
                             "their currents)")
    return Field(chi, M, coils)


COIL_KEYS = ("radius", "height", "centre", "normal", "current")


def _coil(key: str, data) -> Coil:
    """A [[field.coils]] table: radius, current and the loop's place, either ``height`` h (centre (0, 0, h)) or
    ``centre`` = [x, y, z], with ``normal`` = [nx, ny, nz] (default e_z; normalised). The wire must lie outside
    the undeformed unit sphere: its closest approach to the centre, √((|c − (c·n) n| − a)² + (c·n)²), exceeds 1."""
    data = table(key, data, COIL_KEYS)
    for k in ("radius", "current"):
        if data.get(k) is None:
            raise SceneError(f"{key}.{k} is missing: each coil needs radius, current, and height or centre")
    if (data.get("height") is None) == (data.get("centre") is None):
        given = "neither" if data.get("height") is None else \
            f"both height = {show(data['height'])} and centre = {show(data['centre'])}"
        raise SceneError(f"{key}: {given} given: place the loop by one of height (centre = [0, 0, height]) or "
                         "centre = [x, y, z]")
    a = number(f"{key}.radius", data["radius"])
    if not 0 < a <= MAX_COIL_DISTANCE:
        raise SceneError(f"{key}.radius = {show(data['radius'])}: must be in (0, {MAX_COIL_DISTANCE:g}]")
    if data.get("height") is not None:
        h = number(f"{key}.height", data["height"])
        if not abs(h) <= MAX_COIL_DISTANCE:
            raise SceneError(f"{key}.height = {show(data['height'])}: must be in [-{MAX_COIL_DISTANCE:g}, "
                             f"{MAX_COIL_DISTANCE:g}]")
        centre = (0.0, 0.0, h)
    else:
        centre = _vector(f"{key}.centre", data["centre"])
        if not max(map(abs, centre)) <= MAX_COIL_DISTANCE:
            raise SceneError(f"{key}.centre = {show(data['centre'])}: each entry must be within "
                             f"±{MAX_COIL_DISTANCE:g}")
    normal = (0.0, 0.0, 1.0) if data.get("normal") is None else _unit(f"{key}.normal", data["normal"])
    s = number(f"{key}.current", data["current"])
    if s == 0 or abs(s) > MAX_CURRENT:
        raise SceneError(f"{key}.current = {show(data['current'])}: must be nonzero and within ±{MAX_CURRENT:g}")
    if centre[:2] == (0.0, 0.0) and normal == (0.0, 0.0, -1.0):  # the coaxial loop with the current reversed
        normal, s = (0.0, 0.0, 1.0), -s
    coil = Coil(a, s, centre, normal)
    axial = sum(c * n for c, n in zip(centre, normal))
    off_axis = math.dist(centre, [axial * n for n in normal])
    d2 = (off_axis - a) ** 2 + axial**2
    if d2 <= 1 + 1e-9:
        where = "on" if d2 >= 1 - 1e-9 else "inside"
        rule = "a² + h²" if coil.is_coaxial else "(|c − (c·n) n| − a)² + (c·n)²"
        raise SceneError(f"{key}: wire at distance {math.sqrt(d2):.6g} from the centre lies {where} the undeformed "
                         f"membrane ({rule} must be > 1)")
    return coil


def _vector(key: str, raw) -> tuple[float, float, float]:
    """``raw`` as 3 checked numbers."""
    if not isinstance(raw, list) or len(raw) != 3:
        raise SceneError(f"{key} = {show(raw)}: must be 3 numbers [x, y, z]")
    return tuple(number(f"{key}[{i}]", x) for i, x in enumerate(raw))


def _unit(key: str, raw) -> tuple[float, float, float]:
    """``raw`` as a unit vector: divided by its length (kept as written when that is 1 to rounding, so that a scene
    written back reads the same); a zero length is refused."""
    vector = _vector(key, raw)
    length = math.hypot(*vector)
    if length == 0:
        raise SceneError(f"{key} = {show(raw)}: must have a nonzero length (the direction of the loop's axis)")
    return vector if abs(length - 1.0) <= 1e-15 else tuple(x / length for x in vector)


def _electric(data) -> Electric:
    get = _getter(table("electric", data, _keys(Electric)), "electric", Electric)
    return Electric(get("voltage", lambda x: 0 <= x <= MAX_VOLTAGE, f"in [0, {MAX_VOLTAGE:g}]"))


def _geometry(data, field: Field) -> Geometry:
    """[geometry]: the shape, a spheroid's aspect, a tube's length and ends; the parts of the model that are written
    for the sphere alone (the whole-sphere engine of coils off the axis) refuse other shapes here."""
    data = table("geometry", data, _keys(Geometry) + ("axial",))
    raw = data.get("shape")
    raw = Geometry.shape.value if raw is None else raw
    if raw not in tuple(Shape):
        raise SceneError(f"geometry.shape = {show(raw)}: must be one of " + ", ".join(f'"{s.value}"' for s in Shape))
    shape = Shape(raw)
    for key in ("ends", "axial", "axial_stretch"):
        if shape != Shape.TUBE and data.get(key) is not None:
            raise SceneError(f'geometry.{key} = {show(data[key])}: only for geometry.shape = "tube"')
    for key in ("element_length", "element_degrees"):
        if shape != Shape.CAPSULE and data.get(key) is not None:
            raise SceneError(f'geometry.{key} = {show(data[key])}: only for geometry.shape = "capsule"')
    if shape not in (Shape.TUBE, Shape.CAPSULE) and data.get("length") is not None:
        raise SceneError(f'geometry.length = {show(data["length"])}: only for geometry.shape = "tube" or "capsule"')
    if shape == Shape.TUBE:
        return _tube(data, field)
    if shape == Shape.CAPSULE:
        return _capsule(data, field)
    if shape == Shape.SPHERE:
        if data.get("aspect") is not None and data["aspect"] != 1:
            raise SceneError(f'geometry.aspect = {show(data["aspect"])}: only for geometry.shape = "spheroid" (the '
                             "sphere's is 1)")
        return Geometry()
    aspect = _getter(data, "geometry", Geometry)("aspect", lambda x: MIN_ASPECT <= x <= MAX_ASPECT,
                                                  f"in [{MIN_ASPECT:g}, {MAX_ASPECT:g}]")
    where = f'geometry.shape = "{shape.value}"'
    _coaxial_outside(where, field, lambda coil: coil.radius**2 + (coil.height / aspect) ** 2,
                     f"the reference spheroid of aspect {aspect:g} (radius² + (height/aspect)²")
    return Geometry(shape, aspect)


def _coaxial_outside(where: str, field: Field, measure, what: str):
    """The coils of a shape other than the sphere: coaxial (off the axis the whole sphere traces them, whose
    reference is spherical), each wire outside the reference surface (``measure``(coil) > 1, ``what`` names the
    surface and the measure), refused one line each."""
    if not field.is_axisymmetric:
        raise SceneError(f"{where}: coils off the axis are traced on the whole sphere, which has a spherical "
                         'reference only; use coaxial coils or geometry.shape = "sphere"')
    for k, coil in enumerate(field.coils):
        inside = measure(coil)
        if inside <= 1 + 1e-9:
            raise SceneError(f"field.coils[{k}]: wire at (radius {show(coil.radius)}, height {show(coil.height)}) lies "
                             f"inside {what} = {inside:.6g} must be > 1)")


def _length(data, shape: Shape, low: float) -> float:
    """geometry.length of a tube or a capsule, in [low, MAX_LENGTH] (geometry.aspect is a spheroid's)."""
    if data.get("aspect") is not None:
        raise SceneError(f'geometry.aspect = {show(data["aspect"])}: only for geometry.shape = "spheroid" (a '
                         f"{shape.value} has geometry.length)")
    if data.get("length") is None:
        raise SceneError(f"geometry.length: missing; a {shape.value} needs its length in reference radii, in "
                         f"[{low:g}, {MAX_LENGTH:g}]")
    return _getter(data, "geometry", Geometry)("length", lambda x: low <= x <= MAX_LENGTH,
                                                f"in [{low:g}, {MAX_LENGTH:g}]")


def _capsule(data, field: Field) -> Geometry:
    """A capsule's [geometry] (its cylinder's length, 0 the sphere, and its longest cylinder element), its coils
    (coaxial, outside it) and the parts of the model it does not have yet, refused one line each."""
    length = _length(data, Shape.CAPSULE, 0.0)
    element = None
    if data.get("element_length") is not None:
        low = max(MIN_ELEMENT, length / MAX_ELEMENTS)
        element = _getter(data, "geometry", Geometry)("element_length", lambda x: low <= x <= MAX_LENGTH,
                                                       f"in [{low:g}, {MAX_LENGTH:g}] (at most {MAX_ELEMENTS} "
                                                       f"elements on the cylinder of length {length:g})")
    graded = data.get("element_degrees")
    if graded not in (None, GRADED):
        raise SceneError(f'geometry.element_degrees = {show(graded)}: must be "{GRADED}" (a degree per element, '
                         "each from its own tail) or left out (one degree shared by every element)")
    _coaxial_outside('geometry.shape = "capsule"', field,
                     lambda coil: coil.radius**2 + max(abs(coil.height) - length / 2, 0.0) ** 2,
                     f"the reference capsule of length {length:g} (radius² + (|height| − length/2)₊²")
    return Geometry(Shape.CAPSULE, length=length, element_length=element, element_degrees=graded)


def _tube(data, field: Field) -> Geometry:
    """A tube's [geometry] (length, ends, axial_stretch) and the parts of the model a tube does not have yet,
    refused one line each."""
    length = _length(data, Shape.TUBE, MIN_LENGTH)
    raw = Ends.SLIDING.value if data.get("ends") is None else data["ends"]
    if raw not in tuple(Ends):
        raise SceneError(f"geometry.ends = {show(raw)}: must be one of " + ", ".join(f'"{e.value}"' for e in Ends))
    held = _getter(data, "geometry", Geometry)("axial_stretch", lambda x: MIN_AXIAL <= x <= MAX_AXIAL,
                                                f"in [{MIN_AXIAL:g}, {MAX_AXIAL:g}]")
    _axial(data.get("axial"), held)
    where = 'geometry.shape = "tube"'
    if field.coils and not field.is_equator_symmetric:
        raise SceneError(f"{where}: the coils around a tube must be coaxial and mirror-symmetric about its middle "
                         "(z = 0: each coil (radius, height, current) with a partner at -height, one current sign "
                         "for every pair), as the tube's branches keep that symmetry")
    for k, coil in enumerate(field.coils):
        if coil.radius <= 1 + 1e-9 and abs(coil.height) <= length / 2:
            raise SceneError(f"field.coils[{k}]: wire at (radius {coil.radius:g}, height {coil.height:g}) lies on "
                             f"or inside the reference tube (radius 1, heights within ±length/2 = "
                             f"±{length / 2:g}); the radius must be > 1 there")
    return Geometry(Shape.TUBE, length=length, ends=Ends(raw), axial_stretch=held)


def _axial(raw, held: float | None):
    """geometry.axial: "closed" (the ends' distance free, the default) spelled out; the ends held apart are
    written ``axial_stretch = λ`` alone, so the two together are refused, one line."""
    if raw is None:
        return
    if raw != CLOSED:
        raise SceneError(f'geometry.axial = {show(raw)}: must be "{CLOSED}" (the ends\' distance free); ends held '
                         "apart are written geometry.axial_stretch = λ alone")
    if held is not None:
        raise SceneError(f'geometry.axial = "{CLOSED}" with geometry.axial_stretch = {held:g}: give one (closed: the '
                         "ends' distance free; axial_stretch: the ends held at λL)")


def _parameter(data, electric: Electric | None):
    """(parameter, fixed pressure, stop_voltage) of [continuation], checked against [electric]."""
    raw = data.get("parameter")
    raw = ContinuationParameter.PRESSURE.value if raw is None else raw
    allowed = ", ".join(f'"{p.value}"' for p in ContinuationParameter)
    if raw not in tuple(ContinuationParameter):
        raise SceneError(f"continuation.parameter = {show(raw)}: must be one of {allowed}")
    parameter = ContinuationParameter(raw)
    get = _getter(data, "continuation", Continuation)
    if parameter == ContinuationParameter.PRESSURE:
        for key in ("pressure", "stop_voltage"):
            if data.get(key) is not None:
                raise SceneError(f'continuation.{key} = {show(data[key])}: only for continuation.parameter = "voltage"')
        return parameter, None, None
    if electric is None:
        raise SceneError('continuation.parameter = "voltage": needs an [electric] table (the dielectric term)')
    if electric.voltage != 0:
        raise SceneError(f"electric.voltage = {show(electric.voltage)}: a voltage continuation starts at the "
                         "sphere's voltage at continuation.start_stretch; leave electric.voltage out")
    pressure = get("pressure", lambda x: x >= 0, ">= 0")
    return parameter, 0.0 if pressure is None else pressure, get("stop_voltage", lambda x: 0 < x <= MAX_VOLTAGE,
                                                                 f"in (0, {MAX_VOLTAGE:g}]")


def _continuation(data, field: Field, electric: Electric | None = None) -> Continuation:
    data = table("continuation", data, _keys(Continuation))
    get = _getter(data, "continuation", Continuation)
    start = get("start_stretch", lambda x: 1 < x < MAX_STRETCH, f"in (1, {MAX_STRETCH:g})")
    stop = get("stop_stretch", lambda x: start < x <= MAX_STRETCH,
               f"in (continuation.start_stretch = {show(start)}, {MAX_STRETCH:g}]")
    if data.get("min_stretch") is None and start <= Continuation.min_stretch:
        data = {**data, "min_stretch": (1 + start) / 2}  # the default lies below any allowed start_stretch
        get = _getter(data, "continuation", Continuation)
    low = get("min_stretch", lambda x: 1 < x < start, f"in (1, continuation.start_stretch = {show(start)})")
    pressure = get("stop_pressure", lambda x: x > 0, "> 0")
    step_min = get("step_min", lambda x: MIN_STEP <= x <= MAX_STEP, f"in [{MIN_STEP:g}, {MAX_STEP:g}]")
    step_max = get("step_max", lambda x: step_min <= x <= MAX_STEP,
                   f"in [continuation.step_min = {show(step_min)}, {MAX_STEP:g}]")
    step = get(
        "step", lambda x: step_min <= x <= step_max, f"in [step_min, step_max] = [{show(step_min)}, {show(step_max)}]"
    )
    points = get("max_points", lambda n: 1 <= n <= 100_000, "an integer in [1, 100000]", integer=True)
    gap = get("wire_gap", lambda x: 0 < x <= MAX_WIRE_GAP, f"in (0, {MAX_WIRE_GAP:g}]")
    symmetry = data.get("symmetry")
    symmetry = Continuation.symmetry if symmetry is None else symmetry
    if symmetry not in ("auto", "equator", "none"):
        raise SceneError(f'continuation.symmetry = {show(symmetry)}: must be one of "auto", "equator", "none"')
    if symmetry == "equator" and not field.is_equator_symmetric:
        raise SceneError(
            'continuation.symmetry = "equator": the coils are not mirror-symmetric about z = 0 (use "auto" or "none")'
        )
    parameter, fixed_pressure, stop_voltage = _parameter(data, electric)
    stop_field = get("stop_field", lambda x: 0 < x <= MAX_M, f"in (0, {MAX_M:g}]")
    stop_volume = get("stop_volume", lambda x: x > 0, "> 0 (V/R0³)")
    return Continuation(start, stop, low, pressure, step, step_min, step_max, points, symmetry, gap, parameter,
                        fixed_pressure, stop_voltage, stop_field, stop_volume)


def _solver(data) -> Solver:
    data = table("solver", data, _keys(Solver))
    get = _getter(data, "solver", Solver)
    degree = get("degree", lambda n: 8 <= n <= 400, "an integer in [8, 400]", integer=True)
    quadrature = get(
        "quadrature", lambda n: n == 0 or degree + 1 <= n <= MAX_QUADRATURE,
        f"0 (automatic) or an integer in [solver.degree + 1 = {degree + 1}, {MAX_QUADRATURE}]", integer=True,
    )
    tol = get("tol", lambda x: MIN_TOLERANCE <= x <= 1e-3, f"in [{MIN_TOLERANCE:g}, 1e-3]")
    max_newton = get("max_newton", lambda n: 1 <= n <= 200, "an integer in [1, 200]", integer=True)
    if data.get("max_degree") is None and degree > Solver.max_degree:
        data = {**data, "max_degree": degree}  # the default never lies below the starting degree
        get = _getter(data, "solver", Solver)
    max_degree = get("max_degree", lambda n: degree <= n <= 400, f"an integer in [solver.degree = {degree}, 400]",
                     integer=True)
    max_error = get("max_error", lambda x: MIN_TOLERANCE <= x <= 1e-2, f"in [{MIN_TOLERANCE:g}, 1e-2]")
    tube_resolution = data.get("tube_resolution", Solver.tube_resolution)
    if tube_resolution not in TUBE_RESOLUTIONS:
        raise SceneError(f"solver.tube_resolution = {show(tube_resolution)}: must be one of "
                         f"{', '.join(map(repr, TUBE_RESOLUTIONS))}")
    return Solver(degree, quadrature, tol, max_newton, max_degree, max_error, tube_resolution)


def _stability(data) -> Stability:
    data = table("stability", data, _keys(Stability))
    get = _getter(data, "stability", Stability)
    choices = {}
    for key, allowed in (("basis", STABILITY_BASES), ("norm", STABILITY_NORMS)):
        choices[key] = data.get(key, getattr(Stability, key))
        if choices[key] not in allowed:
            raise SceneError(f"stability.{key} = {show(choices[key])}: must be one of "
                             + ", ".join(f'"{b}"' for b in allowed))
    return Stability(
        get("degree", lambda n: 4 <= n <= 200, "an integer in [4, 200]", integer=True),
        get("m_max", lambda n: 0 <= n <= 8, "an integer in [0, 8]", integer=True),
        **choices,
        **{key: get(key, lambda n: n == 0 or 20 <= n <= 400, "0 (off) or an integer in [20, 400]", integer=True)
           for key in ("banded_from", "banded_flags_from")},
    )


def _surface(data, default: Surface) -> Surface:
    data = table("surface", data, _keys(Surface))
    get = _getter(data, "surface", Surface)
    branches = data.get("branches", default.branches)
    if branches not in SURFACE_BRANCHES:
        raise SceneError(f"surface.branches = {show(branches)}: must be one of "
                         + ", ".join(f'"{b}"' for b in SURFACE_BRANCHES))
    return Surface(branches, get("degree", lambda n: 4 <= n <= 48, "an integer in [4, 48]", integer=True),
                   get("max_points", lambda n: 1 <= n <= 10_000, "an integer in [1, 10000]", integer=True))


def _dynamics(data) -> Dynamics:
    data = table("dynamics", data, _keys(Dynamics))
    get = _getter(data, "dynamics", Dynamics)
    switches = {key: data.get(key, getattr(Dynamics, key)) for key in ("frequencies", "modes")}
    for key, wanted in switches.items():
        if not isinstance(wanted, bool):
            raise SceneError(f"dynamics.{key} = {show(wanted)}: must be true or false")
    if switches["modes"] and not switches["frequencies"]:
        raise SceneError("dynamics.modes = true: needs dynamics.frequencies = true (the shapes of those modes)")
    return Dynamics(switches["frequencies"], get("count", lambda n: 1 <= n <= 50, "an integer in [1, 50]", integer=True),
                    get("m_max", lambda n: 0 <= n <= 8, "an integer in [0, 8]", integer=True), switches["modes"])


def _output(data) -> Output:
    get = _getter(table("output", data, _keys(Output)), "output", Output)
    return Output(get("theta_points", lambda n: 3 <= n <= 100_001, "an integer in [3, 100001]", integer=True),
                  get("memory_limit", lambda x: 0 < x <= 1024, "in (0, 1024] GiB"))


def _check_products(continuation: Continuation, output: Output) -> None:
    """SceneError when keys each within their range multiply into more memory than output.memory_limit (GiB):
    a branch's stored profiles are about 2 legs × max_points × theta_points × PROFILE_ARRAYS doubles at once."""
    need = 2 * continuation.max_points * output.theta_points * PROFILE_ARRAYS * 8 / 1024**3
    if need > output.memory_limit:
        raise SceneError(f"continuation.max_points = {continuation.max_points} × output.theta_points = "
                         f"{output.theta_points}: the profiles of one branch would need about {need:.3g} GiB; at "
                         f"most output.memory_limit = {show(output.memory_limit)} GiB (lower either key, or raise "
                         "output.memory_limit if you mean it)")


def _to_toml(data: dict) -> str:
    """TOML for a dict of tables holding scalars, lists and arrays of tables, and top-level arrays of tables
    ([[events]]); None values are left out."""
    lines = []
    for name, content in data.items():
        if isinstance(content, list):
            for item in content:
                lines += [f"[[{name}]]"] + [f"{k} = {show(v)}" for k, v in item.items()] + [""]
            continue
        arrays = {k: v for k, v in content.items() if isinstance(v, list) and v and isinstance(v[0], dict)}
        lines.append(f"[{name}]")
        lines += [f"{k} = {show(v)}" for k, v in content.items() if v is not None and k not in arrays]
        for k, items in arrays.items():
            for item in items:
                lines += ["", f"[[{name}.{k}]]"] + [f"{kk} = {show(vv)}" for kk, vv in item.items()]
        lines.append("")
    return "\n".join(lines)


_PARAMETER_KEY = re.compile(r"material\.parameters\.(\w+)")
_OVERRIDE_KEY = re.compile(r"(\w+)\.(\w+)(?:\[(\d+)\]\.(\w+))?")
_ARRAY_KEY = re.compile(r"(events)\[(\d+)\]\.(\w+)")  # the top-level arrays of tables


def _assign_alpha1(material: dict, value) -> None:
    """``alpha1 = value`` in a material table: α1 replaced, μ1 = (4 − Σ_{i≥2} μ_i α_i)/α1 (``alpha1_terms``)."""
    if not isinstance(material.get("alpha"), list):
        raise SceneError(f"{ALPHA1} = {show(value)}: the first Ogden exponent (with μ1 keeping Σ μ_i α_i = 4); the "
                         f"material is not an Ogden material (vary its material.parameters.NAME instead)")
    if value is None:
        raise SceneError(f"{ALPHA1}: has no default to restore (--unset material.preset or set material.alpha)")
    alpha1 = number(ALPHA1, value)
    if alpha1 == 0 or abs(alpha1) > MAX_EXPONENT:
        raise SceneError(f"{ALPHA1} = {show(value)}: exponents must be nonzero and within ±{MAX_EXPONENT:g}")
    mu, alpha = alpha1_terms(material["mu"], material["alpha"], alpha1)
    material["mu"], material["alpha"] = list(mu), list(alpha)


def _assign(data: dict, key: str, value) -> None:
    """Set the dotted override ``key`` in a scene dict (numpy values become plain Python ones)."""
    value = value.tolist() if hasattr(value, "tolist") else value
    if key == ALPHA1:
        _assign_alpha1(data.get("material", {}), value)
        return
    parameter = _PARAMETER_KEY.fullmatch(key)
    if parameter is not None:  # a strain energy's parameter (scene/energies.py)
        parameters = data.get("material", {}).get("parameters", {})
        if parameter.group(1) not in parameters:
            raise SceneError(f"{key} = {show(value)}: the material has no parameter {parameter.group(1)!r} "
                             f"(it has: {', '.join(parameters) or 'none'})")
        parameters[parameter.group(1)] = value
        return
    element = _ARRAY_KEY.fullmatch(key)
    if element is not None:  # an entry of a top-level array of tables: events[0].value
        name, index, sub = element.groups()
        items = data.get(name)
        if not isinstance(items, list) or int(index) >= len(items):
            raise SceneError(f"{key} = {show(value)}: there is no {name}[{index}]")
        items[int(index)][sub] = value
        return
    match = _OVERRIDE_KEY.fullmatch(key)
    if match is None:
        raise SceneError(f"{key} = {show(value)}: not a scene key (e.g. field.M or field.coils[0].current)")
    tab, k, index, sub = match.groups()
    if index is None:
        if (tab, k) == ("material", "preset"):
            data[tab] = {"preset": value}
        else:
            data.setdefault(tab, {})[k] = value
        return
    items = data.get(tab, {}).get(k)
    if not isinstance(items, list) or int(index) >= len(items):
        raise SceneError(f"{key} = {show(value)}: there is no {tab}.{k}[{index}]")
    items[int(index)][sub] = value
