"""Natural frequencies of a tube (balloon_cg.dynamics.tube) against the vibrations of the uniform inflated cylinder.

Units as the sphere's (tests/test_dynamics.py): lengths over the reference radius, E/2π = ∫_0^L Φ(λ1, λ2) dS − P V/2π
(the strain energy per reference area over μ/2, V/2π = −½ ∫ ρ² η' dS), kinetic energy per 2π ½ ∫ (ρ̇² + η̇²) dS, and
Ω² = ν/2 for K u = ν M u.

Uniform state: ρ = a, η = −b (S − L/2) (hoop stretch a, axial b). ∂/∂a of L Φ(b, a) − P · ½ a² b L gives the hoop
balance P = Φ2/(a b); with closed ends whose distance is free, ∂/∂b gives the axial one Φ1 = ½ P a².

Small vibrations. ρ = a + ε U cos κS, η = −b(S − L/2) + ε W sin κS, κ = kπ/L: ρ' = −ε U κ sin κS, η' = −b + ε W κ cos κS,
so λ1 = sqrt(ρ'² + η'²) = b − ε W κ c + ε² U² κ² s²/(2b) + O(ε³) and λ2 = a + ε U c (c = cos κS, s = sin κS). The ε²
part of Φ is Φ1 U² κ² s²/(2b) + ½ Φ11 W² κ² c² − Φ12 κ U W c² + ½ Φ22 U² c², that of V/2π is ½ b U² c² − a κ U W c²;
with ∫c² = ∫s² = L/2 (k ≥ 1; L for k = 0, W absent), K = 2 × the ε² part and M = ∫(δρ² + δη²) dS:

    K = (L/2) [[Φ1 κ²/b + Φ22 − P b,  (P a − Φ12) κ], [(P a − Φ12) κ, Φ11 κ²]],    M = (L/2) I,

Ω² = eig(K, M)/2. These displacements vanish at the ends for every k (δη(0) = δη(L) = 0, ρ' = 0 there): with the ends
held apart (λ̄ fixed) they are the modes of every k, k even in the even mirror block, odd in the odd one; with closed
ends whose distance is free the odd k are (their inertia does work neither on the ends' symmetric motion nor on the
uniform modes); volume control removes k = 0 (δV = L a b U for k = 0, 0 for k ≥ 1).
"""
import json

import h5py
import numpy as np
import pytest
import sympy as sp
from scipy import linalg
from scipy.optimize import brentq

import balloon_cg as bc
from balloon_cg.analysis.results import Kind, Status
from balloon_cg.app.cli import main
from balloon_cg.dynamics.tube import (tube_branch_frequencies, tube_frequencies, tube_mass, tube_matching_block,
                                      with_frequencies)
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.galerkin.interval import Mirror
from balloon_cg.io.tube_file import read_tube_run, stored_branch
from balloon_cg.scene import load_scene, shipped_scenes
from balloon_cg.tube.picture import tube_picture
from balloon_cg.tube.primary import discretisation, scene_parameters
from balloon_cg.tube.stability import COMPRESSED

from shared_pictures import first_bulge_picture

SPOM1 = ((3.00508, 0.0145, -0.0177), (1.3, 4.0, -2.0))  # (μ_i, α_i), Σ μ_i α_i = 4
COUNT = 6


def ogden_derivatives():
    """Φ1, Φ2, Φ11, Φ12, Φ22 of Φ = Σ (μ/α)(λ1^α + λ2^α + (λ1 λ2)^−α − 3) as functions of (λ1, λ2)."""
    l1, l2 = sp.symbols("l1 l2", positive=True)
    phi = sum(sp.nsimplify(m) / sp.nsimplify(a) * (l1**sp.nsimplify(a) + l2**sp.nsimplify(a)
                                                   + (l1 * l2)**(-sp.nsimplify(a)) - 3) for m, a in zip(*SPOM1))
    terms = (sp.diff(phi, l1), sp.diff(phi, l2), sp.diff(phi, l1, 2), sp.diff(phi, l1, l2), sp.diff(phi, l2, 2))
    return sp.lambdify((l1, l2), terms)


DERIVATIVES = ogden_derivatives()


def closed_axial(a):
    """The axial stretch b of the closed tube of hoop stretch a: Φ1(b, a) = ½ a² Φ2(b, a)/(a b)."""
    def balance(b):
        phi1, phi2, *_ = DERIVATIVES(b, a)
        return phi1 - a * phi2 / (2 * b)
    return brentq(balance, 0.3, 10.0, xtol=1e-15, rtol=1e-15)


