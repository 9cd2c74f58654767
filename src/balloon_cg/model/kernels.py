"""Pick and call the generated kernel module for a scene class (Ogden exponents, field or not).

A material whose exponents match a generated class uses it (exponents baked in); any other material uses the
general class with runtime exponents, its unused terms padded with μ = 0. A strain energy (scene/energies.py)
uses its family's committed class or, for a user formula, the on-demand cache; its parameters are the
``material`` argument.

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

from . import kernel_cache
from .compile_notice import announce_first_use
from .. import generated
from ..scene.energies import StrainEnergy
from ..scene.validation import SceneError


def class_name(alpha, has_field: bool) -> str:
    """The generated module for these exponents: exact match first, else the general class."""
    for name, (alphas, field) in generated.CLASSES.items():
        if alphas is not None and field == has_field and len(alphas) == len(alpha) and all(
            abs(a - b) <= 1e-12 * max(1.0, abs(a)) for a, b in zip(alphas, alpha)
        ):
            return name
    if len(alpha) > generated.GENERAL_TERMS:
        raise SceneError(
            f"material.alpha: {len(alpha)} terms with exponents {tuple(alpha)} match no generated class and the "
            f"general class takes at most {generated.GENERAL_TERMS}; add the exponents to codegen/classes.py and "
            "run `make regenerate`"
        )
    return "ogden_general_field"


class KernelSet:
    """The kernels of one scene: module, packed material parameters and the call conventions.

    ``kernel_class`` forces a generated class by name (benchmarks: the general class on a preset material);
    it must be the general class or one whose exponents match the material, and a field class when
    ``has_field``.
    """

    @classmethod
    def of_scene(cls, scene, kernel_class: str | None = None) -> "KernelSet":
        """The kernels of a scene's class: its material, with the field terms if it has coils, with the dielectric
        term if it has an [electric] table."""
        return cls(scene.material, has_field=bool(scene.field.coils), kernel_class=kernel_class,
                   electric=scene.electric is not None)

    def __init__(self, material, has_field: bool, kernel_class: str | None = None, electric: bool = False):
        """``electric``: the class with the dielectric term (generated on demand, model/kernel_cache.py)."""
        self.has_field, self.electric = has_field, electric
        self.scene_material = material
        self._binders, self._node_kernels = {}, {}
        if isinstance(material, StrainEnergy):
            if kernel_class is not None:
                raise SceneError(f"kernel class {kernel_class!r}: only Ogden materials choose a kernel class")
            self.module = energy_module(material, has_field, electric)
            self.name, self.general, self.field_class = dict(self.module.INPUTS)["class"], False, has_field
            self._scene_arrays = {"material": _frozen(material.values)}
            announce_first_use(self.module)
            return
        # the committed class of these exponents (its dielectric twin, if asked for, is generated from it)
        self.exponent_class = class_name(material.alpha, has_field) if kernel_class is None else kernel_class
        if kernel_class is not None:
            if kernel_class not in generated.CLASSES:
                known = ", ".join(generated.CLASSES)
                raise SceneError(f"kernel class {kernel_class!r}: not generated; known: {known}")
            alphas, field = generated.CLASSES[kernel_class]
            if (has_field and not field) or (alphas is not None and class_name(material.alpha, field) != kernel_class):
                raise SceneError(f"kernel class {kernel_class!r} does not fit material exponents "
                                 f"{tuple(material.alpha)} (field {has_field})")
        self.module = importlib.import_module(f"{generated.__name__}.{self.exponent_class}")
        self.general = generated.CLASSES[self.exponent_class][0] is None
        # a field class evaluated at M = 0 is the "field on, M = 0" general setting of the benchmarks
        self.field_class = generated.CLASSES[self.exponent_class][1]
        if electric:
            self.module = kernel_cache.load(exponents_of(self.module), self.field_class, electric=True)
        self.name = dict(self.module.INPUTS)["class"]
        self._scene_arrays = self._pack(tuple(material.mu), tuple(material.alpha))
        announce_first_use(self.module)

    def surface(self) -> "KernelSet":
        """The surface kernels (MODEL.md §8; codegen/surface.py) of the same class and material packing: a committed
        class's ``generated.surface_<class>``, or for a user formula and every dielectric class the on-demand
        module (model/kernel_cache.py, ``surface=True``)."""
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
            if class_name(alpha, self.field_class) != self.exponent_class:
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


def exponents_of(module) -> kernel_cache.Exponents:
    """The exponents a committed Ogden class module was generated from (its INPUTS), as the cache describes them."""
    alphas = dict(module.INPUTS)["alphas"]
    return kernel_cache.Exponents(None if alphas == "runtime" else alphas)


def dielectric_source(material, has_field: bool):
    """What a material's dielectric class is generated from (model/kernel_cache.py): a strain energy's formula,
    or the exponents of the committed Ogden class the material's exponents select."""
    if isinstance(material, StrainEnergy):
        return material.formula
    return exponents_of(importlib.import_module(f"{generated.__name__}.{class_name(material.alpha, has_field)}"))


def energy_module(material: StrainEnergy, has_field: bool, electric: bool = False):
    """The kernel module of a strain energy: a family's committed one (its formula must be the one generated),
    or a user formula's or any dielectric class's from the on-demand cache (model/kernel_cache.py)."""
    if material.family is None or electric:
        return kernel_cache.load(material.formula, has_field, electric=electric)
    name = f"{material.family}_field" if has_field else material.family
    formula, _ = generated.ENERGY_CLASSES[name]
    if formula != material.formula.text:
        raise ImportError(f"generated/{name}.py is for the formula {formula!r}, the scene layer's family "
                          f"{material.family} is {material.formula.text!r}: run `make regenerate`")
    return importlib.import_module(f"{generated.__name__}.{name}")


def surface_module(kernels: KernelSet):
    """The surface kernel module of a kernel set's class: committed (generated.SURFACE_CLASSES) unless the class
    is generated on demand (a user formula, the dielectric term)."""
    material = kernels.scene_material
    if kernels.electric or (isinstance(material, StrainEnergy) and material.family is None):
        source = material.formula if isinstance(material, StrainEnergy) else exponents_of(kernels.module)
        return kernel_cache.load(source, kernels.field_class, electric=kernels.electric, surface=True)
    return importlib.import_module(f"{generated.__name__}.{generated.SURFACE_CLASSES[kernels.name]}")


def _frozen(values) -> np.ndarray:
    """A read-only float array: the kernels' material arguments are never changed in place."""
    array = np.array(values, dtype=float)
    array.flags.writeable = False
    return array


@cache
def generated_digest() -> str:
    """SHA-256 over the signatures of every generated module (stored as provenance): each class, its whole-sphere
    module, the coil field; read from the modules' text: importing all of them would build every numba dispatcher
    of every class (~0.2 s at start-up)."""
    names = sorted(generated.CLASSES) + sorted(generated.SURFACE_CLASSES.values()) + ["coil_field"]
    return hashlib.sha256("".join(map(module_signature, names)).encode()).hexdigest()


def module_signature(name: str) -> str:
    """The ``SIGNATURE = "…"`` line of generated module ``name`` (codegen/emit.py prints it), without importing it."""
    text = resources.files(generated).joinpath(f"{name}.py").read_text(encoding="utf-8")
    found = _SIGNATURE.search(text)
    if found is None:
        raise ImportError(f"{generated.__name__}.{name} has no SIGNATURE line: run `make regenerate`")
    return found[1]


_SIGNATURE = re.compile(r'^SIGNATURE = "([0-9a-f]{64})"$', re.MULTILINE)
