"""The bulge branch on spectral elements (galerkin/interval_elements.py, tube/front.py): the basis against what it
claims (continuous piecewise polynomials, exact transfers to a split layout, the uniform tube exact), the bulge's
volume fold against the Legendre basis (a second discretisation), and the resolved branch of Ogden's 1972 rubber to
V/V0 = 52 (`-m slow`): every stored point's estimate at most solver.max_error, P at Maxwell's equal-area pressure
(computed in tests/test_tube_maxwell.py from the strain energy)."""
import numpy as np
import pytest
from numpy.polynomial import legendre

from balloon_cg.analysis.branches.problem import ParameterSystem
from balloon_cg.analysis.branches.resolution import Resolution
from balloon_cg.analysis.results import IntervalStop, Kind
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.galerkin.interval import IntervalDiscretisation
from balloon_cg.galerkin.interval_elements import collocated, element_interval
from balloon_cg.model import tube
from balloon_cg.numerics.newton import SparseFactors
from balloon_cg.scene import parse_scene
from balloon_cg.scene.loading import Control
from balloon_cg.scene.tables import Ends
from balloon_cg.tube.bulge import bulge_branch
from balloon_cg.tube.front import front_bulge, refined_layout
from balloon_cg.tube.primary import TubeSystem, held, primary_branch
from balloon_cg.tube.stability import ArrowPattern, _counts_by_one_factor, unstable_counts
from test_tube_maxwell import LENGTH, check_chain, maxwell, ogden_1972_tube  # noqa: F401 (the fixture)

BOUNDS = (-0.6, -0.1, 0.3, 0.75)
PRESSURE = 3.0  # the pressure term makes the Hessian of the test states indefinite


def random_state(disc, seed=2):
    rng = np.random.default_rng(seed)
    return disc.reference() * 1.3 + 0.05 * rng.standard_normal(disc.size)


def test_elements_are_continuous_polynomials_of_their_order():
    """On each element ρ and η are one polynomial of degree p in its t: a numpy fit of degree p through p + 1 points
    reproduces 50 others to 1e-12 (a fit of degree p − 1 does not), element_series' coefficients evaluated by numpy
    equal the profile, and both fields are continuous across every bound (1e-13)."""
    disc = element_interval(12.0, 7, BOUNDS)
    u = random_state(disc)
    edges = disc.edges
    hoop, axial = disc.element_series(u)
    for e in range(disc.count):
        t = np.linspace(-0.999, 0.999, 50)
        S = (edges[e] + 0.5 * (edges[e + 1] - edges[e]) * (t + 1) + 1) * disc.length / 2
        rho, eta = disc.profile(u, S)
        for values in (rho, eta):
            fit = np.polynomial.polynomial.Polynomial.fit(t[::7][:8], values[::7][:8], 7)
            assert np.abs(fit(t) - values).max() <= 1e-12 * np.abs(values).max()
            low = np.polynomial.polynomial.Polynomial.fit(t, values, 6)
            assert np.abs(low(t) - values).max() > 1e-6
        assert np.abs(legendre.legval(t, hoop[e]) - rho).max() <= 1e-12
        bubble_part = eta + u[disc.axial_index] * disc.length / 2 * (2 * S / disc.length - 1)
        assert np.abs(legendre.legval(t, axial[e]) - bubble_part).max() <= 1e-12
    for x in BOUNDS:
        S = (np.array([x - 1e-14, x + 1e-14]) + 1) * disc.length / 2
        rho, eta = disc.profile(u, S)
        assert abs(rho[0] - rho[1]) <= 1e-12 and abs(eta[0] - eta[1]) <= 1e-12