def dispersion(a, b, length, k):
    """The Ω² of the mode k of the uniform tube (a, b) at its pressure (module docstring): two for k ≥ 1, one for 0."""
    phi1, phi2, phi11, phi12, phi22 = DERIVATIVES(b, a)
    P = phi2 / (a * b)
    if k == 0:
        return np.array([(phi22 - P * b) / 2])
    kappa = k * np.pi / length
    K = np.array([[phi1 * kappa**2 / b + phi22 - P * b, (P * a - phi12) * kappa],
                  [(P * a - phi12) * kappa, phi11 * kappa**2]])
    return linalg.eigvalsh(K) / 2  # M = I after the common factor L/2


def lowest(a, b, length, ks, count=COUNT):
    return np.sort(np.concatenate([dispersion(a, b, length, k) for k in ks]))[:count]


def uniform_frequencies(hoop, held: bool):
    """(Ω² per block of the tube of tube_spom1_L10 at the uniform state of hoop stretch ``hoop``, its (a, b, L)):
    held ends at the closed tube's own axial stretch (the same state, another constraint)."""
    b = closed_axial(hoop)
    scene = load_scene("tube_spom1_L10")
    if held:
        scene = scene.with_overrides({"geometry.axial_stretch": b})
    disc = discretisation(scene)
    eq = Equilibrium(scene, disc)
    u = disc.uniform(hoop, b)
    P = DERIVATIVES(b, hoop)[1] / (hoop * b)
    residual = eq.residual(u, Parameters(P))[disc.free]
    assert np.abs(residual).max() <= 1e-11  # the state and P of the docstring are the code's equilibrium
    return tube_frequencies(eq, tube_mass(eq), u, Parameters(P), True, COUNT), (hoop, b, disc.length)


@pytest.mark.parametrize("hoop", [1.3, 2.0, 4.0])
def test_held_tube_modes_are_the_uniform_cylinders_vibrations(hoop):
    """Ends held at the closed tube's axial stretch, hoop stretches 1.3 (stable), 2.0 and 4.0 (beyond the pressure
    maximum of the closed tube): the even block's 6 lowest Ω² are the k = 0, 2, 4, ... closed forms, the odd
    block's the k = 1, 3, 5, ..., even_volume's the k = 2, 4, ... ones, to 1e-9 (relative above 1)."""
    omega2, (a, b, length) = uniform_frequencies(hoop, held=True)
    expected = {"even": lowest(a, b, length, range(0, 40, 2)), "odd": lowest(a, b, length, range(1, 40, 2)),
                "even_volume": lowest(a, b, length, range(2, 40, 2))}
    for block, values in expected.items():
        assert np.abs(omega2[block] - values).max() <= 1e-9 * max(1.0, np.abs(values).max()), (block, omega2[block],
                                                                                                values)


@pytest.mark.parametrize("hoop", [1.3, 4.0])
def test_closed_tube_odd_modes_are_the_uniform_cylinders_vibrations(hoop):
    """Closed ends with their distance free: the odd block's 6 lowest Ω² are the k = 1, 3, 5, ... closed forms (1e-9);
    the even block holds the ends' motion and is not a closed form."""
    omega2, (a, b, length) = uniform_frequencies(hoop, held=False)
    values = lowest(a, b, length, range(1, 40, 2))
    assert np.abs(omega2["odd"] - values).max() <= 1e-9 * max(1.0, np.abs(values).max())


@pytest.fixture(scope="module")
def tube_run():
    """tube_spom1_L10 with [dynamics] frequencies (count 6): its primary and bulge branches (``run``'s, without the
    branches switched at the later branch points: shared_pictures.first_bulge_picture) with_frequencies, and their
    frequencies; the bulge on the default spectral elements (its fold's Ω² a Ritz value, numerics/eigen.lowest_ritz:
    a dense solve's read ±3e-11 there, ε times the layout's highest mode; benchmarks/tube_frequency_ritz.py), without
    the m ≥ 1 blocks (stability.m_max = 0: ~30 of the ~40 s of CPU on elements; the branches are the same), its steps
    at most 0.1 (the scene's 0.5 spaces the bulge's points near its fold too far apart for the interpolation check
    below since the element trace grows its step after 4 corrector iterations, tube/bulge.EASY_NEWTON_ELEMENTS)."""
    scene = load_scene("tube_spom1_L10").with_overrides({"dynamics.frequencies": True, "dynamics.count": COUNT,
                                                         "stability.m_max": 0, "continuation.step_max": 0.1})
    picture = with_frequencies(scene, first_bulge_picture(scene))
    return scene, picture, picture.frequencies


