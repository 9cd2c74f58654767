"""On-demand kernels for a scene class that is not committed in generated/: a user formula, or any material with
the dielectric term (a committed class's Ogden exponents or a strain energy, with or without a field).

The module is generated at first use by the same generator as generated/ (codegen/, shipped as
balloon_cg.codegen; it needs SymPy, the ``codegen`` extra) into a content-keyed cache folder, and imported from
there by every later run. The key is the SHA-256 of

    (canonical formula and parameter names, or 'ogden' and the exponents (None: runtime exponents), field or not,
     dielectric term or not, codegen.GENERATOR_VERSION, the generator's source digest, SymPy version),

so an edited formula, a new generator or another SymPy gives a new module; parameter values (material
parameters, the voltage) are kernel arguments and never enter the key. The text is written to a temporary file in the cache folder and moved into
place with ``os.replace`` (atomic on one file system): concurrent sweep workers generating the same class all
succeed, each finds either no module or a complete one, and the deterministic text makes the winner irrelevant.

This is the only runtime module that imports SymPy or codegen (tests/test_layers.py).
"""
import functools
import hashlib
import importlib.metadata
import importlib.util
import os
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from .. import codegen
from ..scene import formula as formula_module
from ..scene.validation import SceneError

CACHE_ENV = "BALLOON_CG_KERNEL_CACHE"


def cache_dir() -> Path:
    """$BALLOON_CG_KERNEL_CACHE, else $XDG_CACHE_HOME/balloon-cg/kernels (XDG_CACHE_HOME defaulting to ~/.cache)."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "balloon-cg" / "kernels"


def _sympy_version() -> str:
    try:
        return importlib.metadata.version("sympy")
    except importlib.metadata.PackageNotFoundError:
        raise SceneError("kernels: a user formula or the [electric] term needs its kernels generated once, which "
                         "needs SymPy: pip install 'balloon-cg[codegen]'") from None


@functools.cache
def generator_digest() -> str:
    """SHA-256 of the generator's source (codegen/**/*.py and the formula parser it walks): an edit to the generator
    invalidates cached modules even where GENERATOR_VERSION was not raised."""
    files = sorted(Path(codegen.__file__).parent.rglob("*.py")) + [Path(formula_module.__file__)]
    return hashlib.sha256(b"".join(f.name.encode() + f.read_bytes() for f in files)).hexdigest()


@dataclass(frozen=True)
class Exponents:
    """An Ogden material's class as plain data: the exponents of a committed class as the strings it was generated
    from (its INPUTS 'alphas'), or None for the general class (runtime exponents)."""

    alphas: tuple | None


def _identity(material) -> tuple:
    """What the class is generated from: a scene/formula.Formula or Exponents."""
    if isinstance(material, Exponents):
        return ("ogden", material.alphas)
    return (material.text, tuple(material.parameters))


def class_key(material, field: bool, electric: bool = False, surface: bool = False) -> str:
    """The cache key of the class of ``material`` (scene/formula.Formula or Exponents) with or without a field
    and the dielectric term; ``surface``: its surface kernels (MODEL.md §8) instead of the axisymmetric ones."""
    text = repr((*_identity(material), bool(field), bool(electric), bool(surface), codegen.GENERATOR_VERSION,
                 generator_digest(), _sympy_version()))
    return hashlib.sha256(text.encode()).hexdigest()


def module_name(material, field: bool, electric: bool = False, surface: bool = False) -> str:
    kind = ("surface_" if surface else "") + ("ogden" if isinstance(material, Exponents) else "energy")
    return f"{kind}{'_dielectric' if electric else ''}_{class_key(material, field, electric, surface)[:32]}"


def module_path(material, field: bool, electric: bool = False, surface: bool = False) -> Path:
    return cache_dir() / f"{module_name(material, field, electric, surface)}.py"


def generate(material, field: bool, timings: dict | None = None, electric: bool = False,
             surface: bool = False) -> str:
    """The module text of the class, or of its surface kernels (stage timings in seconds into ``timings``: see
    codegen/build.py)."""
    _sympy_version()
    from ..codegen import build, classes
    from ..codegen.functional import SceneClass
    from ..codegen.terms.elastic import Elastic

    if isinstance(material, Exponents):
        elastic = Elastic(material.alphas)
    else:
        elastic = classes.strain_energy(material.text, material.parameters)
    cls = SceneClass(module_name(material, field, electric, surface), elastic, classes.terms(field, electric))
    return (build.surface_module if surface else build.class_module)(cls, timings)


def load(material, field: bool, timings: dict | None = None, electric: bool = False, surface: bool = False):
    """The kernel module of the class (``surface``: its surface kernels), generated and written atomically into
    the cache first if missing; imported once per process (as ``sys.modules[module_name]``)."""
    path = module_path(material, field, electric, surface)
    if path.stem in sys.modules:
        return sys.modules[path.stem]
    if not path.is_file():
        text = generate(material, field, timings, electric, surface)
        start = time.perf_counter()
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", dir=path.parent, prefix=f".{path.stem}.", suffix=".tmp",
                                         delete=False, encoding="utf-8") as handle:
            handle.write(text)
        os.replace(handle.name, path)
        if timings is not None:
            timings["write"] = time.perf_counter() - start
    start = time.perf_counter()
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    sys.modules[path.stem] = module
    if timings is not None:
        timings["import"] = time.perf_counter() - start
    return module