def test_split_layout_holds_the_state_and_uniform_tube_is_exact():
    """``collocated`` onto a layout with elements split (and of a higher order) gives the same ρ(S), η(S) (1e-13);
    the uniform tube of the closed-end path solves the element equations (its residual ≤ 1e-12) with a_0 = λθ."""
    disc = element_interval(12.0, 7, BOUNDS)
    finer = element_interval(12.0, 9, sorted(BOUNDS + (-0.8, 0.1, 0.5)))
    u = random_state(disc)
    S = np.linspace(0, 12.0, 301)
    moved = collocated(disc, u, finer)
    assert np.abs(np.array(disc.profile(u, S)) - np.array(finer.profile(moved, S))).max() <= 1e-12
    scene = ogden_1972_tube(20)
    state = tube.closed_end_state(scene.material, 1.4)
    eq = Equilibrium(scene, element_interval(LENGTH, 8, BOUNDS))
    u = eq.disc.uniform(state.hoop, state.axial)
    assert u[0] == state.hoop and np.abs(eq.residual(u, Parameters(state.pressure))).max() <= 1e-12


def test_element_energy_and_its_derivatives():
    """A state of the Legendre series of degree 7 (tested against the energy written in tests/test_interval.py) is
    one of elements of order 8 (``collocated``): E/(2π) and V/(2π) equal the series' (both quadratures fine enough
    to be exact to rounding: 1e-13 relative); R = ∂E/∂u and J = ∂R/∂u (element by element) against central
    differences, J symmetric."""
    scene = ogden_1972_tube(20)
    series = IntervalDiscretisation(7, LENGTH, quadrature=120)
    disc = element_interval(LENGTH, 8, BOUNDS, quadrature=40)
    rng = np.random.default_rng(4)
    u = series.reference() * 1.2 + 0.02 * rng.standard_normal(series.size) / (1 + np.arange(series.size) % 8)
    moved = collocated(series, u, disc)
    P = Parameters(0.8)
    on_series, on_elements = Equilibrium(scene, series), Equilibrium(scene, disc)
    assert abs(on_elements.energy(moved, P) - on_series.energy(u, P)) <= 1e-13 * abs(on_series.energy(u, P))
    assert abs(on_elements.volume(moved) - on_series.volume(u)) <= 1e-13 * abs(on_series.volume(u))
    h = 1e-6
    R = on_elements.residual(moved, P)
    gradient = [(on_elements.energy(moved + h * e, P) - on_elements.energy(moved - h * e, P)) / (2 * h)
                for e in np.eye(disc.size)]
    assert np.abs(R - gradient).max() <= 1e-7 * np.abs(R).max()
    J = on_elements.jacobian(moved, P)
    assert np.abs(J - J.T).max() <= 1e-13 * np.abs(J).max()
    difference = np.column_stack([(on_elements.residual(moved + h * e, P) - on_elements.residual(moved - h * e, P))
                                  / (2 * h) for e in np.eye(disc.size)])
    assert np.abs(J - difference).max() <= 1e-7 * np.abs(J).max()


