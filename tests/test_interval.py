"""The tube over an interval (galerkin/interval.py, tube/primary.py) against the energy written here and
the uniform closed tube of model/tube.py (the oracle: its closed-end path, pressure maximum and bulge onset).

A tube of radius 1 and length L over its arclength S, meridian downwards (Z = −S): per 2π its energy is
E = ∫_0^L [Φ(λ1, λ2) + ½ P ρ² η'] dS with ρ = λ2, λ1 = sqrt(ρ'² + η'²) (the second term −P V/(2π), the volume
between the end planes π∫ρ²(−η')dS).
"""
import functools

import numpy as np
import pytest
import sympy
from numpy.polynomial import legendre
from scipy import optimize

from balloon_cg.tube.primary import primary_branch
from balloon_cg.galerkin.discretisation import Discretisation
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.galerkin.interval import IntervalDiscretisation, Mirror
from balloon_cg.model import tube
from balloon_cg.model.kernels import KernelSet
from balloon_cg.analysis.results import IntervalStop, StopCode
from balloon_cg.app.cli import main
from balloon_cg.scene import Control, parse_scene
from balloon_cg.scene.validation import SceneError


def tube_scene(preset="SPOM1", length=10.0, extra=""):
    return parse_scene(f'[material]\npreset = "{preset}"\n[geometry]\nshape = "tube"\nlength = {length}\n{extra}')


def ogden(material, l1, l2):
    """Φ = Σ μ_i/α_i (λ1^α_i + λ2^α_i + (λ1λ2)^−α_i − 3)."""
    return sum(m / a * (l1**a + l2**a + (l1 * l2) ** -a - 3) for m, a in zip(material.mu, material.alpha))


def bubble_series(n, b):
    """The Legendre coefficients of Σ_k b_k (P_{k+2} − P_k), k ≤ n − 2."""
    c = np.zeros(n + 1)
    c[2:] += b
    c[: n - 1] -= b
    return c


@functools.lru_cache(maxsize=8)
def gauss_rule(nodes: int) -> tuple:
    """numpy's Gauss–Legendre rule (its eigenvalue solve is most of ``series``' time, computed once per size)."""
    return legendre.leggauss(nodes)


def series(disc, u, nodes=200):
    """(weights per dS, λ1, λ2, η') at a Gauss rule of ``nodes`` points, λ2 and η from the Legendre series of u (the
    bubbles P_{k+2} − P_k as Legendre coefficients; plugged ends: λ2 = 1 + bubbles) by numpy."""
    n, L, k = disc.degree, disc.length, disc.axial_index
    a, stretch, b = u[:k], u[k], u[k + 1:]
    if disc.ends == "plugged":
        a = bubble_series(n, a)
        a[0] += 1.0
    c = bubble_series(n, b)
    x, w = gauss_rule(nodes)
    rate = 2 / L * legendre.legval(x, legendre.legder(a))
    slope = -stretch + 2 / L * legendre.legval(x, legendre.legder(c))
    return L / 2 * w, np.hypot(rate, slope), legendre.legval(x, a), slope


def energy_written_here(material, disc, u, P):
    """E/(2π) of the module docstring."""
    weights, lam1, lam2, slope = series(disc, u)
    return weights @ (ogden(material, lam1, lam2) + 0.5 * P * lam2**2 * slope)


def test_tube_kernels_are_the_sphere_kernels_at_its_equator_node():
    """The tube's kernels (generated on demand, R' = 0, R = 1, S' = 1 folded in: codegen/meridian.py) take no node
    coordinate and equal the committed sphere kernels at cos θ = 0, sin θ = 1 (whose R', R and S' are the same) at
    random states; the tube's module has no pole series and no first-order system in θ."""
    scene = tube_scene("SPOM1")
    tube_kernels, sphere_kernels = KernelSet.of_scene(scene), KernelSet(scene.material)
    assert "pole_series" not in tube_kernels.module.KERNELS and "rhs" not in tube_kernels.module.KERNELS
    rng = np.random.default_rng(5)
    state = dict(zip(("lam2", "v", "eta", "w"), (1 + rng.random(9), rng.standard_normal(9), rng.standard_normal(9),
                                                 -0.5 - rng.random(9))))
    for kernel in ("energy_density", "energy_gradient", "energy_hessian", "pressure_gradient"):
        assert all(name not in ("cos_theta", "sin_theta") for name, _, _ in tube_kernels.module.KERNELS[kernel]["args"])
        ours = tube_kernels.nodes(kernel, state, Parameters(0.7))
        sphere = sphere_kernels.nodes(kernel, state | {"cos_theta": np.zeros(9), "sin_theta": np.ones(9)},
                                      Parameters(0.7))
        assert np.abs(ours - sphere).max() <= 1e-13 * np.abs(sphere).max()


