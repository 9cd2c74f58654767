"""The symbolic layer: printer text, kernels against SymPy, and generated/ up to date."""
import filecmp
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from codegen import functional as fn, poles
from codegen.build import module_names
from codegen.freshness import stale
from codegen.printer import print_expr
from codegen.terms.magnetic import FIELD, M, chi
from codegen.terms.pressure import P

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize(
    "expr",
    ["4*y/x**5", "x**2 + y**-3", "1/sqrt(x + y)", "y/x**(3/2)", "x**(13/10)*y**(-2)", "(x*y)**(-173/100) - 3/x"],
)
def test_printed_expression_evaluates_like_sympy(expr):
    import math  # noqa: F401  (used by the printed text)

    x, y = sp.symbols("x y")
    e = sp.sympify(expr)
    value = eval(print_expr(e), {"math": math, "x": 1.37, "y": 0.61})
    assert value == pytest.approx(float(e.subs({x: 1.37, y: 0.61})), rel=1e-14)


def test_integer_powers_print_as_products():
    x = sp.Symbol("x")
    assert print_expr(x**3) == "(x*x*x)"
    assert print_expr(x**-2) == "(1.0/(x*x))"


@pytest.mark.parametrize("expr", ["(x + y)**3*sin(x*y)", "Piecewise((x**2, x > 0), (exp(x), True))", "f(x)*x", "Abs(x)*y",
                                  "sqrt(x**2 + y**2)**(13/10)*log(x)"])
def test_lean_derivatives_are_sympys(expr):
    """Inside derivative.lean() a derivative is SymPy's expression, node for node (the same tree, not only the same
    function: the emitted text depends on it), also where a node's rule leaves a Derivative (f(x)) or several
    symbols are asked; leaving it restores SymPy's diff."""
    from sympy.core.expr import Expr

    from codegen import derivative

    x, y = sp.symbols("x y", real=True)
    e = sp.sympify(expr, locals={"x": x, "y": y, "f": sp.Function("f")})
    plain = (e.diff(x), e.diff(y), sp.diff(e, x, 2), sp.diff(e, x, y))
    diff = Expr.diff
    with derivative.lean():
        assert Expr.diff is not diff
        lean = (e.diff(x), e.diff(y), sp.diff(e, x, 2), sp.diff(e, x, y))
    assert Expr.diff is diff
    assert [sp.srepr(d) for d in lean] == [sp.srepr(d) for d in plain]


@pytest.mark.parametrize("name", ["ogden_spom1", "ogden_tpom2_field", "ogden_general_field"])
def test_generated_gradient_matches_sympy(name):
    """The emitted energy_gradient equals SymPy's derivative of the functional at a random state."""
    from balloon_cg.model.kernels import KernelSet
    from balloon_cg.scene.materials import Material
    from codegen.classes import scene_classes

    cls = next(c for c in scene_classes() if c.name == name)
    rng = np.random.default_rng(3)
    state = dict(zip((fn.cos_theta, fn.lam2, fn.v, fn.eta, fn.w), (0.3, 1.6, 0.2, 0.4, -1.1)))
    state[fn.sin_theta] = np.sqrt(1 - 0.3**2)
    elastic = cls.elastic
    mus = rng.uniform(0.5, 2.0, elastic.n_terms)
    alphas = np.array([1.7, 3.0, -2.5]) if elastic.alphas is None else np.array([float(a) for a in elastic.alphas])
    values = {**state, P: 0.9, **dict(zip(elastic.moduli(), mus))}
    if elastic.alphas is None:
        values.update(dict(zip(elastic.exponents(), alphas)))
    field = rng.uniform(-1, 1, 6)
    if cls.field:
        values.update({M: 0.01, chi: 1.3, **dict(zip(FIELD, field))})
    density = fn.energy_density(cls)
    expected = [float(fn.at_node(cls, sp.diff(density, s)).subs(values)) for s in fn.STATE]
    kernels = KernelSet(Material("random", tuple(mus), tuple(alphas)), cls.term_names, kernel_class=name)
    named = {str(symbol): float(value) for symbol, value in values.items()} | {"field": field}
    assert np.allclose(kernels.call("energy_gradient", named), expected, rtol=1e-12, atol=1e-12)