@pytest.mark.parametrize("ends, stretch", [("sliding", None), ("sliding", 1.1), ("plugged", None)])
def test_sparse_and_arrow_factors_are_the_dense_ones(ends, stretch):
    """The fast paths on elements against the dense matrices they stand for, at a state with negative eigenvalues:
    the sparse bordered Jacobian equals the dense one (to rounding), J v without J equals J v, SuperLU's bordered
    solve the dense solve; the Hessian on the free unknowns in ``arrow_order`` is banded with half-bandwidth 2p + 1
    but for its last (global) columns, and the arrow LDLᵀ's inertia is numpy's eigenvalues' count and its solve H⁻¹r;
    the three unstable counts equal the counts of eigvalsh of H, of H on g⊥ (a null-space basis) and of
    H + (P/Ṽ) g gᵀ."""
    scene = ogden_1972_tube(20)
    disc = element_interval(LENGTH, 6, BOUNDS, Ends(ends), axial_stretch=stretch)
    eq = Equilibrium(scene, disc)
    rng = np.random.default_rng(7)
    free = disc.free
    u = disc.reference() * 1.5 + 0.05 * rng.standard_normal(disc.size)
    P = Parameters(PRESSURE)
    system = TubeSystem(ParameterSystem(eq, P, "P"), free, held(disc))
    X = np.append(u, PRESSURE)[system.columns]
    u = system.full(X)[:-1]  # held ends: λ̄ at its distance
    J = system.jacobian(X)
    dense = eq.bordered_jacobian(u, P, "P")[np.ix_(free, system.columns)]
    assert np.abs(J.toarray() - dense).max() <= 1e-13 * np.abs(dense).max()
    v = rng.standard_normal(X.size)
    assert np.abs(system.jacobian_vector(X, v) - dense @ v).max() <= 1e-13 * np.abs(dense).max() * np.abs(v).max()
    row, rhs = rng.standard_normal(X.size), rng.standard_normal(X.size)
    solved = SparseFactors(J, row).solve(rhs)
    assert np.allclose(solved, np.linalg.solve(np.vstack([dense, row]), rhs), rtol=0, atol=1e-10 * np.abs(solved).max())
    H = eq.jacobian(u, P)[np.ix_(free, free)]
    order, local, width = disc.arrow_order(free)
    assert width == 2 * disc.order + 1
    rows, columns = np.nonzero(H[np.ix_(order, order)][:local, :local])
    assert np.abs(rows - columns).max() == width
    pattern = ArrowPattern(eq.sparse_jacobian(u, P), free, (order, local, width))
    arrow = pattern.factor(eq.sparse_jacobian(u, P))
    assert arrow.negatives == np.count_nonzero(np.linalg.eigvalsh(H) < 0) > 0
    r = rng.standard_normal(free.size)
    x = np.empty(free.size)
    x[order] = arrow.solve(r[order])
    assert np.abs(H @ x - r).max() <= 1e-9 * np.abs(r).max()
    g = -eq.parameter_derivative(u, P, "P")[free]
    weight = PRESSURE / eq.volume(u)
    basis = np.linalg.svd(g[None, :])[2][1:].T  # an orthonormal basis of g⊥
    expected = [np.count_nonzero(np.linalg.eigvalsh(M) < 0)
                for M in (H, basis.T @ H @ basis, H + weight * np.outer(g, g))]
    assert _counts_by_one_factor(eq, u, P, pattern, g, weight) is not None  # the arrow decided them
    counts = unstable_counts(eq, [np.append(u, PRESSURE)], Parameters(0.0))
    assert [int(counts[c][0]) for c in (Control.PRESSURE, Control.VOLUME, Control.GAS)] == expected


@pytest.mark.slow
def test_bulge_fold_on_elements_is_the_legendre_bases_fold():
    """Ogden 1972, L = 30: the bulge switched at the onset onto 15 equal elements of order 20 and traced to
    V/V0 = 3 locates its volume fold where the Legendre series of degree 120 does (P 1e-9, V/V0 1e-8; docs/tubes.md:
    degrees 120 and 160 agree to 3e-15; measured 4.9e-14 in P), and its branch's points carry their tails (149 s on
    the loaded machine: `-m slow`)."""
    scene = ogden_1972_tube(24)
    primary = primary_branch(scene)
    onset = primary.branch_points()[0]
    disc = element_interval(LENGTH, 20, np.linspace(-1, 1, 16)[1:-1])
    branch = bulge_branch(scene, primary, onset, stop_volume=3.0 * np.pi * LENGTH, step=0.02, on=disc)
    (fold,) = [s for s in branch.special if s.kind == Kind.LV]
    volume = 2 * Equilibrium(scene, disc).volume(fold.u) / LENGTH
    assert abs(fold.pressure - 1.240702968978) <= 1e-9 and abs(volume - 2.145050161885) <= 1e-8
    assert branch.tail.shape == branch.pressure.shape and np.all(branch.tail < 1e-6)


def test_refined_layout_cuts_the_elements_whose_tails_pass():
    """Elements whose largest tail passes max_error are cut into k ≥ 2 equal ones (k from the tail's excess), the
    others kept; none passing: the same layout."""
    disc = element_interval(12.0, 8, BOUNDS)
    tails = np.full((3, disc.count), 1e-12)
    tails[1, 2] = 1e-7
    tails[2, 4] = 3e-9
    finer = refined_layout(disc, tails, 1e-9)
    edges = disc.edges
    assert set(BOUNDS) <= set(finer.bounds)
    assert sum(edges[2] < b < edges[3] for b in finer.bounds) == 3  # (1e-7/1e-9)^(1/4) = 3.2: 4 pieces
    assert sum(edges[4] < b < edges[5] for b in finer.bounds) == 1
    assert refined_layout(disc, np.full((3, disc.count), 1e-10), 1e-9) == disc


