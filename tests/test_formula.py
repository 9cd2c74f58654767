"""User strain-energy formulas: the whitelist parser (nothing in the text runs), the reference-state checks,
the on-demand kernel cache, and a formula for SPOM1's Ogden terms against the SPOM1 preset."""
import ast
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from balloon_cg import codegen
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Block
from balloon_cg.model import kernel_cache
from balloon_cg.model.kernels import PLAIN
from balloon_cg.scene import parse_scene
from balloon_cg.scene.materials import ENERGY_PRESETS, material_from_table
from balloon_cg.scene.validation import SceneError

SPOM1_TERMS = " + ".join(f"mu{i}/a{i}*(lambda1**a{i} + lambda2**a{i} + lambda3**a{i} - 3)" for i in (1, 2, 3))
SPOM1_PARAMETERS = "mu1 = 3.00508\na1 = 1.3\nmu2 = 0.0145\na2 = 4.0\nmu3 = -0.0177\na3 = -2.0"

HOSTILE = {
    "attribute": ("lambda1.real", "lambda1.real"),
    "import": ("__import__('os').system('touch {marker}')", "__import__('os').system"),
    "lambda": ("(lambda x: x)(I1) - 3", "lambda x: x"),
    "call": ("open('{marker}', 'w')", "open"),
    "eval": ("eval('1') * (I1 - 3)", "eval"),
    "subscript": ("I1[0]", "I1[0]"),
    "keyword": ("log(x=I1)", "log(x=I1)"),
    "string": ("I1 - '3'", "'3'"),
    "comprehension": ("[I1 for I1 in (1,)]", "ListComp"),
    "name": ("I1 - three", "three"),
}


@pytest.mark.parametrize("case", list(HOSTILE))
def test_hostile_formulas_are_rejected_with_the_token_named_and_nothing_runs(case, tmp_path):
    """Rejected by one one-line SceneError naming the token; an audit hook sees no exec/eval, no file opened
    and no os.system, and the marker file the formula would create does not exist."""
    marker = tmp_path / "ran"
    formula, token = HOSTILE[case]
    formula = formula.format(marker=marker)
    script = textwrap.dedent(f"""
        import sys
        from balloon_cg.scene.materials import material_from_table
        from balloon_cg.scene.validation import SceneError
        events = []
        sys.addaudithook(lambda event, args: events.append(event) if event in ("exec", "open", "os.system",
                                                                               "subprocess.Popen") else None)
        try:
            material_from_table({{"energy": {formula!r}}})
        except SceneError as e:
            message = str(e)
        print(repr((message, events)))
    """)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    message, events = ast.literal_eval(out)
    assert token in message and "\n" not in message
    assert events == [] and not marker.exists()


def test_very_long_and_deeply_nested_formulas_are_rejected():
    with pytest.raises(SceneError, match="at most 2000"):
        material_from_table({"energy": "+".join(["(I1 - 3)"] * 300)})
    with pytest.raises(SceneError, match="nested deeper"):
        material_from_table({"energy": "I1 - 3" + " + 0*I1" * 0 + "".join(["*(1 + 0*I1"] * 70) + ")" * 70})


@pytest.mark.parametrize("formula, check", [
    ("I1", r"W\(1, 1\) = 3"),
    ("lambda1**2 + lambda2**2 - 2", "stress-free"),
    ("3 - I1", "initial shear modulus"),
    ("(lambda1 - 1)**2", "not isotropic"),
])
def test_reference_state_checks_name_the_failed_check(formula, check):
    with pytest.raises(SceneError, match=check):
        material_from_table({"energy": formula})


def test_parameters_are_named_and_used():
    with pytest.raises(SceneError, match="unknown name 'c'"):
        material_from_table({"energy": "c*(I1 - 3)"})
    with pytest.raises(SceneError, match="parameters.d: not used"):
        material_from_table({"energy": "c*(I1 - 3)", "parameters": {"c": 1.0, "d": 2.0}})
    energy = material_from_table({"energy": "c*(λ1^2 + λ2^2 + λ3^2 - 3)", "parameters": {"c": 1.0}})
    assert energy.formula.text == "c * (lambda1 ** 2 + lambda2 ** 2 + lambda3 ** 2 - 3)"
    assert energy.shear_modulus == pytest.approx(2.0, rel=1e-6)