@pytest.mark.parametrize("ends", ["sliding", "plugged"])
def test_discrete_energy_and_residual_are_those_written_here(ends):
    """At a non-uniform state: E/(2π) and V/(2π) to 1e-13 (relative), R = ∂E/∂u against central differences of the
    energy written here, J symmetric and the derivative of R."""
    scene = tube_scene("SPOM1", 7.0, f'ends = "{ends}"\n')
    disc = IntervalDiscretisation(10, 7.0, quadrature=120, ends=scene.geometry.ends)  # quadrature error < rounding
    eq = Equilibrium(scene, disc)
    rng = np.random.default_rng(3)
    u = disc.reference() * 1.2 + 0.02 * rng.standard_normal(disc.size) / (1 + np.arange(disc.size) % 11)
    P = 0.8
    E = energy_written_here(scene.material, disc, u, P)
    assert abs(eq.energy(u, Parameters(P)) - E) <= 1e-13 * abs(E)
    h = 1e-6
    gradient = [(energy_written_here(scene.material, disc, u + h * e, P)
                 - energy_written_here(scene.material, disc, u - h * e, P)) / (2 * h) for e in np.eye(disc.size)]
    R = eq.residual(u, Parameters(P))
    assert np.abs(R - gradient).max() <= 1e-8 * np.abs(R).max()
    J = eq.jacobian(u, Parameters(P))
    assert np.abs(J - J.T).max() <= 1e-13 * np.abs(J).max()
    difference = np.column_stack([(eq.residual(u + h * e, Parameters(P)) - eq.residual(u - h * e, Parameters(P)))
                                  / (2 * h) for e in np.eye(disc.size)])
    assert np.abs(J - difference).max() <= 1e-7 * np.abs(J).max()
    weights, _, lam2, slope = series(disc, u)
    assert eq.volume(u) == pytest.approx(-weights @ (0.5 * lam2**2 * slope), rel=1e-13)  # V/(2π)


@pytest.mark.parametrize("ends", ["sliding", "plugged"])
def test_crests_are_the_largest_radius_among_the_roots_of_its_slope(ends):
    """The crest (IntervalDiscretisation.crests) of random non-uniform states, several at once and one alone, against
    numpy's: the largest ρ among the ends and the real roots in [−1, 1] of ρ's derivative series (legroots, a
    companion-matrix eigensolve), and η there from the series: S to 1e-9 L, η to 1e-10."""
    L = 7.0
    disc = IntervalDiscretisation(12, L, ends=ends)
    rng = np.random.default_rng(5)
    states = disc.reference() * 1.2 + 0.05 * rng.standard_normal((6, disc.size)) / (1 + np.arange(disc.size) % 13)
    S, eta = disc.crests(states)
    n, k = disc.degree, disc.axial_index
    for u, s, h in zip(states, S, eta):
        a = u[:k] if ends == "sliding" else bubble_series(n, u[:k]) + np.eye(n + 1)[0]
        roots = legendre.legroots(legendre.legder(a))
        x = np.concatenate([[-1.0, 1.0], roots[(abs(roots.imag) < 1e-12) & (abs(roots.real) <= 1)].real])
        top = x[np.argmax(legendre.legval(x, a))]
        assert abs(s - (top + 1) * L / 2) <= 1e-9 * L
        assert abs(h - (-u[k] * L / 2 * top + legendre.legval(top, bubble_series(n, u[k + 1:])))) <= 1e-10
        assert disc.crest(u) == (s, h)


def uniform_balances(material):
    """(P(λθ, λz), N(λθ, λz)) of the uniform closed tube, derived here from the energy per 2π and unit reference
    length e = Φ(λz, λθ) − ½Pλθ²λz (``ogden`` above, differentiated by SymPy): ∂e/∂λθ = 0 is the hoop balance
    P = Φ_2/(λθλz), ∂e/∂λz = 0 the closed-end axial balance N = Φ_1 − λθΦ_2/(2λz) = 0 (the plugs' faces carry
    Pπλθ², nothing else)."""
    hoop, axial = sympy.symbols("hoop axial", positive=True)
    phi = ogden(material, axial, hoop)
    phi_2 = sympy.diff(phi, hoop)
    return (sympy.lambdify((hoop, axial), phi_2 / (hoop * axial)),
            sympy.lambdify((hoop, axial), sympy.diff(phi, axial) - hoop * phi_2 / (2 * axial)))