def test_local_refinement_continues_the_trace_on_finer_layouts(monkeypatch):
    """SPOM1, L = 10, from 4 elements of order 12 to a hoop stretch of 2.5: front_bulge refines the layout where a
    traced point needs it (measured three times: 5, 6, then 7 elements) and continues without retracing: every
    stored point's tail ≤ max_error; the first traced point, from the first layout, lies in that layout's space
    (collocated there and back: 1e-12) and is its equilibrium (|R| ≤ 1e-9 there; measured 1.3e-13); the last point is
    the last layout's (|R| ≤ 1e-9); the volume fold is where the whole branch traced from the onset on the last
    layout (the retrace the local refinement saves, a second trace) has it: P within max(1e-9 relative, the tails of
    the fold's neighbours) (measured 1.8e-15), V/V0 likewise (measured 0). With a cap of 60 unknowns per field (5 elements of order
    12) the branch stops UNRESOLVED at the first point that needed more, saying so, every stored point resolved."""
    import balloon_cg.tube.front as front

    scene = parse_scene('[material]\npreset = "SPOM1"\n[geometry]\nshape = "tube"\nlength = 10.0\n[solver]\n'
                        'degree = 16\n')
    primary = primary_branch(scene)
    onset = primary.branch_points()[0]
    counts, refined = [], front.refined_layout
    monkeypatch.setattr(front, "refined_layout", lambda *a: counts.append((found := refined(*a)).count) or found)
    first = front.uniform_layout(scene, 4, 12)
    branch = front_bulge(scene, primary, onset, Resolution(1e-9, 400), layout=first, stop_stretch=2.5)
    assert len(counts) >= 2 and counts == sorted(counts) and branch.disc.count == counts[-1]
    assert branch.stop.code == IntervalStop.HOOP_STRETCH and branch.tail.max() <= 1e-9
    on_first = collocated(branch.disc, branch.states[1], first)
    assert np.abs(collocated(first, on_first, branch.disc) - branch.states[1]).max() <= 1e-12
    for disc, u, P in ((first, on_first, branch.pressure[1]), (branch.disc, branch.states[-1], branch.pressure[-1])):
        free = disc.free
        assert np.abs(Equilibrium(scene, disc).residual(u, Parameters(P))[free]).max() <= 1e-9
    whole = bulge_branch(scene, primary, onset, on=branch.disc, max_error=1e-9, stop_stretch=2.5)
    (fold,), (again,) = ([s for s in b.special if s.kind == Kind.LV] for b in (branch, whole))
    error = max(1e-9 * abs(again.pressure), *branch.tail[fold.index: fold.index + 2])
    assert abs(fold.pressure - again.pressure) <= error
    eq = Equilibrium(scene, branch.disc)
    assert abs(eq.volume(fold.u) - eq.volume(again.u)) <= max(1e-9, error) * eq.volume(again.u)
    capped = front_bulge(scene, primary, onset, Resolution(1e-9, 60), layout=first, stop_stretch=2.5)
    assert capped.stop.code == IntervalStop.UNRESOLVED and "the layout's cap of 60 unknowns" in capped.stop.message
    assert "\n" not in capped.stop.message
    assert capped.disc.degree <= 60 and capped.tail.max() <= 1e-9 and len(capped.pressure) < len(branch.pressure)


