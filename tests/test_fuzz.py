"""Fuzzed scenes (hypothesis): parsing gives a Scene or one SceneError, never another exception; short runs of
what parses exit 0, 1 or 2 (never 3, an internal error), and a written file reads back with no NaN stored.
Bounded examples here; HYPOTHESIS_PROFILE=soak runs 20x more (the figures in the closing note)."""
import math
import os

import h5py
import numpy as np
from hypothesis import HealthCheck, Phase, given, settings, strategies as st

from balloon_cg.app.cli import main
from balloon_cg.io.run_file import read_run
from balloon_cg.scene import SceneError, parse_scene

SCALE = 20 if os.environ.get("HYPOTHESIS_PROFILE") == "soak" else 1
TABLES = {
    "material": ("preset", "mu", "alpha", "name"),
    "field": ("chi", "M", "coils"),
    "continuation": ("start_stretch", "stop_stretch", "min_stretch", "stop_pressure", "step", "step_min",
                     "step_max", "max_points", "symmetry", "wire_gap"),
    "solver": ("degree", "quadrature", "tol", "max_newton", "max_degree", "max_error"),
    "stability": ("degree", "m_max"),
    "output": ("theta_points",),
}
PRESETS = ("SPOM1", "spom2", "FPOM1", "TPOM2", "neo-Hookean", "Mooney-Rivlin", "nope", "")

numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**20, 10**20),
                    st.sampled_from([0, 1, 1.0005, 1.01, 2, 5, 8, 20, 40, 400, 401, 1e-7, 0.25, -1]))
text = st.text(alphabet="abcdefghijklmnopqrstuvwxyzSPOM0123456789-_ ", max_size=8)
scalars = st.one_of(numbers, st.booleans(), text, st.sampled_from(PRESETS + ("auto", "equator", "none")))
values = st.recursive(scalars, lambda inner: st.lists(inner, max_size=4), max_leaves=12)
coil = st.dictionaries(st.sampled_from(("radius", "height", "current", "colour")), numbers, max_size=4)


@st.composite
def scenes(draw) -> dict:
    data = {}
    for table, keys in TABLES.items():
        if table != "material" and draw(st.booleans()):
            continue
        entries = draw(st.dictionaries(st.sampled_from(keys + ("unknown",)), values, max_size=4))
        if table == "material" and draw(st.booleans()):
            entries["preset"] = draw(st.sampled_from(PRESETS))
        if table == "field" and "coils" in entries:
            entries["coils"] = draw(st.lists(coil, max_size=3))
        data[table] = entries
    if draw(st.integers(0, 9)) == 0:
        data["extra"] = {"x": 1}
    return data


def toml(data: dict) -> str:
    """The TOML text of ``data`` (tables of scalars and lists; field.coils as an array of tables)."""
    lines = []
    for table, entries in data.items():
        lines.append(f"[{table}]")
        coils = entries.get("coils") if table == "field" else None
        for key, value in entries.items():
            if key == "coils" and isinstance(coils, list) and all(isinstance(c, dict) for c in coils):
                continue
            lines.append(f"{key} = {_value(value)}")
        for c in coils if isinstance(coils, list) and all(isinstance(c, dict) for c in coils) else []:
            lines.append("[[field.coils]]")
            lines += [f"{k} = {_value(v)}" for k, v in c.items()]
    return "\n".join(lines) + "\n"


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, int):
        return str(v) if -2**63 <= v < 2**63 else repr(float(v))
    if isinstance(v, str):
        return '"' + v + '"'
    return "[" + ", ".join(_value(x) for x in v) + "]"


@settings(max_examples=300 * SCALE, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenes())
def test_parsing_gives_a_scene_or_one_scene_error(data):
    try:
        scene = parse_scene(toml(data), "fuzz")
    except SceneError as e:
        assert "\n" not in str(e)
        return
    assert scene.continuation.start_stretch > 1 and scene.solver.degree <= scene.solver.max_degree <= 400


short = st.fixed_dictionaries({
    "continuation": st.fixed_dictionaries({
        "start_stretch": st.floats(1.0001, 1.2), "stop_stretch": st.floats(1.0, 6.0),
        "max_points": st.integers(1, 15), "step": st.floats(1e-4, 0.3), "step_max": st.floats(0.01, 0.3),
        "symmetry": st.sampled_from(("auto", "none"))}),
    "solver": st.fixed_dictionaries({"degree": st.integers(8, 48), "tol": st.floats(1e-13, 1e-6)}),
    "field": st.fixed_dictionaries({"M": st.floats(0, 0.01), "coils": st.lists(st.fixed_dictionaries({
        "radius": st.floats(0.5, 5), "height": st.floats(-3, 3), "current": st.sampled_from((1.0, -1.0))}),
        max_size=2)}),
    "material": st.fixed_dictionaries({"preset": st.sampled_from(("SPOM1", "TPOM1", "neo-Hookean"))}),
})


@settings(max_examples=12 * SCALE, deadline=None, phases=(Phase.explicit, Phase.reuse, Phase.generate),
          suppress_health_check=[HealthCheck.too_slow,
                                                                        HealthCheck.function_scoped_fixture])
@given(short)
def test_short_runs_exit_0_1_or_2_and_store_no_nan(tmp_path, data):
    scene, out = tmp_path / "fuzz.toml", tmp_path / "fuzz.h5"
    out.unlink(missing_ok=True)
    scene.write_text(toml(data))
    code = main(["run", str(scene), "-o", str(out), "--primary-only", "--quiet", "--force"])
    assert code in (0, 1, 2)
    if not out.exists():  # bad input (2), or the branch could not start (1): nothing written
        assert code in (1, 2)
        return
    run = read_run(out)
    with h5py.File(out, "r") as f:
        def finite(name, item):  # NaN only where docs/hdf5.md says so: E2..E4 of special points other than BP
            if isinstance(item, h5py.Dataset) and item.dtype.kind == "f":
                values = item[()]
                if name.rsplit("/", 1)[-1] in ("E2", "E3", "E4"):
                    values = values[item.parent["kind"].asstr()[()] == "BP"]
                assert np.isfinite(values).all(), name
        f.visititems(finite)
    assert len(run["branches"]["primary"]["pressure"]) >= 1