@pytest.mark.parametrize("preset", ["SPOM1", "neo-Hookean"])
def test_uniform_tube_is_an_exact_state(preset):
    """The closed-end state of model/tube.py at λθ = 1.2, 1.6, 2.5 has a zero residual (the uniform tube is exact in
    the basis: the hoop balance, the closed-end axial balance in the row of λ̄); the traced primary branch is that
    path at every point (λ̄ = λz(λθ), P(λθ) and V/V0 = λθ²λz to 1e-10, the non-uniform coefficients zero), and
    every point satisfies P = Φ_2/(λθλz) and N = 0 derived here (``uniform_balances``, 1e-12)."""
    scene = tube_scene(preset, 10.0).with_overrides({"solver.degree": 16, "continuation.stop_stretch": 2.2})
    disc = IntervalDiscretisation(16, 10.0)
    eq = Equilibrium(scene, disc)
    for hoop in (1.2, 1.6, 2.5):
        state = tube.closed_end_state(scene.material, hoop)
        R = eq.residual(disc.uniform(state.hoop, state.axial), Parameters(state.pressure))
        assert np.abs(R).max() <= 1e-13 * state.pressure
    branch = primary_branch(scene)
    assert branch.stop.code == IntervalStop.HOOP_STRETCH and len(branch.pressure) > 20
    k = disc.axial_index
    hoop_balance, axial_balance = uniform_balances(scene.material)
    for u, P, V in zip(branch.states, branch.pressure, branch.volume):
        state = tube.closed_end_state(scene.material, u[0])
        assert abs(u[k] - state.axial) <= 1e-10 and abs(P - state.pressure) <= 1e-10
        assert abs(P - hoop_balance(u[0], u[k])) <= 1e-12 * (1 + P) and abs(axial_balance(u[0], u[k])) <= 1e-12
        assert abs(V - u[0] ** 2 * u[k]) <= 1e-10
        assert np.abs(np.delete(u, [0, k])).max() <= 1e-10


@pytest.mark.parametrize("preset", ["SPOM1", "neo-Hookean", "Gent"])
@pytest.mark.parametrize("length", [10.0, 40.0])
def test_first_branch_point_is_the_bulge_onset(preset, length):
    """Along the uniform branch: stable under pressure control up to the fold in P, under volume control up to the
    first branch point; the fold in P is model/tube.pressure_maximum (1e-10) and the first branch point is
    in the mirror-odd block at model/tube.bulge_onset of the mode cos(πS/L) (λθ, λz, P to 1e-8); its null vector
    is that mode: λ2 ∝ cos(πS/L), η ∝ sin(πS/L) (to 1e-8 in the sample's sup norm). SPOM1, neo-Hookean and Gent
    (a strain energy's kernels on a tube)."""
    scene = tube_scene(preset, length).with_overrides({"solver.degree": 20, "continuation.stop_stretch": 1.75})
    branch = primary_branch(scene)
    disc, k = branch.disc, branch.disc.axial_index
    peak = tube.pressure_maximum(scene.material, largest_hoop=3.0)  # Gent's closed-end path ends near λθ = 6
    folds = [s for s in branch.special if s.kind == "LP"]
    assert len(folds) == 1 and folds[0].status == "located"
    assert abs(folds[0].u[0] - peak.hoop) <= 1e-10 and abs(folds[0].pressure - peak.pressure) <= 1e-10
    onset = tube.bulge_onset(scene.material, length, largest_hoop=3.0)
    first = branch.branch_points()[0]
    assert first.block == Mirror.ODD and first.status == "located"
    assert first.index >= folds[0].index  # the onset beyond the maximum
    unstable = branch.unstable
    assert np.all(unstable[Control.PRESSURE][: folds[0].index + 1] == 0)
    assert np.all(unstable[Control.PRESSURE][folds[0].index + 1:] >= 1)
    assert np.all(unstable[Control.VOLUME][: first.index + 1] == 0)
    assert np.all(unstable[Control.VOLUME][first.index + 1:] >= 1)
    assert abs(first.u[0] - onset.hoop) <= 1e-8
    assert abs(first.u[k] - onset.axial) <= 1e-8
    assert abs(first.pressure - onset.pressure) <= 1e-8
    eq = Equilibrium(scene, disc)
    odd = disc.block(Mirror.ODD)
    H = eq.jacobian(first.u, Parameters(first.pressure))[np.ix_(odd, odd)]
    mode = np.zeros(disc.size)
    mode[odd] = np.linalg.eigh(H)[1][:, 0]
    s = np.linspace(0, length, 101)
    rho, eta = disc.profile(mode, s)
    scale = rho[0]
    assert np.abs(rho - scale * np.cos(np.pi * s / length)).max() <= 1e-8 * abs(scale)
    amplitude = eta[50]
    assert np.abs(eta - amplitude * np.sin(np.pi * s / length)).max() <= 1e-8 * abs(scale)
    assert abs(amplitude) > 1e-3 * abs(scale)


