"""The default Gauss rule (``discretisation.gauss_nodes``: 3N/2 + 8 nodes, docs/numerics.md §2) against a finer
one where the integrands are hardest: the membrane next to a wire, solved in x at the degree a branch point
there is located at (benchmarks/quadrature.py is the full study)."""
import numpy as np
import pytest

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import ParameterSystem
from balloon_cg.galerkin.discretisation import Discretisation, gauss_nodes
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.numerics.newton import newton
from balloon_cg.scene import parse_scene

DEGREE = 320  # the plain degree at which the near-wire pear pitchfork of this scene is located
PRESSURE = 1.94  # just above that pitchfork's P ≈ 1.92839, on the falling part of the branch (bulge near the wire)


@pytest.fixture(scope="module")
def near_wire():
    """One coil of radius 2, M = 0.001 (tests/test_branch_points.py's near-wire scene): the primary branch and
    the index of its first point past the pressure maximum with P ≤ PRESSURE."""
    scene = parse_scene('[material]\npreset = "SPOM1"\n[field]\nM = 0.001\n[[field.coils]]\nradius = 2.0\n'
                        'height = 0.0\ncurrent = 1.0\n[continuation]\nstop_stretch = 6.0\nwire_gap = 0.02\n',
                        name="SPOM1-coil")
    primary = trace_primary(scene)
    P = primary.X[:, -1]
    past_maximum = np.arange(len(P)) > np.argmax(P)
    return scene, primary, int(np.flatnonzero(past_maximum & (P <= PRESSURE))[0])


def pressure(near_wire, nodes: int) -> float:
    """P at the point's pole stretch, solved on the plain basis of DEGREE with ``nodes`` Gauss nodes."""
    scene, primary, i = near_wire
    disc = Discretisation(DEGREE, True, primary.disc.pin_translation, nodes)
    system = ParameterSystem(Equilibrium(scene, disc), primary.params, "P")
    row = np.append(disc.pole_rows()["lam2_top"], 0.0)
    stretch = primary.pole_values()["lam2_top"][i]
    result = newton(system.residual, system.jacobian, primary.disc.transfer(primary.X[i], disc), row, stretch,
                    1e-12, 20)
    assert result.converged, result.message
    return float(result.x[-1])


def test_default_rule_holds_the_near_wire_pressure_against_twice_the_nodes(near_wire):
    """3N/2 + 8 nodes agree with 2N + 16 to 1e-9 in P (measured 7e-11); N + 8, which agrees at the
    work-precision points away from the wires, is off by ~2e-7 here (the coil field next to the wire has content
    above the degree that resolves the membrane)."""
    fine = pressure(near_wire, 2 * DEGREE + 16)
    assert abs(pressure(near_wire, gauss_nodes(DEGREE)) / fine - 1) <= 1e-9
    assert abs(pressure(near_wire, DEGREE + 8) / fine - 1) >= 1e-8


@pytest.mark.parametrize("n", [1, 8, 143, 488])
def test_the_shared_gauss_rule_integrates_legendre_products_exactly_and_cannot_be_changed(n):
    """``legendre.gauss_rule`` (numpy's leggauss, computed once per n): exact for P_j P_k with j + k < 2n (the
    orthogonality ∫P_j P_k = 2δ_jk/(2k + 1)), the same arrays on every call, and read-only (a caller that wrote
    into them would change every later discretisation's rule)."""
    from numpy.polynomial import legendre

    from balloon_cg.galerkin.legendre import gauss_rule

    x, w = gauss_rule(n)
    assert gauss_rule(n)[0] is x and not x.flags.writeable and not w.flags.writeable
    k = min(n - 1, 40)
    p = legendre.legvander(x, k)  # P_0..P_k at the nodes
    gram = (p * w[:, None]).T @ p
    assert np.allclose(gram, np.diag(2.0 / (2 * np.arange(k + 1) + 1)), atol=1e-13)
    with pytest.raises(ValueError):
        x[0] = 0.0