def located_zeros(scene, picture) -> list:
    """(branch, kind, block) of every located point of a tube picture with frequencies, after checking that the
    points around it differ by one in its block's negative Ω² (the eigenvalue that crossed: not the lowest at the
    later branch points) and, where its state is in tension (smallest_stress ≥ COMPRESSED: a compressed state
    would wrinkle and is not to be trusted, tube/stability.py), that one Ω² of its block is zero to solver.tol."""
    kinds = []
    for name, branch in picture.branches.items():
        symmetric = bool(branch.lowest)
        for n, s in enumerate(branch.special):
            if s.status != Status.LOCATED:
                continue
            block = tube_matching_block(s, symmetric)
            frequencies = picture.frequencies[name]
            if s.smallest_stress >= COMPRESSED:
                assert np.nanmin(np.abs(frequencies.special[block][n])) <= scene.solver.tol, (name, s.kind, block)
            around = frequencies.omega2[block][s.index:s.index + 2]
            assert np.diff((around < 0).sum(axis=1)) != 0, (name, s.kind, around)
            kinds.append((name, s.kind, block))
    return kinds


def test_located_tube_points_have_a_vanishing_frequency_in_their_block(tube_run):
    """tube_spom1_L10 (primary and bulge branches): at the pressure maximum (LP, even block), every branch point of
    the primary branch (the bulge modes, odd and even blocks) and the bulge branch's fold in V (all_volume) one Ω²
    of the matching block is zero (``located_zeros``)."""
    scene, picture, _ = tube_run
    kinds = located_zeros(scene, picture)
    assert all(s.smallest_stress >= COMPRESSED for b in picture.branches.values() for s in b.special)
    assert ("primary", Kind.LP, "even") in kinds and ("primary", Kind.BP, Mirror.ODD.value) in kinds, kinds
    assert ("bulge", Kind.LV, "all_volume") in kinds, kinds


def test_the_volume_blocks_lowest_frequency_crosses_zero_at_the_located_fold(tube_run):
    """A second check of the bulge's fold in V on elements: Ω²(P) of the volume block at the stored points, an
    interpolating polynomial through k of them on each side of the fold (degree 2k − 1), has its zero at the located
    fold's pressure, the more closely the more points: k = 1, 2, 3 off by ≤ 3e-4, 1e-6, 1e-7 (measured 1.1e-4,
    1.5e-7, 8.8e-9 on the 197 points of the scene's own steps before tube/bulge.EASY_NEWTON_ELEMENTS; on its 90 now
    5.1e-4, 3.8e-6, 1.5e-6: the fixture's steps are at most 0.1; P is monotone there), and the fold's own Ω² is zero to 1e-13 (measured 5.7e-16)."""
    scene, picture, frequencies = tube_run
    branch = picture.branches["bulge"]
    assert branch.disc.count > 1  # spectral elements
    n, fold = next((n, s) for n, s in enumerate(branch.special) if s.kind == Kind.LV)
    omega2 = frequencies["bulge"].omega2["all_volume"][:, 0]
    assert abs(frequencies["bulge"].special["all_volume"][n, 0]) <= 1e-13
    for k, bound in zip((1, 2, 3), (3e-4, 1e-6, 1e-7)):
        around = slice(fold.index + 1 - k, fold.index + 1 + k)
        P, values = branch.pressure[around], omega2[around]
        assert np.all(np.diff(P) < 0) and values[0] * values[-1] < 0
        roots = np.roots(np.polyfit(P, values, 2 * k - 1))
        zero = roots[np.argmin(np.abs(roots - fold.pressure))]
        assert abs(zero.imag) == 0 and abs(zero.real - fold.pressure) <= bound, (k, zero, fold.pressure)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(n for n in shipped_scenes() if n.startswith("tube_")))
def test_every_located_point_of_a_shipped_tube_scene_has_a_zero_frequency(name):
    """Every shipped tube scene with [dynamics] frequencies: ``located_zeros`` on its whole picture (the coil scene's
    points ≤ 1e-11; its branches stop where the membrane turns compressed)."""
    scene = load_scene(name).with_overrides({"dynamics.frequencies": True, "dynamics.count": COUNT})
    assert located_zeros(scene, with_frequencies(scene, tube_picture(scene)))


@pytest.fixture(scope="module")
def frequency_run(tmp_path_factory):
    """``run`` of tube_spom1_L10 at degree 16 to a hoop stretch of 3 with [dynamics] frequencies (count 4), every
    branch point switched: (its scene file, its run file)."""
    folder = tmp_path_factory.mktemp("frequencies")
    scene_file, path = folder / "tube.toml", folder / "tube.h5"
    scene_file.write_text(load_scene("tube_spom1_L10").text.replace("degree = 40", "degree = 16")
                          .replace("stop_stretch = 9.0", "stop_stretch = 3.0")
                          + "\n[dynamics]\nfrequencies = true\ncount = 4\n")
    assert main(["run", str(scene_file), "-o", str(path), "--quiet"]) == 0
    return scene_file, path