def test_later_branch_points_are_the_higher_modes():
    """SPOM1, L = 10, to λθ = 2.3: the branch points of the uniform branch are the modes cos(nπS/L), n = 1..4, in
    the odd, even, odd, even block, each at model/tube.bulge_onset(mode = n) (λθ and P to 1e-8; measured 1e-14)."""
    scene = tube_scene("SPOM1", 10.0).with_overrides({"solver.degree": 30, "continuation.stop_stretch": 2.3})
    branch = primary_branch(scene)
    points = branch.branch_points()
    assert [p.block for p in points] == [Mirror.ODD, Mirror.EVEN, Mirror.ODD, Mirror.EVEN]
    for n, point in enumerate(points, start=1):
        onset = tube.bulge_onset(scene.material, 10.0, mode=n)
        assert abs(point.u[0] - onset.hoop) <= 1e-8 and abs(point.pressure - onset.pressure) <= 1e-8


def first_integral(material, disc, u):
    """H = λ1Φ_1 − Φ at 401 points along the tube (module docstring: ρ'∂π/∂ρ' + η'∂π/∂η' − π, the pressure's
    term linear in η' dropping out; constant along S on an equilibrium, the Noether integral of axial translation),
    Φ_1 = Σ μ_i (λ1^(α_i − 1) − λ1^(−α_i − 1) λ2^(−α_i)) written here."""
    _, lam1, lam2, _ = series(disc, u, 401)
    phi_1 = sum(m * (lam1 ** (a - 1) - lam1 ** (-a - 1) * lam2**-a) for m, a in zip(material.mu, material.alpha))
    return lam1 * phi_1 - ogden(material, lam1, lam2)


def test_bulge_branch_from_the_onset_through_its_volume_fold():
    """SPOM1, L = 10: the branch switched at the first (odd) branch point bulges at S = 0, its V/V0 falls to a
    located minimum (LV: P and V/V0 at degrees 30 and 40 within 1e-9; measured 3e-11) and then rises while P falls,
    beyond V/V0 = 50 up to the stop at 60, with P above Maxwell's pressure (model/tube.maxwell_pressure, checked
    against the equal-area rule in tests/test_tube.py). Unstable (one direction) under pressure control throughout;
    under volume control one unstable direction up to the fold and stable beyond it (the plateau). Near the fold
    the state solves the continuous problem: the first integral H (written here) is constant along the tube to
    1e-6 (measured 4e-8 at degree 40)."""
    from balloon_cg.tube.bulge import bulge_branch

    folds = []
    for degree in (30, 40):
        scene = tube_scene("SPOM1", 10.0).with_overrides({"solver.degree": degree, "continuation.stop_stretch": 1.75,
                                                          "continuation.step_max": 0.5})
        primary = primary_branch(scene)
        branch = bulge_branch(scene, primary, primary.branch_points()[0], stop_volume=60.0 * np.pi * scene.geometry.length, step=0.02)
        assert branch.stop.code == StopCode.STOP_VOLUME and abs(branch.volume[-1] - 60) < 1e-9 * 60
        eq = Equilibrium(scene, branch.disc)
        folds.append([(s, 2 * eq.volume(s.u) / 10.0) for s in branch.special if s.kind == "LV"])  # V/V0
    assert len(folds[0]) == len(folds[1]) == 1
    ((coarse, coarse_volume),), ((fold, fold_volume),) = folds
    assert fold.status == "located"
    assert abs(coarse.pressure - fold.pressure) <= 1e-9 and abs(coarse_volume - fold_volume) <= 1e-9
    disc = branch.disc
    assert branch.pressure[0] == primary.branch_points()[0].pressure
    rho, _ = disc.profile(branch.states[5], np.array([0.0, 10.0]))
    assert rho[0] > rho[1]
    after = slice(fold.index + 1, None)
    assert np.all(np.diff(branch.volume[after]) > 0) and np.all(np.diff(branch.pressure[after]) < 0)
    assert branch.volume[fold.index] > fold_volume and branch.volume[fold.index + 1] > fold_volume
    maxwell, _, _ = tube.maxwell_pressure(scene.material)
    assert branch.pressure[-1] > maxwell
    unstable = branch.unstable
    assert np.all(unstable[Control.PRESSURE][1:] == 1)
    assert np.all(unstable[Control.VOLUME][1: fold.index + 1] == 1) and np.all(unstable[Control.VOLUME][after] == 0)
    H = first_integral(scene.material, disc, fold.u)
    assert np.abs(H - H.mean()).max() <= 1e-6 * abs(H.mean())