def test_pole_series_of_the_sphere():
    """At M = 0 the pole coefficients reduce to the sphere's: e2 = −c0/2 iff P = 2 φ_01 / c0² (MODEL.md §4)."""
    _, e2, _, _ = poles.pole_coefficients("north")
    phi01 = sp.Symbol("phi01")
    sphere_P = 2 * phi01 / poles.c0**2
    assert sp.simplify(e2.subs({M: 0, P: sphere_P}) + poles.c0 / 2) == 0


@pytest.mark.parametrize("preset", ["SPOM1", "FPOM2", "TPOM2"])
def test_first_order_system_holds_on_the_exact_sphere(preset):
    """On the sphere λ2 = λ, η = λ cos θ at the exact pressure, f = (0, 0, −λ sin θ, −λ cos θ)."""
    from balloon_cg.model.kernels import KernelSet
    from balloon_cg.scene.materials import get_preset
    from balloon_cg.model.sphere import sphere_pressure

    material = get_preset(preset)
    kernels = KernelSet(material)
    lam = 2.3
    for theta in (0.2, 1.1, 2.9):
        c, s = np.cos(theta), np.sin(theta)
        values = {"theta": theta, "cos_theta": c, "sin_theta": s, **kernels.state((lam, 0.0, lam * c, -lam * s)),
                  "P": sphere_pressure(material, lam)}
        f = kernels.call("rhs", values)
        assert np.allclose(f, (0.0, 0.0, -lam * s, -lam * c), atol=1e-12)


def test_generated_is_up_to_date():
    """generated/ is what today's generator prints (codegen/freshness.py, from the modules' headers: each module's
    GENERATOR_SOURCES is the digest of codegen/ and the runtime modules it reads, and its text is the generator's
    header over its body); fails when generated/ is stale: run `make regenerate`."""
    assert stale(ROOT / "generated") == [], "generated/ is stale: run `make regenerate`"


def test_a_stale_generated_folder_is_seen_without_regenerating(tmp_path):
    """The check above on copies made stale on purpose: an edit to a generator source (codegen/ or the formula
    parser it reads), a module edited by hand (its body; its header's inputs), a module missing, one left over, and
    the registry edited: each is named."""
    from codegen import generator_sources

    folder = Path(shutil.copytree(ROOT / "generated", tmp_path / "generated"))
    sources = generator_sources()
    for name in ("codegen/printer.py", "balloon_cg/scene/formula.py"):
        edited = tmp_path / name.replace("/", "_")
        edited.write_text(sources[name].read_text() + "# an edit\n")
        lines = stale(folder, sources | {name: edited})
        assert len(lines) == len(module_names()) and all("printed by other generator sources" in line
                                                          for line in lines), lines
    assert stale(folder, sources) == []
    spom1 = folder / "ogden_spom1.py"
    text = spom1.read_text()
    assert "\n    return (" in text
    spom1.write_text(text.replace("\n    return (", "\n    return  (", 1))  # the body: one kernel's last line
    (folder / "inertia.py").write_text((folder / "inertia.py").read_text().replace("Inputs: [", "Inputs: [ ", 1))
    (folder / "coil_field.py").unlink()
    (folder / "ogden_spom9.py").write_text("")
    (folder / "__init__.py").write_text((folder / "__init__.py").read_text() + "\n")
    assert stale(folder, sources) == [
        "coil_field.py: missing", "ogden_spom9.py: not a module the generator writes",
        "__init__.py: not the registry of today's scene table",
        "inertia.py: edited after it was generated (its header does not match its body)",
        "ogden_spom1.py: edited after it was generated (its header does not match its body)"]


@pytest.mark.slow
def test_make_regenerate_reproduces_generated_byte_for_byte(tmp_path):
    """`make regenerate` reproduces generated/ byte for byte: also what the check from the headers cannot see
    (another SymPy or mpmath printing otherwise). A minute of CPU: `-m slow`, and .ci/run runs it after the
    default suite."""
    subprocess.run([sys.executable, "-m", "codegen", str(tmp_path)], cwd=ROOT, check=True, capture_output=True)
    fresh = sorted(p.name for p in tmp_path.glob("*.py"))
    committed = sorted(p.name for p in (ROOT / "generated").glob("*.py"))
    assert fresh == committed
    _, mismatch, errors = filecmp.cmpfiles(tmp_path, ROOT / "generated", fresh, shallow=False)
    assert not mismatch and not errors, f"stale generated modules: {mismatch + errors}; run `make regenerate`"
