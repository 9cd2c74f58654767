"""Pick and call the generated kernel module for a scene class: its material and its energy terms by name
(``scene_terms``: the pressure, the magnetic term with coils, the dielectric term with a voltage).

A material whose exponents match a generated class uses it (exponents baked in); any other material uses the
general class with runtime exponents, its unused terms padded with μ = 0. A strain energy (scene/energies.py)
uses its family's committed class or, for a user formula, the on-demand cache; its parameters are the
``material`` argument. The committed module is the one with the fewest terms that include the scene's (the
registry generated.CLASSES lists each module's terms); a term set no committed module covers (the dielectric
term) is generated on demand from the same exponents or formula (model/kernel_cache.py), and so is every class of a
reference shape other than the sphere (scene.Geometry; its scalars, the spheroid's aspect, are bound from it).

Calling convention: every generated module lists, in ``KERNELS``, each kernel's arguments as (name, kind,
rows) and its output labels (codegen/kernels.py: convention). ``KernelSet.arguments`` is the one place that
turns named values into an argument tuple, so no caller knows the argument order:

- 'node' and 'node_rows' arguments (cos_theta, lam2, …; field) and 'param' scalars (P, M, chi, voltage, m) are
  the values of the same name;
- μ and α are the material's (padded for the general class), or the overrides ``mu``/``alpha`` when given; a
  strain energy's ``material`` array is its parameter values, or the override ``Parameters.material``;
- ``pole_field`` rows 'NAME_N' / 'NAME_S' are the FIELD_ROWS entry NAME of ``field_north`` / ``field_south``.
"""
import copy
import hashlib
import importlib
import operator
import re
from functools import cache, cached_property
from importlib import resources

import numpy as np

from . import compile_lock, kernel_cache
from .compile_notice import announce_first_use
from .. import generated
from . import meridian
from ..scene.energies import StrainEnergy
from ..scene.tables import Geometry, Shape
from ..scene.validation import SceneError


compile_lock.install()  # before any kernel runs (a computation picks its kernel set first): compiled once across processes
PLAIN = ("pressure",)  # the terms of a class without coils or voltage


def scene_terms(scene) -> tuple:
    """The energy terms of a scene's class beyond the elastic one, by name (codegen/terms/), in kernel order: the
    pressure always, the magnetic term with coils, the dielectric term with an [electric] table."""
    present = {"pressure": True, "magnetic": bool(scene.field.coils), "dielectric": scene.electric is not None}
    return tuple(name for name, on in present.items() if on)


def _same_exponents(alphas, alpha) -> bool:
    return len(alphas) == len(alpha) and all(abs(a - b) <= 1e-12 * max(1.0, abs(a)) for a, b in zip(alphas, alpha))


def committed_class(registry: dict, identity, terms: tuple) -> str | None:
    """The committed module of ``registry`` (generated.CLASSES or ENERGY_CLASSES: name -> (identity, term names))
    for ``identity`` (exponents, None for the general class, or a canonical formula) whose terms are the fewest
    that include ``terms`` (a term a scene lacks is evaluated at zero: M = 0, no field rows); None: the class is
    generated on demand (model/kernel_cache.py)."""
    fits = [(len(names), name) for name, (ident, names) in registry.items()
            if set(terms) <= set(names) and (ident == identity if identity is None or isinstance(identity, str)
                                              else ident is not None and _same_exponents(ident, identity))]
    return min(fits)[1] if fits else None


def exponent_class(alpha) -> str:
    """A committed Ogden module of these exponents (the one with the fewest terms), else the general class."""
    name = committed_class(generated.CLASSES, tuple(alpha), PLAIN)
    if name is not None:
        return name
    if len(alpha) > generated.GENERAL_TERMS:
        raise SceneError(
            f"material.alpha: {len(alpha)} terms with exponents {tuple(alpha)} match no generated class and the "
            f"general class takes at most {generated.GENERAL_TERMS}; add the exponents to codegen/classes.py and "
            "run `make regenerate`"
        )
    return committed_class(generated.CLASSES, None, PLAIN)


