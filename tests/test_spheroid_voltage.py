"""A voltage across a spheroid ([electric]): continued in P at a fixed voltage, and in the voltage Φ̄ at a fixed
pressure (``continuation.parameter = "voltage"``). The dielectric term −Φ̄²λ1²λ2² per reference area is a function
of the stretches, so its kernels on the spheroid's meridian are generated as the elastic ones are; the start is
solved from the unstressed spheroid (analysis/branches/primary.py: ``inflated_reference``, then the voltage switched
on at the start stretch; ``held_by_voltage`` for a voltage continuation), where the sphere has its closed form.

Checked against
- the sphere's dielectric pipeline (tests/test_dielectric.py, tests/test_voltage_branches.py: closed forms of the
  charged sphere, its pull-in and pear points): a spheroid of aspect 1 is the sphere, point for point;
- the energy written in tests/test_shapes.py (``energy_gradient``) with the dielectric density −Φ̄²λ1²λ2² S': on a
  spheroid of aspect ≠ 1 the Galerkin state is stationary for it.
"""
import numpy as np
import pytest

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Kind
from balloon_cg.scene import parse_scene
from test_dielectric import NEO
from test_shapes import SPHEROID, energy_gradient
from test_voltage_branches import VOLTAGE_SCENE

IN_PRESSURE = NEO + "[electric]\nvoltage = 0.3\n[continuation]\nstart_stretch = 1.2\nstop_stretch = 1.45\n"


@pytest.mark.parametrize("text", [IN_PRESSURE, VOLTAGE_SCENE], ids=["pressure", "voltage"])
def test_spheroid_of_aspect_one_under_a_voltage_is_the_sphere(text):
    """Neo-Hookean under Φ̄ = 0.3 traced in P from pole stretch 1.2, and traced in Φ̄ at P = 0.5 from 1.1 (through
    its pull-in and its pear branch point), to 1.45, with m = 0 and m = 1 stability: the spheroid of aspect 1 (its
    dielectric kernels another module, its start solved, the sphere's in closed form) has the sphere's special
    points (kind, block, status) and every point of it to 1e-10."""
    one, other = (analyse(parse_scene(text + extra), pear=False).branches[0]
                  for extra in ("", SPHEROID.format(aspect=1.0)))
    assert other.kernel_class.startswith("ogden_dielectric_spheroid") and other.kernel_class != one.kernel_class
    assert [p.kind for p in one.special] == [p.kind for p in other.special]
    assert Kind.LP in [p.kind for p in one.special]
    for a, b in zip(one.special, other.special):
        assert (a.kind, a.block, a.status) == (b.kind, b.block, b.status)
        assert np.abs(a.X - b.X).max() <= 1e-10
    assert one.X.shape == other.X.shape and np.abs(one.X - other.X).max() <= 1e-10
    assert [a.flags() for a in one.stability] == [a.flags() for a in other.stability]


def dielectric(voltage, area=lambda metric: metric):
    """The dielectric density −Φ̄²λ1²λ2² per reference area, per d(cos θ) (``area``: its S', MODEL.md §2)."""
    return lambda lam1, lam2, rho, eta, metric: -voltage**2 * lam1**2 * lam2**2 * area(metric)


@pytest.mark.parametrize("aspect, text", [
    (1.3, '[material]\npreset = "SPOM1"\n[electric]\nvoltage = 0.1\n[continuation]\nstop_stretch = 1.2\n'),
    (0.7, VOLTAGE_SCENE.replace("stop_stretch = 1.45", "stop_stretch = 1.3"))], ids=["pressure", "voltage"])
def test_spheroid_under_a_voltage_is_stationary_for_the_energy_written_here(aspect, text):
    """A SPOM1 spheroid of aspect 1.3 under Φ̄ = 0.1 traced in P to pole stretch 1.2, and a neo-Hookean one of
    aspect 0.7 traced in Φ̄ at P = 0.5 to 1.3: at the last point of each the energy written in tests/test_shapes.py
    with the dielectric density −Φ̄²λ1²λ2² S' (at that point's Φ̄) is stationary along every basis direction (1e-8),
    while without the voltage, or with the dielectric density left without S', it is not (> 1e-3)."""
    scene = parse_scene(text + SPHEROID.format(aspect=aspect))
    branch = analyse(scene, pear=False).branches[0]
    X = branch.X[-1]
    voltage = X[-1] if scene.continuation.parameter.value == "voltage" else scene.voltage
    if scene.continuation.parameter.value == "voltage":
        X = np.append(X[:-1], scene.continuation.pressure)
    assert voltage > 0.05

    def largest(term):
        return np.abs(energy_gradient(scene, X, branch.disc, term)).max()

    assert largest(dielectric(voltage)) < 1e-8
    assert largest(dielectric(0.0)) > 1e-3
    assert largest(dielectric(voltage, lambda metric: 1.0)) > 1e-3
