"""Stage driver: scene classes -> kernels -> lowered IR -> module text -> files in generated/."""
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from . import derivative, equations, poles
from . import inertia, second_variation, stretch_derivatives, surface
from .classes import scene_classes
from .emit import module_text
from .functional import SceneClass
from .kernels import lower
from .terms.elastic import GENERAL_TERMS
from .terms.magnetic import FIELD

GENERATOR = "codegen/build.py"


def layout() -> dict:
    """Row layouts of the class modules (the same for every class, so also in the registry): the state
    (λ2, v, η, w), the energy_hessian rows as (i, j) state pairs, the perturbation (R, R', Z, Z', T, T') and the
    azimuthal_hessian rows as its pairs, and the rows of the field argument (H² and its (ρ, η) derivatives)."""
    return {
        "STATE": equations.STATE_LABELS,
        "HESSIAN_PAIRS": equations.HESSIAN_PAIRS,
        "PERTURBATION": tuple(map(str, second_variation.PERTURBATION)),
        "AZIMUTHAL_PAIRS": second_variation.PAIRS,
        "FIELD_ROWS": tuple(map(str, FIELD)),
    }


def class_module(cls: SceneClass, timings: dict | None = None) -> str:
    """Module text of one scene class: Galerkin energy kernels, first-order system, pole series (the last two only
    on an analytic meridian with poles) and the m ≥ 1 second variation. ``timings``
    (if given) receives the seconds spent per stage: 'derive' (equations, poles, second variation), 'lower'
    (CSE), 'print'."""
    start = time.perf_counter()
    with derivative.lean():
        kernels = equations.energy_kernels(cls)
        # a meridian without poles (a tube) or with joins (a capsule) has no pole series and no first-order system
        # (codegen/meridian.py)
        if cls.meridian.analytic:
            kernels += equations.first_order_kernels(cls) + [poles.pole_kernel(cls)]
        # non-axisymmetric (m ≥ 1) second variation: azimuthal_hessian, shear_coefficient (codegen/second_variation.py;
        # on every meridian)
        kernels += second_variation.second_variation_kernels(cls)
        if cls.elastic.energy is not None:
            kernels += [stretch_derivatives.derivatives_kernel(cls), *stretch_derivatives.domain_kernels(cls)]
    title = cls.title("Kernels for scene class")
    derived = time.perf_counter()
    lowered = [lower(k) for k in kernels]
    cse = time.perf_counter()
    text = module_text(title, cls.inputs(), lowered, GENERATOR, layout=layout())
    if timings is not None:
        timings.update(derive=derived - start, lower=cse - derived, print=time.perf_counter() - cse)
    return text


def surface_module(cls: SceneClass, timings: dict | None = None) -> str:
    """Module text of the surface kernels of one scene class (codegen/surface.py), separate from its class
    module; ``timings`` as for ``class_module``."""
    start = time.perf_counter()
    with derivative.lean():
        kernels = surface.surface_kernels(cls)
    title = cls.title("Surface kernels (MODEL.md §8) for scene class", surface=True)
    derived = time.perf_counter()
    lowered = [lower(k) for k in kernels]
    cse = time.perf_counter()
    text = module_text(title, {**cls.inputs(), "surface": True}, lowered, GENERATOR, layout=surface.layout())
    if timings is not None:
        timings.update(derive=derived - start, lower=cse - derived, print=time.perf_counter() - cse)
    return text


def surface_name(cls: SceneClass) -> str:
    """The module name of a committed class's surface kernels."""
    return f"surface_{cls.name}"


def field_module_text() -> str:
    from . import field

    title, inputs, kernels, constants, layout = field.field_module()
    return module_text(title, inputs, [lower(k) for k in kernels], "codegen/field.py", constants, layout)


def inertia_module_text() -> str:
    title, inputs, kernels = inertia.inertia_module()
    return module_text(title, inputs, [lower(k) for k in kernels], "codegen/inertia.py")


def _class_job(job):
    kind, cls = job
    if kind == "surface":
        return surface_name(cls), surface_module(cls)
    return cls.name, class_module(cls)


def module_names() -> list[str]:
    """The modules ``write_all`` writes beside the registry: each class's, its surface kernels', the coil field's
    and the mass matrices' (inertia)."""
    classes = scene_classes()
    return sorted([cls.name for cls in classes] + [surface_name(cls) for cls in classes] + ["coil_field", "inertia"])


def all_modules(workers: int = 2):
    """{module name: text}, generated in parallel; output does not depend on the worker count."""
    classes = scene_classes()
    jobs = [("class", cls) for cls in classes] + [("surface", cls) for cls in classes]
    with ProcessPoolExecutor(workers) as pool:
        texts = dict(pool.map(_class_job, jobs))
    texts["coil_field"] = field_module_text()
    texts["inertia"] = inertia_module_text()
    return dict(sorted(texts.items()))


def registry_text() -> str:
    """``generated/__init__.py``: the index the runtime uses to pick a module for a scene."""
    rows, energy_rows = [], []
    for cls in scene_classes():
        elastic = cls.elastic
        if elastic.energy is not None:
            energy_rows.append(f"    {cls.name!r}: ({elastic.energy[0]!r}, {cls.term_names!r}),\n")
            continue
        alphas = None if elastic.alphas is None else tuple(float(a) for a in elastic.alphas)
        rows.append(f"    {cls.name!r}: ({alphas!r}, {cls.term_names!r}),\n")
    return (
        '"""Kernels emitted by codegen/ (make regenerate). Never edit by hand.\n\n'
        'CLASSES maps module name -> (Ogden exponents or None for runtime exponents, the names of its energy terms\n'
        'beyond the elastic one), ENERGY_CLASSES module name -> (canonical strain-energy formula, its terms); a scene\n'
        'class without a committed module is generated on demand (model/kernel_cache.py). The layout constants are\n'
        'those of every class module (codegen/build.py: layout). SURFACE_CLASSES maps class name -> its surface module\n'
        '(MODEL.md §8, codegen/surface.py), whose row layouts are the SURFACE_ constants.\n"""\n'
        f"GENERAL_TERMS = {GENERAL_TERMS}\n"
        + "".join(f"{name} = {value!r}\n" for name, value in layout().items())
        + "CLASSES = {\n" + "".join(rows) + "}\n"
        + "ENERGY_CLASSES = {\n" + "".join(energy_rows) + "}\n"
        + "".join(f"{name} = {value!r}\n" for name, value in surface.layout().items())
        + "SURFACE_CLASSES = {\n" + "".join(f"    {c.name!r}: {surface_name(c)!r},\n" for c in scene_classes())
        + "}\n"
    )


def write_all(outdir: Path, log=print) -> list[Path]:
    outdir.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    modules = all_modules()
    log(f"codegen: derived and printed {len(modules)} modules in {time.perf_counter() - start:.1f} s")
    written = []
    init = outdir / "__init__.py"
    init.write_text(registry_text())
    written.append(init)
    for name, text in modules.items():
        path = outdir / f"{name}.py"
        path.write_text(text)
        written.append(path)
    return written