def class_source(material, terms: tuple = PLAIN, kernel_class: str | None = None, shape: Shape = Shape.SPHERE):
    """(committed module name or None, what an on-demand class is generated from: a scene/formula.Formula or
    kernel_cache.Exponents, or None) of a material with ``terms``; ``kernel_class`` forces a committed Ogden class
    (it must include the terms and fit the exponents). Classes are committed for the sphere only: another
    ``shape`` is generated on demand from the sphere's class's material."""
    if shape != Shape.SPHERE:
        if kernel_class is not None:
            raise SceneError(f"kernel class {kernel_class!r}: committed classes have a spherical reference, the scene "
                             f"is a {shape.value}")
        name, source = class_source(material, terms)
        return None, source if name is None else _source_of(name, material)
    if isinstance(material, StrainEnergy):
        if kernel_class is not None:
            raise SceneError(f"kernel class {kernel_class!r}: only Ogden materials choose a kernel class")
        if material.family is None:
            return None, material.formula
        formula, _ = generated.ENERGY_CLASSES[material.family]
        if formula != material.formula.text:
            raise ImportError(f"generated/{material.family}.py is for the formula {formula!r}, the scene layer's "
                              f"family {material.family} is {material.formula.text!r}: run `make regenerate`")
        name = committed_class(generated.ENERGY_CLASSES, formula, terms)
        return (name, None) if name is not None else (None, material.formula)
    if kernel_class is not None:
        if kernel_class not in generated.CLASSES:
            known = ", ".join(generated.CLASSES)
            raise SceneError(f"kernel class {kernel_class!r}: not generated; known: {known}")
        alphas, names = generated.CLASSES[kernel_class]
        if not set(terms) <= set(names) or (alphas is not None and not _same_exponents(alphas, material.alpha)):
            raise SceneError(f"kernel class {kernel_class!r} does not fit material exponents "
                             f"{tuple(material.alpha)} (terms {', '.join(terms)})")
        return kernel_class, None
    own = exponent_class(material.alpha)
    alphas = generated.CLASSES[own][0]
    name = committed_class(generated.CLASSES, alphas, terms)
    if name is not None:
        return name, None
    return None, exponents_of(importlib.import_module(f"{generated.__name__}.{own}"))


