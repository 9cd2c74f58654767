"""The calling convention exported by codegen (KERNELS and the layouts) and the runtime's binding by name."""
import importlib
import inspect
from dataclasses import replace

import numpy as np
import pytest

from balloon_cg import generated
from balloon_cg.analysis.critical.pitchfork_curve import ExtendedSystem, alpha1_material
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.scene import parse_scene

LAYOUTS = ("STATE", "HESSIAN_PAIRS", "PERTURBATION", "AZIMUTHAL_PAIRS", "FIELD_ROWS")
SPOM1 = parse_scene('[material]\npreset = "SPOM1"\n', name="SPOM1")


@pytest.mark.parametrize("name", sorted(generated.CLASSES) + ["coil_field"])
def test_exported_convention_matches_the_functions(name):
    """KERNELS names every jitted function's parameters in order (NAME_nodes: the same, then out), and the class
    modules' layouts are the registry's."""
    module = importlib.import_module(f"{generated.__name__}.{name}")
    for kernel, spec in module.KERNELS.items():
        names = [arg for arg, _, _ in spec["args"]]
        assert list(inspect.signature(getattr(module, kernel).py_func).parameters) == names
        if spec["nodes"]:
            assert list(inspect.signature(getattr(module, f"{kernel}_nodes").py_func).parameters) == names + ["out"]
        assert all(bool(rows) == (kind in ("param_array", "node_rows")) for _, kind, rows in spec["args"])
    if name in generated.CLASSES:
        assert {key: getattr(module, key) for key in LAYOUTS} == {key: getattr(generated, key) for key in LAYOUTS}
        hessian = module.KERNELS["energy_hessian"]["outputs"]
        assert hessian == tuple(f"{module.STATE[i]}_{module.STATE[j]}" for i, j in module.HESSIAN_PAIRS)


def test_material_overrides_are_arguments_not_state():
    """Parameters(mu, alpha) on the general class give the residual of the material with those values, and the
    kernels' material arrays cannot be written."""
    disc = Discretisation(12, True, True)
    u = np.zeros(disc.size)
    u[0], u[disc.a_index.size] = 1.6, 1.6
    material = alpha1_material(SPOM1.material, 1.7)
    general = Equilibrium(SPOM1, disc, kernel_class="ogden_general_field")
    own = Equilibrium(replace(SPOM1, material=material), disc)
    assert own.kernels.name == "ogden_general_field"
    overridden = general.residual(u, Parameters(2.1, mu=material.mu, alpha=material.alpha))
    assert np.array_equal(overridden, own.residual(u, Parameters(2.1)))
    assert not np.array_equal(overridden, general.residual(u, Parameters(2.1)))
    with pytest.raises(ValueError):
        general.kernels.material()["alpha"][0] = 1.7
    with pytest.raises(ValueError, match="general kernel class"):
        Equilibrium(SPOM1, disc).residual(u, Parameters(2.1, alpha=material.alpha))


def test_alpha1_system_leaves_the_given_equilibrium_alone():
    """The α1 extended system evaluates its own general-class Equilibrium with per-call parameters."""
    eq = Equilibrium(SPOM1, Discretisation(12, True, True))
    system = ExtendedSystem(eq, Parameters(2.0), "alpha1", np.zeros(0))
    assert eq.kernels.name == "ogden_spom1" and system.eq is not eq
    params = system.set_q(1.7)
    material = alpha1_material(SPOM1.material, 1.7)
    assert params.alpha == material.alpha and params.mu == pytest.approx(material.mu, rel=1e-15)
    assert system.set_q(1.3).alpha[0] == 1.3 and params.alpha[0] == 1.7
