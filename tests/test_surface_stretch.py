"""Surface kernels of a strain energy written in the principal stretches (codegen/surface.py: the closed form at
λ1 = √(m + d), λ2 = J/λ1 away from λ1 = λ2, the series in q = (λ1 − λ2)² near it, switched at d/m = SWITCH as the
Ogden terms): against the same energy written in the invariants and against the committed Ogden kernels, at random
states, at λ1 = λ2 exactly and nearly, and on both sides of the switch; and an m = 1 branch of such a scene."""
from dataclasses import replace

import numpy as np
import pytest

from balloon_cg.model.kernels import KernelSet
from balloon_cg.scene import parse_scene
from balloon_cg.scene.energies import formula_energy
from balloon_cg.scene.materials import get_preset
from test_surface_kernels import (assert_close, full_hessian, random_state, stretched_state, switch_neighbours,
                                  switch_side, values)

SPOM1 = get_preset("SPOM1")
# the SPOM1 Ogden sum Σ (μ_i/α_i)(λ1^α_i + λ2^α_i + λ3^α_i − 3) as a formula in the stretches
SPOM1_TEXT = " + ".join(f"{mu!r}/{alpha!r}*(lambda1**{alpha!r} + lambda2**{alpha!r} + lambda3**{alpha!r} - 3)"
                        for mu, alpha in zip(SPOM1.mu, SPOM1.alpha))
MOONEY_RIVLIN = {"c1": 1 / 1.1, "c2": 0.1 / 1.1}
PAIRS = {  # name: (the energy in the stretches, the same energy by the kernels it is checked against)
    "neo-Hookean": (formula_energy("lambda1**2 + lambda2**2 + lambda3**2 - 3", {}, "stretches"),
                    formula_energy("I1 - 3", {}, "invariants")),
    "Mooney-Rivlin": (formula_energy("c1*(lambda1**2 + lambda2**2 + lambda3**2 - 3) + "
                                     "c2*(lambda1**-2 + lambda2**-2 + lambda3**-2 - 3)", MOONEY_RIVLIN, "stretches"),
                      formula_energy("c1*(I1 - 3) + c2*(I2 - 3)", MOONEY_RIVLIN, "invariants")),
    "SPOM1": (formula_energy(SPOM1_TEXT, {}, "stretches"), SPOM1),
}
RATIOS = (0.0, 1e-8, 0.29, 0.31, 0.5)  # d/m = (λ1² − λ2²)/(λ1² + λ2²), SWITCH = 0.3


@pytest.fixture(scope="module", params=list(PAIRS))
def pair(request):
    stretches, reference = PAIRS[request.param]
    return KernelSet(stretches).surface(), KernelSet(reference).surface()


def outputs(kernels, state):
    named = values(state, False)
    return (kernels.call("surface_energy", named), kernels.call("surface_gradient", named),
            full_hessian(kernels, state, named))


def states():
    rng = np.random.default_rng(3)
    yield from (random_state(rng) for _ in range(4))
    yield from (stretched_state(r, lam2, angle) for r in RATIOS for lam2, angle in ((0.8, 0.1), (1.1, 0.4), (2.3, 1.2)))
    yield from switch_neighbours()


def test_a_formula_in_the_stretches_matches_its_reference_kernels(pair):
    """Energy, gradient and Hessian to 1e-12 relative, at λ1 = λ2 (d = 0: the series' constant term), near it, on
    both sides of the switch (the series below, the closed form above) and at random states."""
    stretches, reference = pair
    sides = set()
    for state in states():
        sides.add(switch_side(state))
        for ours, theirs in zip(outputs(stretches, state), outputs(reference, state)):
            assert_close(ours, theirs, 1e-12)
    assert sides == {True, False}


def test_the_series_is_continuous_across_the_switch():
    """The stretch formula's own two branches a few ulps of d/m apart: value, gradient, Hessian to rounding."""
    kernels = KernelSet(PAIRS["Mooney-Rivlin"][0]).surface()
    below, above = switch_neighbours()
    for ours, theirs in zip(outputs(kernels, below), outputs(kernels, above)):
        assert_close(ours, theirs, 1e-12)


@pytest.mark.slow
def test_a_scene_in_the_stretches_traces_its_m1_branch():
    """SPOM1 written in the stretches at M = 0: the branch born at the m = 1 copy of the pear point starts and takes
    its points with the generated surface kernels, as the Ogden class's (tests/test_surface.py), at the same
    pressures (slow: the axisymmetric and whole-sphere modules of the formula are generated and compiled cold, ~1 to
    6 minutes)."""
    from balloon_cg.analysis.picture import analyse
    from balloon_cg.analysis.results import Block
    from balloon_cg.analysis.surface.branches import trace_surface

    traced = {}
    for name, material in (("stretches", f"energy = {SPOM1_TEXT!r}"), ("ogden", 'preset = "SPOM1"')):
        scene = parse_scene(f"[material]\n{material}\n[continuation]\nstop_stretch = 4.0\n"
                            "[surface]\nbranches = \"none\"\nmax_points = 3\n", name)
        primary = analyse(scene, pear=False).primary
        bp = primary.branch_points()[0]
        traced[name] = trace_surface(primary, 0, replace(bp, m=1, block=Block.M1_HELD), 1.0, "m1",
                                     scene.surface.max_points)
    stretches, ogden = traced["stretches"], traced["ogden"]
    assert len(stretches.values) == 3 and stretches.measures["tilt"][1:].min() > 89.999
    assert np.allclose(stretches.values, ogden.values, rtol=1e-8, atol=0)
