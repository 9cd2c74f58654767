"""A tube's accuracy measures (tube/accuracy.py) and its resolution policy (tube/resolution.py): the Legendre tail
against the series' true neglected tail, a branch stopping or retraced where the tail passes max_error, and the
first integral H = λ1Φ_1 − Φ, constant along an exact solution, varying less along the tube as the degree grows."""
import numpy as np
from numpy.polynomial import legendre

from balloon_cg.analysis.branches.resolution import Resolution
from balloon_cg.analysis.results import IntervalStop, Kind, StopCode
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.galerkin.interval import IntervalDiscretisation
from balloon_cg.model import tube
from balloon_cg.tube.accuracy import first_integral, first_integral_spread
from balloon_cg.tube.bulge import bulge_branch
from balloon_cg.tube.primary import primary_branch
from balloon_cg.tube.resolution import resolved_bulge_branch
from shared_pictures import first_bulge_picture
from test_interval import ogden, tube_scene

FOLD = (1.3628306751130, 2.7222883983230)  # SPOM1, L = 10: the bulge's volume fold (P, V/V0), docs/tubes.md


def spom1_l10(degree: int):
    return tube_scene("SPOM1", 10.0).with_overrides({"solver.degree": degree, "continuation.stop_stretch": 1.75,
                                                     "continuation.step_max": 0.5})


def test_tail_bounds_the_neglected_coefficients():
    """λ2 = 1 + 2 sech((S − 2)/1.5) on L = 10 (numpy's Legendre fit at degree 220, to rounding) truncated at
    N = 20, 30, 40, 60: the estimate lies between the true neglected tail Σ_{k>N} |c_k|/|c_0| and 10 times it
    (measured 2.6–6.6×); the uniform tube (exact in the basis) has none."""
    x = np.cos(np.pi * (np.arange(2000) + 0.5) / 2000)
    c = legendre.legfit(x, 1 + 2 / np.cosh((5 * (x + 1) - 2.0) / 1.5), 220)
    for degree in (20, 30, 40, 60):
        disc = IntervalDiscretisation(degree, 10.0)
        u = disc.uniform(1.0, 1.2)
        u[: degree + 1] = c[: degree + 1]
        true = np.abs(c[degree + 1:]).sum() / abs(c[0])
        assert true <= disc.tail(u) <= 10 * true
    assert IntervalDiscretisation(30, 10.0).tail(IntervalDiscretisation(30, 10.0).uniform(2.0, 1.5)) == 0.0


def test_bulge_branch_stops_where_its_tail_passes_max_error():
    """SPOM1, L = 10, degree 30, max_error 1e-5: the bulge grows steeper after its volume fold and its tail passes
    1e-5 near V/V0 = 3 (measured 4.4e-5 at V/V0 = 3.01): the branch stops there with IntervalStop.UNRESOLVED, every
    stored point within max_error, the fold (tail 2.7e-7) located before it; without max_error the same trace runs on
    to V/V0 = 4 with unresolved points (tail up to 7e-4)."""
    scene = spom1_l10(30)
    primary = primary_branch(scene)
    stopped = bulge_branch(scene, primary, primary.branch_points()[0], stop_volume=4.0 * np.pi * 10.0, step=0.02, max_error=1e-5)
    assert stopped.stop.code == IntervalStop.UNRESOLVED
    assert stopped.tail.max() <= 1e-5 and 2.8 < stopped.volume[-1] < 3.5
    assert [s.kind for s in stopped.special] == [Kind.LV]
    free = bulge_branch(scene, primary, primary.branch_points()[0], stop_volume=4.0 * np.pi * 10.0, step=0.02)
    assert free.stop.code == StopCode.STOP_VOLUME and free.tail.max() > 1e-4
    same = len(stopped.volume)
    assert np.array_equal(free.states[:same], stopped.states) and np.array_equal(free.tail[:same], stopped.tail)