def test_preset_initial_shear_moduli_are_two():
    """Every family preset has the Ogden presets' initial shear modulus μ0 = 2 (units of μ/2)."""
    for energy in ENERGY_PRESETS.values():
        assert energy.shear_modulus == pytest.approx(2.0, rel=1e-6), energy.name


def test_arruda_boyce_pade_error():
    """Cohen's rounded Padé x(3 − x²)/(1 − x²) against the inverse Langevin function (L(β) = coth β − 1/β):
    largest relative error 4.94 % on (0, 1), at x ≈ 0.80 (docs/scenes.md); exact as x → 0 and x → 1."""
    from scipy.optimize import brentq

    x = np.linspace(1e-3, 0.999, 2000)
    exact = np.array([brentq(lambda b: 1 / np.tanh(b) - 1 / b - xi, 1e-9, 1e4, xtol=1e-14) for xi in x])
    error = np.abs(x * (3 - x**2) / (1 - x**2) / exact - 1)
    assert 0.049 < error.max() < 0.0495 and 0.78 < x[error.argmax()] < 0.82
    assert error[0] < 1e-5 and error[-1] < 2e-3


def test_cache_key_changes_with_formula_field_generator_source_and_version(monkeypatch):
    energy = material_from_table({"energy": "I1 - 3"})
    other = material_from_table({"energy": "(I1 - 3)"})  # the same canonical text
    key = kernel_cache.class_key(energy.formula, PLAIN)
    assert kernel_cache.class_key(other.formula, PLAIN) == key
    assert kernel_cache.class_key(energy.formula, (*PLAIN, "magnetic")) != key
    assert kernel_cache.class_key(material_from_table({"energy": "I1 - 3 + 0*I2"}).formula, PLAIN) != key
    monkeypatch.setattr(codegen, "generator_digest", lambda: "an edited generator")
    assert kernel_cache.class_key(energy.formula, PLAIN) != key
    monkeypatch.undo()
    monkeypatch.setattr(codegen, "GENERATOR_VERSION", codegen.GENERATOR_VERSION + "-changed")
    assert kernel_cache.class_key(energy.formula, PLAIN) != key