def test_neo_hookean_bulge_keeps_falling_without_a_maxwell_state():
    """Neo-Hookean, L = 10: the uniform closed tube's P(λθ) = 2(1 − λz⁻²λθ⁻⁴)/λz (``uniform_balances`` on N = 0)
    falls for ever beyond its maximum (P → 0: checked here from λθ* to 50), so no two uniform states share a pressure
    beyond it and there is no Maxwell state (model/tube.maxwell_pressure is None). The bulge branch switched at the
    onset passes its volume fold (LV) and then P keeps falling as V/V0 grows to 100 (every step; no plateau; the last
    kept point is the one before the stop), and the propagating bulge of SPOM1's plateau has no counterpart: P at
    the last point is below a third of the onset's (measured: 0.352 at V/V0 = 96.9 against 1.4991)."""
    from balloon_cg.tube.bulge import bulge_branch

    scene = tube_scene("neo-Hookean", 10.0).with_overrides({"solver.degree": 40, "continuation.stop_stretch": 1.75,
                                                            "continuation.step_max": 0.5})
    assert tube.maxwell_pressure(scene.material) is None
    hoop_balance, axial_balance = uniform_balances(scene.material)
    peak = tube.pressure_maximum(scene.material)
    hoops = np.linspace(peak.hoop, 50.0, 400)
    axial = [optimize.brentq(lambda a: axial_balance(h, a), 0.5, 50.0, xtol=1e-14) for h in hoops]
    uniform = np.array([hoop_balance(h, a) for h, a in zip(hoops, axial)])
    assert np.all(np.diff(uniform) < 0) and uniform[-1] < 0.1 * uniform[0]
    primary = primary_branch(scene)
    onset = primary.branch_points()[0]
    branch = bulge_branch(scene, primary, onset, stop_volume=100.0 * np.pi * scene.geometry.length, step=0.02)
    assert branch.stop.code == StopCode.STOP_VOLUME and abs(branch.volume[-1] - 100) < 1e-9 * 100  # landed on it
    folds = [s for s in branch.special if s.kind == "LV"]
    assert len(folds) == 1 and folds[0].status == "located"
    assert np.all(np.diff(branch.pressure[1:]) < 0)  # falling, through the fold and beyond: no plateau
    assert branch.pressure[-1] < onset.pressure / 3


