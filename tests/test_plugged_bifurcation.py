"""Does a plugged tube's mirror-symmetric branch bifurcate into non-symmetric states (a bulge shifted towards one
plug)? A zero of its odd block, read as the lowest eigenvalue ν of H_odd q = ν M_odd q against the membrane's mass
(dynamics/tube.py ``tube_mass``: qᵀMq = ∫(δρ² + δη²) dS), a property of the continuous problem that converges in the
degree (docs/tubes.md "Is there a bulge branch on plugged ends?", benchmarks/plugged_odd_block.py for the study at
L = 10, 14, 20 and degrees to 200).

Checked
- closed plugged ends (SPOM1, L = 10, to a hoop stretch of 5): no odd branch point reported at degrees 60 and 80, ν
  positive at every point, and ν at the bulge amplitude ρ(L/2) = 3 the same at both degrees (its state corrected
  onto that amplitude by Newton on (R_even, ρ(L/2) − 3)): a resolved positive eigenvalue, no bifurcation;
- plugged ends held apart (Gent, λ = 1.5, L = 10; slow): one odd branch point at degree 80, within 1e-4 in P of
  degree 60's, at a taut state (smallest stress > 0), with a negative ν beyond it: a genuine bifurcation (its branch
  is compressed within a few steps: tube/bulge.py refuses it, ``PLUGGED_WHY``).
"""
import numpy as np
import pytest
from scipy import linalg

from balloon_cg.dynamics.tube import tube_mass
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.galerkin.interval import Mirror
from balloon_cg.scene import parse_scene
from balloon_cg.tube.primary import primary_branch

SCENE = ('[material]\npreset = "{preset}"\n[geometry]\nshape = "tube"\nlength = {length}\nends = "plugged"\n{held}'
         "[solver]\ndegree = {degree}\n[continuation]\nstop_stretch = {stop}\nstep_max = {step}\nmax_points = 5000\n")


def odd_eigenvalue(eq, mass, Y, params) -> float:
    """The lowest ν of H_odd q = ν M_odd q at Y = (u, P)."""
    odd = eq.disc.block(Mirror.ODD)
    H = eq.jacobian(Y[:-1], params.with_value("P", Y[-1]))[np.ix_(odd, odd)]
    return float(linalg.eigh(H, mass[np.ix_(odd, odd)], eigvals_only=True, subset_by_index=[0, 0])[0])


def middle_row(disc) -> tuple:
    """(r, c) with ρ(L/2) = r·u + c, the middle's hoop stretch (affine in u)."""
    def rho(u):
        return float(disc.radius(u[None, :], np.zeros(1))[0][0])

    c = rho(np.zeros(disc.size))
    return np.array([rho(e) - c for e in np.eye(disc.size)]), c


def at_middle(eq, params, Y, target, tol=1e-12, iterations=30):
    """Y = (u, P) on the mirror-symmetric branch whose middle hoop stretch ρ(L/2) is ``target`` (the bulge's
    amplitude), by Newton on (R_even(u, P), ρ(L/2) − target) from Y (a held λ̄ fixed)."""
    disc = eq.disc
    index = disc.block(Mirror.EVEN)
    if disc.held:
        index = index[index != disc.axial_index]
    row, offset = middle_row(disc)
    Y = Y.copy()
    for _ in range(iterations):
        at = params.with_value("P", Y[-1])
        F = np.append(eq.residual(Y[:-1], at)[index], row @ Y[:-1] + offset - target)
        if np.abs(F).max() < tol:
            return Y
        J = np.zeros((index.size + 1, index.size + 1))
        J[:-1, :-1] = eq.jacobian(Y[:-1], at)[np.ix_(index, index)]
        J[:-1, -1] = eq.parameter_derivative(Y[:-1], at, "P")[index]
        J[-1, :-1] = row[index]
        step = np.linalg.solve(J, -F)
        Y[index] += step[:-1]
        Y[-1] += step[-1]
    raise ArithmeticError(f"no state with middle hoop stretch {target:g}: |F| = {np.abs(F).max():.2e}")


def past_the_fold(eq, branch, target):
    """Y = (u, P) of ``branch`` (a plugged tube's primary branch) past its pressure maximum whose middle hoop stretch
    ρ(L/2) is ``target`` (``at_middle`` from the point before the first crossing), None where it is not reached."""
    middle, offset = middle_row(branch.disc)
    amplitude = branch.states @ middle + offset
    crossing = np.flatnonzero((amplitude[:-1] - target) * (amplitude[1:] - target) <= 0)
    crossing = crossing[crossing >= np.argmax(branch.pressure)]
    if crossing.size == 0:
        return None
    return at_middle(eq, branch.params, np.append(branch.states[crossing[0]], branch.pressure[crossing[0]]), target)


def traced(preset, degree, held="", stop=5.0):
    """(its Equilibrium, the primary branch) of a plugged tube of length 10 (``SCENE``) at ``degree``."""
    scene = parse_scene(SCENE.format(preset=preset, length=10.0, held=held, degree=degree, stop=stop, step=0.1))
    branch = primary_branch(scene, degree)
    return Equilibrium(scene, branch.disc), branch


def test_closed_plugged_tube_has_no_odd_bifurcation():
    """SPOM1, closed, L = 10, to a hoop stretch of 5: at degrees 60 and 80 no odd branch point; at degree 80 ν > 0 at
    every point; at ρ(L/2) = 3 ν = 1.1359e-3 at both degrees within 1e-4 relative (measured 2.7e-5)."""
    values = []
    for degree in (60, 80):
        eq, branch = traced("SPOM1", degree)
        assert branch.branch_points(Mirror.ODD) == []
        mass = tube_mass(eq)
        values.append(odd_eigenvalue(eq, mass, past_the_fold(eq, branch, 3.0), branch.params))
    nu = [odd_eigenvalue(eq, mass, np.append(u, P), branch.params) for u, P in zip(branch.states, branch.pressure)]
    assert min(nu) > 0
    assert values[1] > 1e-3 and abs(values[0] - values[1]) <= 1e-4 * values[1]


@pytest.mark.slow
def test_held_plugged_tube_has_one_odd_branch_point_at_a_taut_state():
    """Gent, held at λ = 1.5, L = 10, to a hoop stretch of 5: at degree 80 one odd branch point, within 1e-4 in P of
    degree 60's first (measured 1.9e-5: P = 1.073424), its state taut (smallest stress 0.029), ν < −1e-2 past it."""
    firsts = []
    for degree in (60, 80):
        eq, branch = traced("Gent", degree, held="axial_stretch = 1.5\n")
        firsts.append(branch.branch_points(Mirror.ODD))
    (point,) = firsts[1]
    assert abs(point.pressure - firsts[0][0].pressure) <= 1e-4 and point.smallest_stress > 0
    mass = tube_mass(eq)
    beyond = [odd_eigenvalue(eq, mass, np.append(u, P), branch.params)
              for u, P in zip(branch.states[point.index + 1:], branch.pressure[point.index + 1:])]
    assert min(beyond) < -1e-2