def test_unresolved_bulge_is_retraced_at_a_higher_degree():
    """The same with the policy max_error 1e-5, max_degree 100: retraced from degree 30 at 45 and 67 (the
    policy's growth 1.5), where it reaches V/V0 = 4 resolved (degree 60's tail there: 3.1e-6); its fold at the
    converged one (docs/tubes.md: degrees 30–120 agree to 3e-11) within 1e-9. With max_degree 30 it is the stopped
    branch of degree 30."""
    _, branch = resolved_bulge_branch(spom1_l10(30), stop_volume=4.0 * np.pi * 10.0, step=0.02, policy=Resolution(1e-5, 100))
    assert branch.disc.degree == 67 and branch.stop.code == StopCode.STOP_VOLUME
    assert branch.tail.max() <= 1e-5 and abs(branch.volume[-1] - 4.0) <= 1e-9
    ((fold, volume),) = [(s, 2 * Equilibrium(spom1_l10(67), branch.disc).volume(s.u) / 10.0) for s in branch.special
                         if s.kind == Kind.LV]
    assert abs(fold.pressure - FOLD[0]) <= 1e-9 and abs(volume - FOLD[1]) <= 1e-9
    _, capped = resolved_bulge_branch(spom1_l10(30), stop_volume=4.0 * np.pi * 10.0, step=0.02, policy=Resolution(1e-5, 30))
    assert capped.disc.degree == 30 and capped.stop.code == IntervalStop.UNRESOLVED and capped.tail.max() <= 1e-5


def test_first_integral_is_constant_on_exact_states_and_falls_with_the_degree():
    """H at the nodes (tube/accuracy.first_integral) is λ1Φ_1 − Φ written here (test_interval.ogden, Φ_1 by a
    central difference) at a random state; on the uniform closed tube (exact) its spread is rounding (1e-13); at
    the bulge's volume fold, located at degrees 30, 40, 60, it falls more than 30× per step (measured 3.2e-6,
    3.5e-8, 7.3e-12), as the stored per-point spread does at the branch's last point, V/V0 = 4 (measured 6.2e-3,
    1.1e-3, 4.3e-5)."""
    scene = spom1_l10(30)
    eq = Equilibrium(scene, IntervalDiscretisation(30, 10.0))
    u = eq.disc.uniform(1.4, 1.1) + 0.01 * np.random.default_rng(3).standard_normal(eq.disc.size)
    hoop, rate, _, slope = eq.disc.node_state(u)
    axial, h = np.hypot(rate, slope), 1e-6
    phi_1 = (ogden(scene.material, axial + h, hoop) - ogden(scene.material, axial - h, hoop)) / (2 * h)
    written = axial * phi_1 - ogden(scene.material, axial, hoop)
    assert np.abs(first_integral(eq, u) - written).max() <= 1e-8 * np.abs(written).max()
    state = tube.closed_end_state(scene.material, 1.7)
    assert first_integral_spread(eq, eq.disc.uniform(state.hoop, state.axial)) <= 1e-13
    folds, ends = [], []
    for degree in (30, 40, 60):
        scene = spom1_l10(degree)
        primary = primary_branch(scene)
        branch = bulge_branch(scene, primary, primary.branch_points()[0], stop_volume=4.0 * np.pi * 10.0, step=0.02)
        (fold,) = [s for s in branch.special if s.kind == Kind.LV]
        folds.append(first_integral_spread(Equilibrium(scene, branch.disc), fold.u))
        ends.append(branch.first_integral[-1])
    assert folds[0] > 30 * folds[1] > 900 * folds[2] and ends[0] > ends[1] > ends[2]


def test_run_file_stores_each_points_tail_and_first_integral(tmp_path):
    """A tube run file (io/tube_file.py) holds per point of every branch ``tail`` and ``first_integral_spread``:
    the bulge branch's those it was traced with, bit for bit; the primary branch's (uniform, exact in the basis: its
    other coefficients zero to the Newton tolerance, test_interval.test_uniform_tube_is_an_exact_state) ≤ 1e-10
    (measured 6.7e-14 and 3.4e-13 to a hoop stretch of 2.5), and they read back through TubeResult's points table;
    ``inspect`` counts the points whose tail is above solver.max_error and shows the largest."""
    from balloon_cg.app.tube_result import TubeResult
    from balloon_cg.app.tube_summary import format_tube, summarise_tube
    from balloon_cg.io.tube_file import read_tube_run, write_tube_run

    scene = spom1_l10(20).with_overrides({"continuation.stop_stretch": 2.5, "stability.m_max": 0,
                                          "solver.tube_resolution": "flag"})  # a bulge with unresolved points
    picture = first_bulge_picture(scene)  # run's primary and bulge branches (shared_pictures.py)
    path = write_tube_run(tmp_path / "tube.h5", scene, picture)
    branches = read_tube_run(path)["branches"]
    bulge = picture.branches["bulge"]
    assert np.array_equal(branches["bulge"]["tail"], bulge.tail) and bulge.tail.max() > 1e-8
    assert np.array_equal(branches["bulge"]["first_integral_spread"], bulge.first_integral)
    assert branches["primary"]["tail"].max() <= 1e-10 and branches["primary"]["first_integral_spread"].max() <= 1e-10
    table = TubeResult.read(path).to_dataframe()
    assert {"tail", "first_integral_spread"} <= set(table.columns)
    summary = summarise_tube(read_tube_run(path))["branches"]
    assert summary["bulge"]["unresolved_points"] == (bulge.tail > 1e-9).sum() > 0  # solver.max_error: the default
    assert summary["bulge"]["largest_tail"] == bulge.tail.max() and summary["primary"]["unresolved_points"] == 0
    assert f"{summary['bulge']['unresolved_points']} points unresolved" in format_tube(summarise_tube(
        read_tube_run(path)))


