"""Pick and call the generated kernel module for a scene class (Ogden exponents, field or not).

A material whose exponents match a generated class uses it (exponents baked in); any other material uses the
general class with runtime exponents, its unused terms padded with μ = 0.
"""
import hashlib
import importlib
from functools import cached_property

import numpy as np

from .. import generated
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

    def __init__(self, material, has_field: bool, kernel_class: str | None = None):
        self.has_field = has_field
        self.name = class_name(material.alpha, has_field) if kernel_class is None else kernel_class
        if kernel_class is not None:
            if kernel_class not in generated.CLASSES:
                known = ", ".join(generated.CLASSES)
                raise SceneError(f"kernel class {kernel_class!r}: not generated; known: {known}")
            alphas, field = generated.CLASSES[kernel_class]
            if (has_field and not field) or (alphas is not None and class_name(material.alpha, field) != kernel_class):
                raise SceneError(f"kernel class {kernel_class!r} does not fit material exponents "
                                 f"{tuple(material.alpha)} (field {has_field})")
        self.module = importlib.import_module(f"{generated.__name__}.{self.name}")
        self.general = generated.CLASSES[self.name][0] is None
        if self.general:
            pad = generated.GENERAL_TERMS - len(material.mu)
            self.mu = np.array(list(material.mu) + [0.0] * pad)
            self.alpha = np.array(list(material.alpha) + [1.0] * pad)
        else:
            self.mu = np.array(material.mu, dtype=float)
        # a field class evaluated at M = 0 is the "field on, M = 0" general setting of the benchmarks
        self.field_class = generated.CLASSES[self.name][1]

    @cached_property
    def signature(self) -> str:
        """Hash of the generated module text (provenance)."""
        return self.module.SIGNATURE

    def params(self, P: float, M: float, chi: float) -> tuple:
        """Branch parameters in the order the generated kernels take them."""
        args = (float(P),) + ((float(M), float(chi)) if self.field_class else ())
        args += (self.mu,) + ((self.alpha,) if self.general else ())
        return args

    def nodes(self, kernel: str, geometry: tuple, state: tuple, params: tuple, field, rows: int) -> np.ndarray:
        """Run ``kernel`` at every node: geometry (θ-dependent arrays), state (λ2, v, η, w), field rows."""
        out = np.empty((rows, state[0].shape[0]))
        extra = (field,) if self.field_class else ()
        getattr(self.module, f"{kernel}_nodes")(*geometry, *state, *params, *extra, out)
        return out


def generated_digest() -> str:
    """SHA-256 over the signatures of every generated module (stored as provenance)."""
    names = sorted(generated.CLASSES) + ["coil_field"]
    text = "".join(importlib.import_module(f"{generated.__name__}.{n}").SIGNATURE for n in names)
    return hashlib.sha256(text.encode()).hexdigest()
