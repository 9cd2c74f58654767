"""``balloon-cg kernels SCENE``: which kernel class a scene uses, generated on demand if needed, with timings.

Stages reported (seconds): for a class not committed in generated/ (a user formula, any class with the
dielectric term) the codegen stages
'derive' (equations, pole series, second variation), 'lower' (CSE), 'print', then 'write' (atomic, into the
cache) and 'import'; for every class 'jit' per kernel: its first call, compiled by numba or loaded from
numba's on-disk cache ('cache' column: hits).
"""
import json
import math
import time

_SAMPLE = {"theta": 1.0, "cos_theta": math.cos(1.0), "sin_theta": math.sin(1.0), "lam2": 1.2, "v": 0.01,
           "eta": 0.5, "w": 0.3, "lam0": 1.2, "lam1": 1.3, "P": 0.5, "M": 0.001, "chi": 1.0, "m": 1.0,
           "voltage": 0.3}
_NODES = 4


def add_kernels(commands):
    from .cli import SCENE_HELP  # the CLI's parser calls this: cli is loaded

    p = commands.add_parser("kernels", help="the kernel class of a scene, generated on demand, with timings")
    p.add_argument("scene", help=SCENE_HELP)
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(handler=kernels)


def kernels(args) -> int:
    from ..scene import load_scene  # the CLI imports what a subcommand needs when it runs (app/cli.py)

    report = kernel_report(load_scene(args.scene))
    if args.json:
        print(json.dumps(report))
        return 0
    print(f"class {report['class']} ({report['source']})" + (f", cache key {report['key']}" if report["key"] else ""))
    for stage, seconds in report["stages"].items():
        print(f"  {stage:<8} {seconds:9.3f} s")
    for name, (seconds, hits) in report["jit"].items():
        print(f"  jit      {seconds:9.3f} s  {name}{' (numba cache)' if hits else ''}")
    return 0


def kernel_report(scene) -> dict:
    """{'class', 'source' (committed | cached | generated), 'key', 'stages' {stage: s}, 'jit' {kernel: (s, hits)}}."""
    from ..model import kernel_cache
    from ..model.kernels import KernelSet, class_source, scene_terms

    material, terms, shape = scene.material, scene_terms(scene), scene.geometry.shape
    stages, key, source = {}, None, "committed"
    _, cached = class_source(material, terms, shape=shape)
    if cached is not None:
        key = kernel_cache.class_key(cached, terms, shape=shape.value)
        source = "cached" if kernel_cache.module_path(cached, terms, shape=shape.value).is_file() else "generated"
        kernel_cache.load(cached, terms, stages, shape=shape.value)
    start = time.perf_counter()
    kernel_set = KernelSet(material, terms, geometry=scene.geometry)
    stages["bind"] = time.perf_counter() - start
    return {"class": kernel_set.name, "source": source, "key": key, "stages": stages, "jit": _first_calls(kernel_set)}


def _first_calls(kernel_set) -> dict:
    """{kernel: (seconds of its first call, numba cache hits)} for every kernel of the module."""
    import numpy as np

    out = {}
    for name, spec in kernel_set.module.KERNELS.items():
        values = {**_SAMPLE, "field_north": np.zeros(6), "field_south": np.zeros(6)}
        nodes = spec["nodes"]
        for arg, kind, rows in spec["args"]:
            if kind == "node":
                values[arg] = np.full(_NODES if nodes else 1, _SAMPLE[arg]) if nodes else _SAMPLE[arg]
            elif kind == "node_rows":
                values[arg] = np.zeros((len(rows), _NODES))
        function = getattr(kernel_set.module, f"{name}_nodes" if nodes else name)
        start = time.perf_counter()
        kernel_set.nodes(name, values) if nodes else kernel_set.call(name, values)
        out[name] = (time.perf_counter() - start, sum(function.stats.cache_hits.values()))
    return out