class KernelSet:
    """The kernels of one scene: module, packed material parameters and the call conventions.

    ``terms``: the energy terms beyond the elastic one, by name (``scene_terms``); the module is the committed class
    with the fewest terms that include them, or one generated on demand for them (model/kernel_cache.py: every
    class with the dielectric term, every user formula). ``kernel_class`` forces a committed Ogden class by name
    (benchmarks: the general class on a preset material).
    """

    @classmethod
    def of_scene(cls, scene, kernel_class: str | None = None) -> "KernelSet":
        """The kernels of a scene's class: its material, its terms (``scene_terms``) and its reference shape."""
        return cls(scene.material, scene_terms(scene), kernel_class=kernel_class, geometry=scene.geometry)

    def __init__(self, material, terms: tuple = PLAIN, kernel_class: str | None = None,
                 geometry: Geometry = Geometry()):
        self.terms = tuple(terms)
        self.scene_material = material
        self.geometry = geometry
        self.shape_values = meridian.kernel_values(geometry)  # the meridian's scalar arguments (aspect)
        self._binders, self._node_kernels = {}, {}
        name, self.source = class_source(material, self.terms, kernel_class, geometry.shape)
        if name is not None:
            self.module = importlib.import_module(f"{generated.__name__}.{name}")
            registry = generated.ENERGY_CLASSES if isinstance(material, StrainEnergy) else generated.CLASSES
            self.class_terms = registry[name][1]
        else:
            self.module = kernel_cache.load(self.source, self.terms, shape=geometry.shape.value)
            self.class_terms = self.terms
        self.name = dict(self.module.INPUTS)["class"]
        if isinstance(material, StrainEnergy):
            self.general = False
            self._scene_arrays = {"material": _frozen(material.values)}
            announce_first_use(self.module)
            return
        alphas = dict(self.module.INPUTS)["alphas"]
        self.exponents = None if alphas == "runtime" else tuple(float(a) for a in alphas)
        self.general = self.exponents is None
        self._scene_arrays = self._pack(tuple(material.mu), tuple(material.alpha))
        announce_first_use(self.module)

    @property
    def field_class(self) -> bool:
        """Whether the module has the magnetic term (it takes field rows; zero without coils)."""
        return "magnetic" in self.class_terms

    @property
    def electric(self) -> bool:
        """Whether the module has the dielectric term (it takes the voltage)."""
        return "dielectric" in self.class_terms

    def surface(self) -> "KernelSet":
        """The surface kernels (MODEL.md §8; codegen/surface.py) of the same class and material packing: a committed
        class's ``generated.surface_<class>``, or for a user formula and every dielectric class the on-demand
        module (model/kernel_cache.py, ``surface=True``)."""
        if self.geometry.shape != Shape.SPHERE:
            raise ValueError(f"the whole-sphere kernels have a spherical reference; this class's is a "
                             f"{self.geometry.shape.value}")
        twin = copy.copy(self)
        twin._binders, twin._node_kernels = {}, {}
        twin.module = surface_module(self)
        twin.__dict__.pop("signature", None)
        announce_first_use(twin.module)
        return twin

    @cached_property
    def signature(self) -> str:
        """Hash of the generated module text (provenance)."""
        return self.module.SIGNATURE

    def material(self, mu=None, alpha=None, values=None) -> dict:
        """{'mu': μ, 'alpha': α} or a strain energy's {'material': values} as the kernels take them (read-only
        arrays); None: the scene material's.

        The general class takes GENERAL_TERMS terms, the unused ones padded with μ = 0, α = 1; a class with
        baked-in exponents takes μ only, and accepts an α override only if it is its own exponents."""
        if mu is None and alpha is None and values is None:
            return self._scene_arrays
        energy = isinstance(self.scene_material, StrainEnergy)
        if energy and mu is None and alpha is None:
            names = self.scene_material.formula.parameters
            if len(values) != len(names):
                raise ValueError(f"{len(values)} parameter values for {self.scene_material.name}'s {len(names)} "
                                 f"({', '.join(names)})")
            return {"material": _frozen(values)}
        if energy or values is not None:
            kind = "moduli/exponents" if energy else "strain-energy parameter"
            raise ValueError(f"{kind} overrides do not apply to the material {self.scene_material.name}")
        return self._pack(tuple(self.scene_material.mu if mu is None else mu),
                          tuple(self.scene_material.alpha if alpha is None else alpha))

    def _pack(self, mu: tuple, alpha: tuple) -> dict:
        if len(mu) != len(alpha):
            raise ValueError(f"{len(mu)} moduli for {len(alpha)} exponents")
        if not self.general:
            if not _same_exponents(self.exponents, alpha):
                raise ValueError(f"exponents {alpha} need the general kernel class, not {self.name}")
            return {"mu": _frozen(mu)}
        pad = generated.GENERAL_TERMS - len(mu)
        return {"mu": _frozen(mu + (0.0,) * pad), "alpha": _frozen(alpha + (1.0,) * pad)}

    def arguments(self, kernel: str, values: dict, params=None) -> tuple:
        """The argument tuple of ``kernel`` from named values (module docstring) and, if given, the branch
        parameters ``params`` (galerkin.equilibrium.Parameters: P, M, χ, Φ̄, μ, α, material); missing names raise
        KeyError."""
        pick, scalars, pole_rows = self._binders.get(kernel) or self._binder(kernel)
        if params is None:
            mu, alpha, energy = values.get("mu"), values.get("alpha"), None
            source = {**values}
        else:
            mu, alpha, energy = params.mu, params.alpha, params.material
            source = {"P": params.P, "M": params.M, "chi": params.chi, "voltage": params.voltage, **values}
        source.update(self.material(mu, alpha, energy))
        source.update(self.shape_values)
        try:
            for name in scalars:
                source[name] = float(source[name])
            if pole_rows:
                source["pole_field"] = self._pole_field(source, pole_rows)
            return pick(source)
        except KeyError as e:
            raise KeyError(f"{kernel}: no value for its argument {e.args[0]!r}") from None

    def _binder(self, kernel: str) -> tuple:
        """(a getter of the argument tuple from a dict of named values, the scalar parameter names, the
        pole-field rows or None) of ``kernel``, read once from KERNELS."""
        spec = self.module.KERNELS[kernel]["args"]
        names = [name for name, _, _ in spec]
        getter = operator.itemgetter(*names)
        pick = getter if len(names) > 1 else (lambda source: (getter(source),))
        scalars = tuple(name for name, kind, _ in spec if kind == "param")
        pole_rows = next((rows for name, _, rows in spec if name == "pole_field"), None)
        self._binders[kernel] = binder = (pick, scalars, pole_rows)
        return binder

    def _pole_field(self, values: dict, rows: tuple) -> np.ndarray:
        """Rows 'NAME_N' / 'NAME_S': entry NAME (of FIELD_ROWS) of values['field_north'] / values['field_south']."""
        at_pole = {"N": values["field_north"], "S": values["field_south"]}
        out = np.empty(len(rows))
        for k, row in enumerate(rows):
            quantity, pole = row.rsplit("_", 1)
            out[k] = at_pole[pole][self.module.FIELD_ROWS.index(quantity)]
        return out

    def call(self, kernel: str, values: dict) -> tuple:
        """``kernel`` at one point (scalar node values)."""
        return getattr(self.module, kernel)(*self.arguments(kernel, values))

    def nodes(self, kernel: str, values: dict, params=None) -> np.ndarray:
        """``kernel`` at every node (node values are arrays): output k (KERNELS[kernel]['outputs']) in row k."""
        function, rows, first_node, axis = self._node_kernels.get(kernel) or self._node_kernel(kernel)
        out = np.empty((rows, values[first_node].shape[axis]))
        function(*self.arguments(kernel, values, params), out)
        return out

    def _node_kernel(self, kernel: str) -> tuple:
        """(the kernel's node loop, its output count, the name of the argument that counts the nodes, its node
        axis), read once: the first 'node' argument, or else (the surface kernels) the columns of the first
        'node_rows' argument, as the node loop counts them (codegen/emit.py: node_count)."""
        spec = self.module.KERNELS[kernel]
        nodes = [(name, 0) for name, kind, _ in spec["args"] if kind == "node"]
        first_node, axis = (nodes or [(name, 1) for name, kind, _ in spec["args"] if kind == "node_rows"])[0]
        entry = (getattr(self.module, f"{kernel}_nodes"), len(spec["outputs"]), first_node, axis)
        self._node_kernels[kernel] = entry
        return entry

    def state(self, state) -> dict:
        """Named values of the state (λ2, v, η, w) in the generated order STATE."""
        return dict(zip(self.module.STATE, state))