def test_plugged_tube_has_a_pressure_maximum_above_the_uniform_one():
    """Plugged ends (ρ = 1 at both ends, closed): SPOM1, L = 10, the primary branch's fold in P at degrees 30 and 40
    within 1e-10 (measured 1.7e-13); ρ(0) = ρ(L) = 1; at the fold the first integral H (written here) is constant
    along the tube to 1e-6 (measured 5e-8 at degree 40): the state solves the continuous problem with the plugs'
    conditions. The plugs stiffen the tube: the maximum lies above the uniform closed tube's and approaches it as L
    grows (L = 5, 10, 20 at degree 40: 0.123, 0.0204, 0.00253 above; each gap below a fifth of the last)."""
    peak = tube.pressure_maximum(tube_scene().material)
    folds = {}
    for length, degree in ((10.0, 30), (10.0, 40), (5.0, 40), (20.0, 40)):
        scene = tube_scene("SPOM1", length, 'ends = "plugged"\n').with_overrides(
            {"solver.degree": degree, "continuation.stop_stretch": 1.8})
        branch = primary_branch(scene)
        found = [s for s in branch.special if s.kind == "LP"]
        assert len(found) == 1 and found[0].status == "located"
        folds[length, degree] = found[0]
    assert abs(folds[10.0, 30].pressure - folds[10.0, 40].pressure) <= 1e-10
    fold, disc = folds[10.0, 40], IntervalDiscretisation(40, 10.0, ends=scene.geometry.ends)
    rho, _ = disc.profile(fold.u, np.array([0.0, 10.0]))
    assert np.abs(rho - 1).max() <= 1e-14
    H = first_integral(scene.material, disc, fold.u)
    assert np.abs(H - H.mean()).max() <= 1e-6 * abs(H.mean())
    gaps = [folds[length, 40].pressure - peak.pressure for length in (5.0, 10.0, 20.0)]
    assert gaps[0] > 5 * gaps[1] > 0 and gaps[1] > 5 * gaps[2] > 0


def test_mirror_blocks_split_the_hessian_of_a_symmetric_state():
    """On a mirror-symmetric non-uniform state the Hessian has no entries between the even and odd blocks, and the
    blocks partition the unknowns."""
    scene = tube_scene("SPOM1", 6.0)
    disc = IntervalDiscretisation(9, 6.0)
    even, odd = disc.block(Mirror.EVEN), disc.block(Mirror.ODD)
    assert sorted(np.concatenate([even, odd])) == list(range(disc.size))
    u = np.zeros(disc.size)
    u[even] = disc.uniform(1.4, 1.1)[even] + 0.03 / (1 + np.arange(even.size))
    J = Equilibrium(scene, disc).jacobian(u, Parameters(1.0))
    assert np.abs(J[np.ix_(even, odd)]).max() <= 1e-14 * np.abs(J).max()


@pytest.mark.parametrize("table, message", [
    ("length = 10\n", 'geometry.length = 10: only for geometry.shape = "tube"'),
    ('shape = "tube"\n', "geometry.length: missing; a tube needs its length in reference radii, in [0.1, 1000]"),
    ('shape = "tube"\nlength = 0\n', "geometry.length = 0: must be in [0.1, 1000]"),
    ('shape = "tube"\nlength = "long"\n', 'geometry.length = "long": '),
    ('shape = "tube"\nlength = 10\nends = "glued"\n', 'geometry.ends = "glued": must be one of "sliding"'),
    ('shape = "tube"\nlength = 10\naspect = 2\n', 'geometry.aspect = 2: only for geometry.shape = "spheroid"'),
    ('shape = "spheroid"\naspect = 2\nends = "sliding"\n', 'geometry.ends = "sliding": only for geometry.shape'),
])
def test_tube_table_errors_name_key_value_and_range(table, message):
    with pytest.raises(SceneError, match="^scene: " + message.replace("[", r"\[").replace("(", r"\(")) as error:
        parse_scene(f'[material]\npreset = "SPOM1"\n[geometry]\n{table}')
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("extra, message", [
    ("[field]\nM = 0.001\n[[field.coils]]\nradius = 2\nheight = 1\ncurrent = 1\n",
     'geometry.shape = "tube": the coils around a tube must be coaxial and mirror-symmetric about its middle'),
    ("[field]\nM = 0.001\n[[field.coils]]\nradius = 0.8\nheight = 3\ncurrent = 1\n[[field.coils]]\nradius = 0.8\n"
     "height = -3\ncurrent = 1\n",
     r"field.coils\[0\]: wire at \(radius 0.8, height 3\) lies on or inside the reference tube"),
    ('[electric]\n[continuation]\nparameter = "voltage"\npressure = 0.5\n',
     r"stability.m_max = 1: a tube's voltage continuation \(continuation.parameter = \"voltage\"\) reads the m = 0 "
     "stability only for now; allowed: 0"),
    ("[dynamics]\nfrequencies = true\nmodes = true\n", "dynamics.modes = true: a tube's mode shapes are not stored"),
    ('ends = "plugged"\n[[events]]\nquantity = "lam2_top"\nvalue = 1.2\n',
     r'events\[0\].quantity = "lam2_top": the plugs hold the hoop stretch at a plugged tube\'s ends at 1'),
])
def test_tube_refuses_the_parts_it_does_not_have(extra, message):
    with pytest.raises(SceneError, match=message) as error:
        tube_scene("SPOM1", 10.0, extra)
    assert "\n" not in str(error.value)


