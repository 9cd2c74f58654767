"""The resolution of the tube over (S, φ) along a branch (tube/surface/resolution.py, tube/surface/branch.py): the
error estimate read against Legendre fits of the fields, the refinement policy, a capped basis flagged ``limited``,
and (slow) SPOM1's bulge's lateral buckle on its refined basis against a much larger one."""
import numpy as np
import pytest
from numpy.polynomial import legendre

from balloon_cg.tube.azimuthal import basis_values
from balloon_cg.tube.surface import resolution
from balloon_cg.tube.surface.basis import TubeSurfaceBasis
from balloon_cg.tube.surface.branch import traced_branch
from balloon_cg.tube.surface.resolution import error_estimate, refined, spectra, tails
from test_tube_surface import located_zeros, random_state, scene_and_disc
from test_tube_surface_branch import larger_point


@pytest.mark.parametrize("ends", ["sliding", "plugged"])
def test_the_spectra_are_the_fields_legendre_coefficients(ends):
    """e_k of ``spectra`` (over the mean radius) against numpy's Legendre fit of degree N, at 2N Gauss points, of
    every field: λ2 and η of order 0 (IntervalDiscretisation.series: the interval's own tail) and R, T, Z of orders
    1..3 from tube/azimuthal.basis_values (1e-12); the order maxima are each order's largest coefficient; an
    axisymmetric state's degree tail is IntervalDiscretisation.tail, its order tail 0."""
    scene, disc = scene_and_disc(ends)
    basis = TubeSurfaceBasis(disc, (0, 1, 2, 3))
    rng = np.random.default_rng(5)
    c = basis.axisymmetric(random_state(disc))
    for m in (1, 2, 3):
        c[basis.block(m)] = rng.normal(scale=0.1 / m**3, size=basis.mode_size)
    x, _ = legendre.leggauss(2 * disc.degree)
    hoop, axial = disc.series(c[basis.block(0)])
    fits = [np.abs(hoop), np.abs(axial)]
    for m in (1, 2, 3):
        R, _, Z, _, T, _ = basis_values(disc, x)
        fits += [np.abs(legendre.legfit(x, F @ c[basis.block(m)], disc.degree)) for F in (R, T, Z)]
    by_degree, by_order = spectra(basis, c)
    assert np.max(np.abs(by_degree * abs(hoop[0]) - np.max(fits, axis=0))) <= 1e-12
    assert np.allclose(by_order[1:] * abs(hoop[0]), [np.abs(c[basis.block(m)]).max() for m in (1, 2, 3)], rtol=1e-14)
    u = c[basis.block(0)]
    assert tails(basis, basis.axisymmetric(u)) == (disc.tail(u), 0.0)


def test_the_policy_refines_where_a_tail_is_large_and_stops_at_the_caps(monkeypatch):
    """``refined``: a resolved state keeps its basis (the same object); a state whose order tail passes max_error
    gets more orders (multiples of m), the degree kept while its tail is below; past MAX_HARMONICS or MAX_DEGREE
    None."""
    scene, disc = scene_and_disc("sliding")
    basis = TubeSurfaceBasis(disc, (0, 2, 4))
    c = basis.axisymmetric(random_state(disc, size=0.0))  # the uniform tube: exact in the basis
    c[basis.block(2)][0], c[basis.block(4)][0] = 1e-2, 1e-4
    degree_tail, order_tail = tails(basis, c)
    assert degree_tail <= 1e-12 and order_tail == pytest.approx(1e-4 / abs(c[0]))
    assert refined(basis, c, 2, 1e-3) is basis
    finer = refined(basis, c, 2, 1e-9)
    assert finer.disc == disc and finer.orders[:3] == (0, 2, 4) and len(finer.orders) > 3
    assert all(m % 2 == 0 for m in finer.orders)
    monkeypatch.setattr(resolution, "MAX_HARMONICS", 2)
    assert refined(basis, c, 2, 1e-9) is None


def test_a_capped_basis_flags_the_branch_limited(monkeypatch):
    """The held neo-Hookean tube's sideways buckle with the orders capped at m = 3: the trace goes on at the cap (all
    8 points), the branch ``limited``, its stop message saying so, the points past solver.max_error only after the
    cap was reached (a tail of the branch) and their estimates stored; uncapped, none past it and not limited."""
    scene, parent, found = located_zeros("held")
    free = traced_branch(scene, parent.disc, found[0], parent.params, max_points=8)
    assert not free.limited and np.all(free.error_estimate <= scene.solver.max_error)
    monkeypatch.setattr(resolution, "MAX_HARMONICS", 3)
    capped = traced_branch(scene, parent.disc, found[0], parent.params, max_points=8)
    past = capped.error_estimate > scene.solver.max_error
    assert capped.limited and "limited" in capped.stop.message and len(capped.pressure) == 8
    assert past.any() and np.all(past[np.argmax(past):]) and capped.basis.orders[-1] <= 3
    for k in np.flatnonzero(past):
        assert capped.error_estimate[k] == error_estimate(capped.basis, capped.coefficients[k])


@pytest.mark.slow
def test_spom1_lateral_buckle_converges_on_its_refined_basis():
    """SPOM1's bulge's first m = 1 zero (its lateral buckle; L = 10, the parent at degree 20 with a Legendre tail
    2.5e-4 there) traced to 16 points: the estimate below solver.max_error wherever the branch is not flagged
    (``limited`` only where a point past it follows the cap), and the last point (amplitude ~0.93) re-solved on a
    much larger basis, the degree raised by 16 and the orders by 4: P within the point's own estimate (relative),
    every coefficient within it times the mean radius."""
    scene, parent, found = located_zeros("bulge")
    zero = found[0]
    branch = traced_branch(scene, parent.disc, zero, parent.params, max_points=16)
    past = branch.error_estimate[1:] > scene.solver.max_error
    assert branch.limited or not past.any()
    k = len(branch.pressure) - 1 if not past.any() else int(np.argmax(past))
    assert branch.error_estimate[k] <= scene.solver.max_error and abs(branch.amplitude[k]) > 0.8
    point, start = larger_point(scene, parent, zero, branch, k, 16, 4)
    assert point.converged, point.message
    estimate = branch.error_estimate[k]
    radius = abs(branch.basis.disc.series(branch.coefficients[k][branch.basis.block(0)])[0][0])
    assert abs(point.pressure - branch.pressure[k]) <= estimate * abs(branch.pressure[k]), (point.pressure, estimate)
    assert np.max(np.abs(point.c - start)) <= estimate * radius, (np.max(np.abs(point.c - start)), estimate)