def test_two_processes_generating_the_same_class_both_succeed(tmp_path):
    """Both generate at once into an empty cache, both import a complete module, one module file remains."""
    script = textwrap.dedent("""
        from balloon_cg.model.kernels import KernelSet
        from balloon_cg.scene.materials import material_from_table
        energy = material_from_table({"energy": "c*(I1 - 3) + d*(I2 - 3)**2", "parameters": {"c": 1.0, "d": 0.01}})
        kernels = KernelSet(energy)
        print(kernels.call("membrane_derivatives", {"lam1": 1.2, "lam2": 1.3})[1])
    """)
    env = {**__import__("os").environ, kernel_cache.CACHE_ENV: str(tmp_path)}
    workers = [subprocess.Popen([sys.executable, "-c", script], env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outputs = [w.communicate(timeout=600) for w in workers]
    assert [w.returncode for w in workers] == [0, 0], outputs
    values = [float(out) for out, _ in outputs]
    l1, l2 = 1.2, 1.3  # Φ_1 = c ∂I1/∂λ1 + 2d (I2 − 3) ∂I2/∂λ1
    i2 = l1**-2 + l2**-2 + (l1 * l2) ** 2
    expected = 2 * l1 - 2 / (l1**3 * l2**2) + 0.02 * (i2 - 3) * (-2 / l1**3 + 2 * l1 * l2**2)
    assert values == pytest.approx([expected] * 2, rel=1e-13)
    assert [p.name for p in tmp_path.iterdir()] == [p.name for p in tmp_path.glob("energy_*.py")]
    assert len(list(tmp_path.iterdir())) == 1


def test_cached_module_has_the_committed_header(tmp_path, monkeypatch):
    monkeypatch.setenv(kernel_cache.CACHE_ENV, str(tmp_path))
    energy = material_from_table({"energy": "I1 - 3 + 0.5*(I2 - 3)"})
    text = kernel_cache.generate(energy.formula, PLAIN)
    assert "Generated by balloon-cg codegen" in text and "SIGNATURE = " in text
    assert f"('energy', {energy.formula.text!r})" in text


# (preset, the same energy as a user formula (another code path: runtime exponents, the kernel cache), pear points)
PAIRS = {"SPOM1": (f'energy = "{SPOM1_TERMS}"\n[material.parameters]\n{SPOM1_PARAMETERS}', 2),
         "neo-Hookean": ('energy = "I1 - 3"', 0)}


@pytest.mark.parametrize("preset", list(PAIRS))
def test_user_formula_reproduces_the_preset(preset):
    """Primary branch, branch points and pear branches (SPOM1's isola) of the whole picture, to 1e-12."""
    formula_material, pears = PAIRS[preset]
    scenes = [parse_scene(f'[material]\n{m}\n[continuation]\nstop_stretch = 6.0\n', name="s")
              for m in (f'preset = "{preset}"', formula_material)]
    pictures = [analyse(s) for s in scenes]
    assert [b.name for b in pictures[0].branches] == [b.name for b in pictures[1].branches]
    assert (len(pictures[0].branches) > 1) == bool(pears)  # SPOM1: the primary branch and the isola
    for preset_branch, formula_branch in zip(*(p.branches for p in pictures)):
        lam_p, lam_f = (b.pole_values()["lam2_top"] for b in (preset_branch, formula_branch))
        assert lam_p.shape == lam_f.shape
        assert np.abs(lam_f - lam_p).max() < 1e-12
        assert np.abs(formula_branch.pressure / preset_branch.pressure - 1).max() < 1e-12
    pair = [p.primary for p in pictures]
    for block in (Block.ODD_HELD, Block.EVEN):
        points = [[b.pole_values(bp.X)["lam2_top"][0] for bp in b.branch_points(block)] for b in pair]
        assert len(points[0]) == len(points[1]) and (block != Block.ODD_HELD or len(points[0]) == pears)
        assert np.abs(np.subtract(*points)).max(initial=0) < 1e-12


def spom1_formula_kernels():
    from balloon_cg.model.kernels import KernelSet

    values = dict(zip(("mu1", "a1", "mu2", "a2", "mu3", "a3"), (3.00508, 1.3, 0.0145, 4.0, -0.0177, -2.0)))
    return KernelSet(material_from_table({"energy": SPOM1_TERMS, "parameters": values}))


def test_shear_coefficient_of_a_stretch_formula_is_exact_through_lambda1_eq_lambda2():
    """The generic removable-singularity form (closed form, even Taylor series within 1 %) for SPOM1 written as
    a formula, against the exact Ogden divided difference of test_azimuthal (the preset's test, same bound)."""
    from test_azimuthal import SPOM1, exact_shear

    kernels = spom1_formula_kernels()
    worst = 0.0
    for l2 in (1.0, 1.7, 3.0, 6.0):
        for h in np.concatenate([-np.logspace(-15, -0.5, 80), [0.0], np.logspace(-15, -0.5, 80)]):
            l1 = l2 * (1 + h)
            K = kernels.call("shear_coefficient", {"lam1": l1, "lam2": l2})[0]
            worst = max(worst, abs(K / exact_shear(*SPOM1, l1, l2) - 1))
    assert worst < 1e-13


def test_azimuthal_hessian_of_the_spom1_formula_is_the_presets():
    from balloon_cg.model.kernels import KernelSet
    from balloon_cg.scene.materials import get_preset

    formula, preset = spom1_formula_kernels(), KernelSet(get_preset("SPOM1"))
    rng = np.random.default_rng(3)
    for _ in range(20):
        c = rng.uniform(-1, 1)
        values = {"cos_theta": c, "sin_theta": np.sqrt(1 - c * c), "lam2": rng.uniform(1, 4), "v": rng.uniform(-.3, .3),
                  "eta": rng.uniform(-2, 2), "w": rng.uniform(-3, -0.5), "P": rng.uniform(0, 3), "m": 1.0 + _ % 3}
        a, b = (np.array(k.call("azimuthal_hessian", values)) for k in (formula, preset))
        assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max()


def test_shear_coefficient_of_an_invariant_energy_is_its_divided_difference():
    """Gent (K = W_1/(e1e2)² + W_2((e1+e2)/(e1e2)² − 1)) against (φ̂_1 − φ̂_2)/(e1 − e2) in 40-digit arithmetic."""
    import sympy as sp

    from balloon_cg.model.kernels import KernelSet

    e1, e2 = sp.symbols("e1 e2", positive=True)
    i1 = e1 + e2 + 1 / (e1 * e2)
    phi = -97.2 * sp.log(1 - (i1 - 3) / sp.Rational("97.2"))
    divided = (sp.diff(phi, e1) - sp.diff(phi, e2)) / (e1 - e2)
    kernels = KernelSet(ENERGY_PRESETS["Gent"])
    for l1, l2 in ((1.9, 1.4), (1.3, 2.6), (3.0, 3.2), (2.0, 2.0 * (1 + 1e-7))):
        exact = float(divided.subs({e1: sp.Float(l1, 40) ** 2, e2: sp.Float(l2, 40) ** 2}).evalf(40))
        assert kernels.call("shear_coefficient", {"lam1": l1, "lam2": l2})[0] == pytest.approx(exact, rel=1e-13)


def test_shear_coefficient_of_a_formula_with_logarithms():
    """A Hencky-type stretch formula (the series engine does not expand log: repeated differentiation) against
    (φ̂_1 − φ̂_2)/(e1 − e2) in 40-digit arithmetic, far from and through λ1 = λ2."""
    import sympy as sp

    from balloon_cg.model.kernels import KernelSet

    text = "I1 - 3 + k*(log(lambda1)**2 + log(lambda2)**2 + log(lambda3)**2)"
    kernels = KernelSet(material_from_table({"energy": text, "parameters": {"k": 0.3}}))
    e1, e2 = sp.symbols("e1 e2", positive=True)
    logs = sp.log(e1) ** 2 / 4 + sp.log(e2) ** 2 / 4 + sp.log(e1 * e2) ** 2 / 4
    phi = e1 + e2 + 1 / (e1 * e2) - 3 + sp.Rational("0.3") * logs
    divided = (sp.diff(phi, e1) - sp.diff(phi, e2)) / (e1 - e2)
    for l1, l2 in ((1.9, 1.4), (1.3, 2.6), (2.0 * (1 + 3e-3), 2.0), (2.0 * (1 - 1e-6), 2.0), (1.5, 1.5)):
        if l1 == l2:
            exact = float(sp.limit(divided.subs(e2, sp.Rational(9, 4)), e1, sp.Rational(9, 4)))
        else:
            exact = float(divided.subs({e1: sp.Float(l1, 40) ** 2, e2: sp.Float(l2, 40) ** 2}).evalf(40))
        assert kernels.call("shear_coefficient", {"lam1": l1, "lam2": l2})[0] == pytest.approx(exact, rel=1e-13)


def test_a_family_whose_committed_formula_is_stale_is_refused(monkeypatch):
    """The scene layer's family formula and its committed class must be the same text: otherwise `make regenerate`
    is asked for (never a quiet on-demand class in its place)."""
    from balloon_cg import generated
    from balloon_cg.model.kernels import KernelSet

    stale = {**generated.ENERGY_CLASSES, "gent": ("an older formula", generated.ENERGY_CLASSES["gent"][1])}
    monkeypatch.setattr(generated, "ENERGY_CLASSES", stale)
    with pytest.raises(ImportError, match="make regenerate"):
        KernelSet(ENERGY_PRESETS["Gent"])