def refined_scene(max_degree: int):
    """``spom1_l10(30)`` to V/V0 = 4 (step 0.02, m = 0, stop_stretch 6: past the bulge's V/V0 = 4) with max_error 1e-5
    and solver.tube_resolution = "refine"."""
    return spom1_l10(30).with_overrides({"solver.max_error": 1e-5, "solver.max_degree": max_degree,
                                         "solver.tube_resolution": "refine", "continuation.stop_volume": 40.0 * np.pi,
                                         "continuation.step": 0.02, "continuation.stop_stretch": 6.0,
                                         "stability.m_max": 0})


def test_run_refines_the_bulge_to_max_error_where_the_scene_asks(tmp_path, capsys):
    """``run`` with solver.tube_resolution = "refine" (max_error 1e-5, max_degree 100): the bulge branch of
    test_unresolved_bulge_is_retraced_at_a_higher_degree, retraced to degree 67, is written with the primary branch of
    that degree: every point's tail ≤ 1e-5, the end at V/V0 = 4, its fold at the converged one (1e-9); exit 0. With
    max_degree 30 it stops unresolved: the bulge's stop code ``unresolved``, its message naming solver.max_degree,
    every stored point resolved, and ``run`` exits 1 with one line saying so (0 with --allow-partial)."""
    from balloon_cg.app.cli import main
    from balloon_cg.io.tube_file import read_tube_run

    for max_degree, code in ((100, 0), (30, 1)):
        scene_file, path = tmp_path / f"refine{max_degree}.toml", tmp_path / f"refine{max_degree}.h5"
        scene_file.write_text(refined_scene(max_degree).to_toml())
        assert main(["run", str(scene_file), "-o", str(path), "--quiet"]) == code
        run = read_tube_run(path)
        bulge = run["branches"]["bulge"]
        assert bulge["tail"].max() <= 1e-5
        err = capsys.readouterr().err
        if code == 0:
            assert run["attrs"]["degree"] == 67 and bulge["attrs"]["stop_code"] == StopCode.STOP_VOLUME
            assert abs(bulge["volume"][-1] - 4.0) <= 1e-9 and err == ""
            ((fold_pressure, fold_volume),) = [(s["pressure"], s["volume"]) for s in bulge["special_points"]
                                               if s["kind"] == "LV"]
            assert abs(fold_pressure - FOLD[0]) <= 1e-9 and abs(fold_volume - FOLD[1]) <= 1e-9
        else:
            assert run["attrs"]["degree"] == 30 and bulge["attrs"]["stop_code"] == IntervalStop.UNRESOLVED
            assert "= solver.max_degree" in bulge["attrs"]["stop_message"]
            assert "incomplete (bulge:" in err and len(err.strip().splitlines()) == 1
            assert main(["run", str(scene_file), "-o", str(path), "--quiet", "--force", "--allow-partial"]) == 0


def test_tube_resolution_key_is_the_tubes_and_always_in_a_tubes_text():
    """solver.tube_resolution: a tube's normalised text always names it ("elements", the default since session 30,
    and "refine" alike: a stored text without it reads as its file's revision ran, test_tube_sweep), another shape's
    never; a wrong value and the key on another shape are one line naming the key, its value and what is allowed; a
    sphere scene carries the default and never reads it."""
    import pytest
    from balloon_cg.scene import SceneError, load_scene, parse_scene

    assert 'tube_resolution = "elements"' in spom1_l10(30).to_toml()
    assert 'tube_resolution = "refine"' in refined_scene(100).to_toml()
    assert parse_scene(refined_scene(100).to_toml()).solver.tube_resolution == "refine"
    for text, words in (('[solver]\ntube_resolution = "fine"\n', "solver.tube_resolution = \"fine\": must be one of"),
                        ('[solver]\ntube_resolution = "refine"\n', 'only for geometry.shape = "tube"')):
        with pytest.raises(SceneError) as error:
            parse_scene('[material]\npreset = "SPOM1"\n' + text)
        assert words in str(error.value) and "\n" not in str(error.value)
    assert load_scene("spom1").solver.tube_resolution == "elements"
