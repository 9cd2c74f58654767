"""Energy terms as data (codegen/terms/): a class's terms decide its kernels, and a new term changes only what it
adds. The toy term here, the membrane's weight g η per reference area, is defined in the test alone: no stage of
codegen/ knows it."""
import importlib
from dataclasses import dataclass

import pytest
import sympy as sp

from codegen import equations, functional as fn, poles, surface
from codegen.classes import PLAIN, scene_classes, terms
from codegen.functional import SceneClass
from codegen.terms import Term
from codegen.terms.elastic import Elastic

g = sp.Symbol("g", real=True)


@dataclass(frozen=True)
class Weight(Term):
    """π += g η (axisymmetric), g z (whole sphere): the weight of the membrane along the axis (per reference area:
    times the meridian's metric S', 1 on the sphere)."""

    parameters = (g,)
    continuation = (g, "weight", "g")

    def axisymmetric(self, c, s, metric):
        return g * fn.eta * metric

    def surface(self, point, a_t, a_p, areal):
        return g * point[2]

    def pole(self, lam, z, q, s, z0, metric):
        return g * z * s * metric


NEO_HOOKEAN = Elastic(("2",))
BASE = SceneClass("toy", NEO_HOOKEAN, terms(PLAIN))
WEIGHTED = SceneClass("toy", NEO_HOOKEAN, terms(PLAIN) + (Weight(),))


@pytest.mark.parametrize("cls", scene_classes(), ids=lambda c: c.name)
def test_committed_kernels_follow_the_class_terms(cls):
    """Every committed module has exactly the parameter-derivative kernels of its class's terms, and its kernels
    take exactly the terms' runtime scalars."""
    module = importlib.import_module(f"balloon_cg.generated.{cls.name}")
    words = [word for _, word, _ in fn.continuations(cls)]
    assert [k for k in module.KERNELS if k.endswith("_gradient") and k != "energy_gradient"] == [
        f"{w}_gradient" for w in words]
    assert [k for k in module.KERNELS if k.startswith("rhs_") and k != "rhs_jacobian"] == [f"rhs_{w}" for w in words]
    params = [name for name, kind, _ in module.KERNELS["energy_gradient"]["args"] if kind == "param"]
    assert params == [str(p) for p in fn.runtime_args(cls)]
    twin = importlib.import_module(f"balloon_cg.generated.surface_{cls.name}")
    assert [k for k in twin.KERNELS if k.endswith("_gradient") and k != "surface_gradient"] == [
        f"surface_{w}_gradient" for w in words]


def names(kernels):
    return [k.name for k in kernels]


def params(kernel):
    return [a.name for a in kernel.args if a.kind == "param"]


def test_a_new_term_adds_its_parameter_and_its_derivative_kernels():
    base = equations.energy_kernels(BASE) + equations.first_order_kernels(BASE)
    weighted = equations.energy_kernels(WEIGHTED) + equations.first_order_kernels(WEIGHTED)
    assert names(weighted) == names(base[:4]) + ["weight_gradient"] + names(base[4:]) + ["rhs_weight"]
    assert all(params(k) == ["P", "g"] for k in weighted)
    assert names(surface.surface_kernels(WEIGHTED)) == names(surface.surface_kernels(BASE)) + [
        "surface_weight_gradient"]
    assert params(poles.pole_kernel(WEIGHTED)) == ["P", "g"]


def test_a_new_term_changes_only_its_own_energy():
    """π̂ and π gain g η and g z; the gradient in g is (0, 0, 1, 0); Φ, and so the shear coefficient, is unchanged;
    the pole series at g = 0 is the class's without the term."""
    assert sp.expand(fn.energy_density(WEIGHTED) - fn.energy_density(BASE)) == g * fn.eta
    assert sp.expand(surface.density(WEIGHTED) - surface.density(BASE)) == g * surface.STATE[2]
    kernel = equations.energy_kernels(WEIGHTED)[-1]
    assert kernel.name == "weight_gradient" and kernel.outputs == (0, 0, 1, 0)
    assert fn.membrane_energy(WEIGHTED, *sp.symbols("l1 l2")) == fn.membrane_energy(BASE, *sp.symbols("l1 l2"))
    at = {sp.Symbol("lam0", positive=True): 1.7, sp.Symbol("P", real=True): 0.8, NEO_HOOKEAN.moduli()[0]: 1.3}
    for with_term, without in zip(poles.pole_kernel(WEIGHTED).outputs, poles.pole_kernel(BASE).outputs):
        assert with_term.has(g)
        assert float(with_term.subs(g, 0).subs(at)) == pytest.approx(float(without.subs(at)), rel=1e-13)