def test_tube_frequencies_are_stored_with_units_and_shown_by_inspect(frequency_run, capsys):
    """``run`` of a tube scene with [dynamics] frequencies (degree 16, to hoop stretch 3, primary and bulge): the file
    holds every branch's Ω² of tube_branch_frequencies number for number, units "1" (of the branches as stored: that
    they are tube_picture's number for number is test_tube_cli's test_run_writes_what_the_tube_pipeline_computes, at
    these settings); ``inspect`` lists each located point's lowest Ω² per block (the LP's even one zero), ``--json``
    per branch block → lowest Ω² over the points."""
    scene_file, path = frequency_run
    scene = load_scene(scene_file)
    run = read_tube_run(path)
    assert {"primary", "bulge"} < set(run["branches"])
    for name in run["branches"]:
        branch = stored_branch(run, name, scene_parameters(scene))
        expected, stored = tube_branch_frequencies(scene, branch, 4), run["branches"][name]["frequencies"]
        assert stored["count"] == 4 and set(stored["omega2"]) == set(expected.omega2)
        for block in expected.omega2:
            assert np.array_equal(stored["omega2"][block], expected.omega2[block], equal_nan=True)
            assert np.array_equal(stored["special"][block], expected.special[block], equal_nan=True)
    with h5py.File(path) as f:
        assert f["branches/primary/frequencies/omega2_odd"].attrs["units"] == "1"
    assert main(["inspect", str(path)]) == 0
    text = capsys.readouterr().out
    lp = next(line for line in text.split("branch primary")[1].splitlines() if " LP " in line)
    after = text.split(lp)[1].splitlines()[1]
    assert after.strip().startswith("lowest Ω²") and abs(float(after.split("even ")[1].split()[0])) < 1e-9
    assert main(["inspect", str(path), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)["branches"]
    assert summary["bulge"]["frequencies"]["all_volume"] == list(run["branches"]["bulge"]["frequencies"]["omega2"]
                                                                 ["all_volume"][:, 0])


def test_a_tube_sweep_stores_each_members_frequencies(tmp_path):
    """``sweep --primary-only`` over a tube scene with [dynamics] frequencies (length 8, degree 16, to hoop stretch
    3): the member holds the frequencies of its scene's run alone, number for number."""
    scene_file = tmp_path / "tube.toml"
    scene_file.write_text(load_scene("tube_spom1_L10").text.replace("degree = 40", "degree = 16")
                          .replace("stop_stretch = 9.0", "stop_stretch = 3.0")
                          + "\n[dynamics]\nfrequencies = true\ncount = 2\n")
    assert main(["sweep", str(scene_file), "--vary", "geometry.length=8", "-o", str(tmp_path / "sweep.h5"),
                 "--workers", "1", "--primary-only", "--quiet"]) == 0
    alone = tmp_path / "alone.h5"
    assert main(["run", str(scene_file), "--set", "geometry.length=8", "-o", str(alone), "--primary-only",
                 "--quiet"]) == 0
    stored = bc.load(tmp_path / "sweep.h5").members[0].branches["primary"]["frequencies"]
    expected = read_tube_run(alone)["branches"]["primary"]["frequencies"]
    assert set(stored["omega2"]) == {"even", "even_volume", "odd"} and stored["count"] == 2
    for key in ("omega2", "special"):
        for block, values in expected[key].items():
            assert np.array_equal(stored[key][block], values, equal_nan=True)


def test_continue_at_the_onset_keeps_the_frequencies(frequency_run, tmp_path):
    """``continue`` of a tube run with [dynamics] frequencies at its onset label (degree 16, hoop stretch 3): the
    written primary and bulge branches carry the frequencies of the run's, number for number."""
    run, again = frequency_run[1], tmp_path / "again.h5"
    first = read_tube_run(run)
    label = next(k for k, s in enumerate(first["branches"]["primary"]["special_points"])
                 if (s["kind"], s["block"]) == ("BP", "odd"))
    assert main(["continue", str(run), str(label), "-o", str(again)]) == 0
    for name, branch in read_tube_run(again)["branches"].items():
        expected = first["branches"][name]["frequencies"]
        for key in ("omega2", "special"):
            assert set(branch["frequencies"][key]) == set(expected[key])
            for block, values in expected[key].items():
                assert np.array_equal(branch["frequencies"][key][block], values, equal_nan=True), (name, block)