def test_tube_scene_round_trips_and_the_sphere_pipeline_refuses_it(tmp_path, capsys):
    scene = tube_scene("SPOM1", 12.5)
    assert parse_scene(scene.to_toml()).geometry == scene.geometry
    assert scene.geometry.ends == "sliding" and scene.geometry.length == 12.5
    with pytest.raises(SceneError, match='^geometry.shape = "tube": this command is not built for a tube yet'):
        Equilibrium(scene, Discretisation(10, True, True))
    path = tmp_path / "tube.toml"
    path.write_text(scene.to_toml())
    code, err = main(["solve", str(path), "--pole-stretch", "2"]), capsys.readouterr().err
    assert code == 2, err  # a tube's solve takes --hoop-stretch (tests/test_tube_solve.py)
    assert len(err.strip().splitlines()) == 1 and "a tube has no pole" in err


@pytest.mark.slow
def test_bulge_propagates_at_maxwells_pressure():
    """SPOM1, L = 20 (43 s on the loaded machine with one BLAS thread, 254 s before): the bulge branch to
    V/V0 = 420. Where its front is far from both ends (V/V0 ≥ 320) P is within 1e-6 of Maxwell's pressure
    (model/tube.maxwell_pressure, checked against the equal-area rule in tests/test_tube.py; measured ≤ 5.2e-7,
    1.2e-9 at V/V0 = 415), the same P(V) at degree 140 within 1e-7 (measured 2.3e-8: the pressure converges
    although the steep front is not resolved pointwise, the first integral varying along the tube by 6–16 % at
    degree 100: docs/tubes.md), and under volume control the plateau is stable. The front (post/tube_measures.front,
    its mid-level point S_f in the reference arclength) joins Maxwell's two states a and b (ρ at the last point within
    1e-3 of λθ_a and 5e-3 of λθ_b; measured 1e-4, 2.5e-3) and moves by the lever rule of the sharp front,
    V/V0 = v_a + (S_f/L)(v_b − v_a) with v = λθ²λz: S_f − L(V/V0 − v_a)/(v_b − v_a) is constant on the plateau to 3e-3
    (measured: 1.8e-3 at both degrees, the front moving by 2.3 radii): the front translates without changing."""
    from balloon_cg.tube.bulge import bulge_branch

    curves = {}
    for degree in (100, 140):
        scene = tube_scene("SPOM1", 20.0).with_overrides({"solver.degree": degree, "continuation.stop_stretch": 1.75,
                                                          "continuation.step_max": 0.5,
                                                          "continuation.max_points": 1000})
        primary = primary_branch(scene)
        branch = bulge_branch(scene, primary, primary.branch_points()[0], stop_volume=420.0 * np.pi * scene.geometry.length, step=0.02)
        assert branch.stop.code == StopCode.STOP_VOLUME
        curves[degree] = branch
    maxwell, _, _ = tube.maxwell_pressure(scene.material)
    coarse, fine = curves[100], curves[140]
    plateau = coarse.volume >= 320
    assert plateau.sum() > 50 and np.all(np.diff(fine.volume[fine.volume >= 300]) > 0)
    assert np.abs(coarse.pressure[plateau] - maxwell).max() <= 1e-6
    finer = np.interp(coarse.volume[plateau], fine.volume, fine.pressure)
    assert np.abs(coarse.pressure[plateau] - finer).max() <= 1e-7
    assert np.all(coarse.unstable[Control.VOLUME][plateau] == 0)
    from balloon_cg.post.tube_measures import front

    _, a, b = tube.maxwell_pressure(scene.material)
    va, vb = a.hoop**2 * a.axial, b.hoop**2 * b.axial
    s = np.linspace(0.0, 20.0, 4001)
    for branch in (coarse, fine):
        fronts = [front(s, branch.disc.profile(u, s)[0]) for u in branch.states[branch.volume >= 320]]
        offset = [f.position - 20.0 * (v - va) / (vb - va) for f, v in zip(fronts, branch.volume[branch.volume >= 320])]
        assert np.ptp(offset) <= 3e-3
        assert abs(fronts[-1].low - a.hoop) <= 1e-3 and abs(fronts[-1].high - b.hoop) <= 5e-3