@pytest.mark.slow
def test_resolved_bulge_reaches_maxwells_pressure_with_every_point_resolved(maxwell):  # noqa: F811
    """Ogden 1972, L = 30: the bulge on elements refined locally by tube/front.front_bulge to V/V0 = 52 (order 16, E p
    up to 400 per field: measured 22 elements at the end, 352), every stored point's estimate ≤ solver.max_error
    (1e-9; measured 9.8e-10 to V/V0 = 50: benchmarks/tube_front_speed.py), and the acceptance's chain (test_tube_maxwell.check_chain: the onset,
    one LV, V rising beyond it, |P − P_M| ≤ 1e-6 from V/V0 = 50, stable under volume control; measured 6.0e-8, the
    finite tube's approach to the plateau, docs/tubes.md); the fold where the Legendre series of degree 120 has it
    (1e-10)."""
    scene = ogden_1972_tube(24)
    primary = primary_branch(scene)
    onset = primary.branch_points()[0]
    branch = front_bulge(scene, primary, onset, Resolution(scene.solver.max_error, 400), stop_volume=52.0 * np.pi * LENGTH, step=0.02)
    assert branch.tail.max() <= scene.solver.max_error
    fold = check_chain(onset, branch, maxwell[0], 52.0)
    volume = 2 * Equilibrium(scene, branch.disc).volume(fold.u) / LENGTH
    assert abs(fold.pressure - 1.240702968978) <= 1e-10 and abs(volume - 2.145050161885) <= 1e-10


def test_run_traces_the_bulge_on_elements_and_its_file_reads_back(tmp_path):
    """solver.tube_resolution = "elements" (SPOM1, L = 10, to a hoop stretch of 2.5): ``run``'s bulge branch is on
    spectral elements with every point within max_error and its m = 1 blocks assessed on them; the file stores the
    layout, the branch read back is on it (the same unknowns, ρ(S) to rounding) and ``inspect`` reads the file."""
    from balloon_cg.app.cli import main
    from balloon_cg.io.tube_file import read_tube_run, stored_branch, write_tube_run
    from balloon_cg.tube.primary import scene_parameters
    from shared_pictures import first_bulge_picture

    scene = parse_scene('[material]\npreset = "SPOM1"\n[geometry]\nshape = "tube"\nlength = 10.0\n[solver]\n'
                        'degree = 16\ntube_resolution = "elements"\n[continuation]\nstop_stretch = 2.5\n')
    picture = first_bulge_picture(scene)
    bulge = picture.branches["bulge"]
    assert bulge.disc.order > 0 and bulge.tail.max() <= scene.solver.max_error
    assert len(picture.modes["bulge"].lowest[1]) == len(bulge.pressure)
    path = write_tube_run(tmp_path / "tube.h5", scene, picture)
    read = stored_branch(read_tube_run(path), "bulge", scene_parameters(scene))
    assert read.disc == bulge.disc and np.array_equal(read.states, bulge.states)
    S = np.linspace(0, 10.0, 51)
    assert np.abs(read.disc.profile(read.states[-1], S)[0] - bulge.disc.profile(bulge.states[-1], S)[0]).max() == 0
    assert main(["inspect", str(path)]) == 0


def test_a_fold_found_on_an_earlier_layout_is_located_again_on_the_stored_one(monkeypatch):
    """tube_spom1_L10's bulge on its default elements: its volume fold lies in a step of a layout the trace later
    refines (tube/bulge._relocated runs: counted), and the stored fold is an equilibrium of the stored layout
    (|R| ≤ solver.tol on its free rows; measured 7.6e-15) and V's extremum there: its two neighbours' volumes lie
    on the same side of the fold's."""
    import balloon_cg.tube.bulge as bulge
    from balloon_cg.scene import load_scene
    from shared_pictures import first_bulge_picture

    relocated, original = [], bulge._relocated
    monkeypatch.setattr(bulge, "_relocated", lambda *a: relocated.append(1) or original(*a))
    scene = load_scene("tube_spom1_L10")
    branch = first_bulge_picture(scene).branches["bulge"]
    assert relocated and scene.solver.tube_resolution == "elements"
    (fold,) = [s for s in branch.special if s.kind == Kind.LV]
    eq = Equilibrium(scene, branch.disc)
    assert np.abs(eq.residual(fold.u, Parameters(fold.pressure))[branch.disc.free]).max() <= scene.solver.tol
    volumes = [eq.volume(u) for u in branch.states[fold.index:fold.index + 2]]
    assert np.sign(volumes[0] - eq.volume(fold.u)) == np.sign(volumes[1] - eq.volume(fold.u)), volumes