def _source_of(name: str, material):
    """What the committed class ``name`` of ``material`` is generated from, to generate it for another shape."""
    if isinstance(material, StrainEnergy):
        return material.formula
    return exponents_of(importlib.import_module(f"{generated.__name__}.{name}"))


def exponents_of(module) -> kernel_cache.Exponents:
    """The exponents a committed Ogden class module was generated from (its INPUTS), as the cache describes them."""
    alphas = dict(module.INPUTS)["alphas"]
    return kernel_cache.Exponents(None if alphas == "runtime" else alphas)


def surface_module(kernels: KernelSet):
    """The surface kernel module of a kernel set's class: the committed one (generated.SURFACE_CLASSES) of a
    committed class, else generated on demand from the same source and terms."""
    if kernels.source is None:
        return importlib.import_module(f"{generated.__name__}.{generated.SURFACE_CLASSES[kernels.name]}")
    return kernel_cache.load(kernels.source, kernels.class_terms, surface=True)


def _frozen(values) -> np.ndarray:
    """A read-only float array: the kernels' material arguments are never changed in place."""
    array = np.array(values, dtype=float)
    array.flags.writeable = False
    return array


@cache
def generated_digest() -> str:
    """SHA-256 over the signatures of every generated module (stored as provenance): each class, its whole-sphere
    module, the coil field, the mass matrices (inertia); read from the modules' text: importing all of them would build
    every numba dispatcher of every class (~0.2 s at start-up)."""
    names = sorted(generated.CLASSES) + sorted(generated.SURFACE_CLASSES.values()) + ["coil_field", "inertia"]
    return hashlib.sha256("".join(map(module_signature, names)).encode()).hexdigest()


def module_signature(name: str) -> str:
    """The ``SIGNATURE = "…"`` line of generated module ``name`` (codegen/emit.py prints it), without importing it."""
    text = resources.files(generated).joinpath(f"{name}.py").read_text(encoding="utf-8")
    found = _SIGNATURE.search(text)
    if found is None:
        raise ImportError(f"{generated.__name__}.{name} has no SIGNATURE line: run `make regenerate`")
    return found[1]


_SIGNATURE = re.compile(r'^SIGNATURE = "([0-9a-f]{64})"$', re.MULTILINE)
