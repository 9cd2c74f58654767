"""A capsule scene's `[surface] branches` run end to end (analysis/picture.py ``trace_capsule``): SPOM1, length 3,
m_max = 1, its primary branch to V = 65 (continuation.stop_volume: past its first located m1_held point at
P = 1.46129, tests/test_capsule_surface.py's ``switched``; stop_stretch 3, which bounds the surface branch's largest
hoop stretch, 2.36 at that point), `[surface] branches = "first"`, max_points 4. The run's m = 1 branch is written
to the run file and read back, shown by `inspect` (text and JSON); it equals capsule.traced_branch called directly;
its switched point is stationary for the energy written in tests/test_capsule_surface.py; a signal during its trace
keeps the points traced, each the uninterrupted run's, and marks the run interrupted. Its −φ half is the image
under the rotation by π about the axis (analysis/surface/meridian/rotation.py), checked to be an equilibrium and
against the branch traced along −φ; both are drawn by the sphere's figures (post/meridian_branches.py).
"""
import json

import numpy as np
import pytest

from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import StopCode
from balloon_cg.analysis.surface.meridian import capsule as capsule_surface
from balloon_cg.io.run_file import read_run, write_run
from balloon_cg.numerics import interrupt
from balloon_cg.numerics.threads import limited_blas
from test_capsule_azimuthal import capsule
from test_capsule_surface import written_derivatives

POINTS = 4  # [surface] max_points: the zero (point 0) and the switched point count
SETTINGS = {"stability.m_max": 1, "continuation.stop_stretch": 3.0, "continuation.stop_volume": 65.0,
            "surface.branches": "first", "surface.max_points": POINTS}


def first_held_point(branch):
    """(k, bp): the branch's first located m1_held point and its number in ``branch.branch_points()``."""
    return next((k, bp) for k, bp in enumerate(branch.branch_points()) if bp.block.value == "m1_held")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """(scene, picture, the run file written and read back)."""
    scene = capsule(3.0).with_overrides(SETTINGS)
    picture = analyse(scene)
    path = tmp_path_factory.mktemp("capsule") / "capsule.h5"
    write_run(path, scene, picture.branches, snaps=picture.snaps, found=picture.incomplete,
              meridian_surface=picture.meridian_surface)
    return scene, picture, path, read_run(path)


def test_the_run_traces_the_first_m1_branch_and_stores_it(run):
    """One branch, m1_bp<k> at the primary's first m1_held point, POINTS points (the zero first), its parent named,
    and its −φ half m1_bp<k>_rotated; the picture's gaps their budget (LIMITED: stated, the run complete); stored with
    its points, stop and basis (the capsule's mode degree and equator flag)."""
    scene, picture, _, stored = run
    k, bp = first_held_point(picture.primary)
    assert list(picture.meridian_surface) == [f"m1_bp{k}", f"m1_bp{k}_rotated"] and not picture.not_started
    branch = picture.meridian_surface[f"m1_bp{k}"]
    assert branch.m == 1 and branch.parent == ("primary", k) and len(branch.pressure) == POINTS
    assert abs(branch.pressure[0] - bp.X[-1]) <= 1e-14 * bp.X[-1]
    assert branch.stop.code.value == "max_points" and [(i.gap.value, i.branch) for i in picture.incomplete] == [
        ("limited", f"m1_bp{k}"), ("limited", f"m1_bp{k}_rotated")]  # stated, not failing: the run is complete
    found = stored["meridian_surface"][f"m1_bp{k}"]
    assert np.array_equal(found["coefficients"], branch.coefficients)
    assert np.array_equal(found["pressure"], branch.pressure)
    assert found["attrs"]["stop_code"] == branch.stop.code.value
    assert found["attrs"]["mode_degree"] == branch.basis.mode_degree
    assert bool(found["attrs"]["equator"]) == branch.basis.equator


def test_the_stored_branch_is_capsule_traced_branch_called_directly(run):
    """capsule.traced_branch from the same point, with the same budget and BLAS threads (numerics/threads.py: the
    run's, ``analyse`` is limited_blas): the same points (coefficients, P, V/V0, amplitude, the mirror sector's
    lowest eigenvalues) to 1e-12."""
    scene, picture, _, _ = run
    k, bp = first_held_point(picture.primary)
    direct = limited_blas(capsule_surface.traced_branch)(scene, picture.primary, bp, max_points=POINTS,
                                                         parent=("primary", k))
    ran = picture.meridian_surface[f"m1_bp{k}"]
    for name in ("coefficients", "pressure", "volume", "amplitude", "lowest"):
        ours, theirs = getattr(ran, name), getattr(direct, name)
        assert ours.shape == theirs.shape and np.max(np.abs(ours - theirs)) <= 1e-12 * np.max(np.abs(theirs)), name


def test_the_first_switched_point_is_stationary_for_the_written_energy(run):
    """Point 1 (the switched point at ε = 0.05, on the final basis: nested, exact) is stationary for the energy
    written in tests/test_capsule_surface.py: its derivatives along the state's orders below 1e-9 of the elastic
    part's."""
    scene, picture, _, _ = run
    branch = next(iter(picture.meridian_surface.values()))
    totals, elastics = written_derivatives(scene, branch.basis, branch.coefficients[1], branch.pressure[1])
    assert np.max(np.abs(totals)) <= 1e-9 * np.max(np.abs(elastics)), (totals, elastics)


def rotated_pair(picture) -> tuple:
    """(the traced branch, its stored image under the rotation by π/m) of the run."""
    (name, branch), (image_name, image) = picture.meridian_surface.items()
    assert image_name == f"{name}_rotated" and image.image_of == name and not branch.image_of
    return branch, image


def test_the_minus_phi_half_is_an_equilibrium_of_the_written_energy(run):
    """The −φ half is the image of the +φ branch under the rotation Q by π/m about the axis (m = 1: by π; c_k ↦
    (−1)^k c_k), a symmetry of the capsule, its pressure and the held gauge (analysis/surface/meridian/rotation.py).
    Checked, not assumed, at every point: the engine's gauged residual at the image (its reaction τ negated) ≤ 1e-10
    of the largest of its parts (the trace's tolerance: solver.tol 1e-12 on ~1e2 entries), its amplitude −φᵀ G c_1
    of the source's, P, V/V0 and every eigenvalue the source's; the energy written in tests/test_capsule_surface.py
    (another code path: Ogden's Φ over the metric, the cone volume) stationary at the image's points ≥ 1 (its
    derivatives along the state's orders below 1e-9 of the elastic part's, as at the source's point 1)."""
    from balloon_cg.analysis.surface.meridian.equilibrium import MeridianSurfaceEquilibrium
    from balloon_cg.analysis.surface.meridian.system import MeridianSurfaceSystem

    scene, picture, _, stored = run
    branch, image = rotated_pair(picture)
    assert np.array_equal(image.pressure, branch.pressure) and np.array_equal(image.volume, branch.volume)
    assert np.array_equal(image.lowest, branch.lowest) and image.folds == branch.folds
    assert np.array_equal(image.amplitude, -branch.amplitude) and np.all(branch.amplitude[1:] > 0)
    params = picture.primary.params_at(picture.primary.X[0])
    system = MeridianSurfaceSystem(MeridianSurfaceEquilibrium(scene, image.basis), params, image.coefficients[0])
    assert system.gauged == 1  # the equator states: the translation along x alone (capsule.py gauge_rows)
    for c, P, tau in zip(image.coefficients, image.pressure, image.reaction):
        X = system.point(c, P)
        X[system.free.size] = tau  # the held gauge's reaction τ: the source's, negated
        load = P * np.abs(system.surface.parameter_derivative(c, params.with_value("P", P))).max()  # |P ∇V|
        assert np.abs(system.residual(X)).max() <= 1e-10 * load
    for c, P in zip(image.coefficients[1:], image.pressure[1:]):
        totals, elastics = written_derivatives(scene, image.basis, c, P)
        assert np.max(np.abs(totals)) <= 1e-9 * np.max(np.abs(elastics)), (totals, elastics)
    name = image.image_of
    assert stored["meridian_surface"][f"{name}_rotated"]["attrs"]["image_of"] == name
    assert np.array_equal(stored["meridian_surface"][f"{name}_rotated"]["coefficients"], image.coefficients)


def test_the_minus_phi_half_is_the_branch_traced_along_minus_phi(run):
    """A second method: capsule.traced_branch along −φ (direction −1: switched at ε = −0.05, the tangent along −φ)
    with the same budget gives the image's points: coefficients, P, amplitude and the mirror sector's eigenvalues
    to 1e-9 (Newton's iterates are images of the +φ trace's to rounding)."""
    scene, picture, _, _ = run
    k, bp = first_held_point(picture.primary)
    _, image = rotated_pair(picture)
    traced = limited_blas(capsule_surface.traced_branch)(scene, picture.primary, bp, direction=-1.0,
                                                         max_points=POINTS, parent=("primary", k))
    for name in ("coefficients", "pressure", "amplitude", "lowest"):
        ours, theirs = getattr(image, name), getattr(traced, name)
        assert ours.shape == theirs.shape and np.max(np.abs(ours - theirs)) <= 1e-9 * np.max(np.abs(theirs)), name


def test_inspect_shows_it(run, capsys):
    """`inspect` names the branch with its parent point, points and stop, and its image as the image; `--json` has
    both under surface_branches, the image's ``image_of`` its source."""
    from balloon_cg.app.cli import main

    _, picture, path, _ = run
    branch, _ = rotated_pair(picture)
    name = next(iter(picture.meridian_surface))
    assert main(["inspect", str(path)]) == 0
    text = capsys.readouterr().out
    assert f"surface branch {name} (m = 1, from branch point {branch.parent[1]} of primary): {POINTS} points" in text
    assert f"; the image of {name} under the rotation by π/1 about the axis" in text
    assert main(["inspect", str(path), "--json"]) == 0
    found = json.loads(capsys.readouterr().out)["surface_branches"]
    summary = found[name]
    assert summary["points"] == POINTS and summary["stop_code"] == branch.stop.code.value
    assert summary["image_of"] == "" and found[f"{name}_rotated"]["image_of"] == name


def test_a_signal_during_the_trace_keeps_the_points_traced(run, monkeypatch):
    """A signal at the trace's second point stops it there (INTERRUPTED): the points traced are kept, each the
    uninterrupted run's (1e-12), and the picture is interrupted (the run file says so; a run is computed again, as
    the sphere's)."""
    from balloon_cg.analysis.surface.meridian import trace as module

    scene, picture, _, _ = run
    whole = next(iter(picture.meridian_surface.values()))
    calls, stretch = [], module.largest_hoop_stretch

    def signalled_at_the_second(*args):
        calls.append(1)
        if len(calls) == 2:
            interrupt.request()
        return stretch(*args)

    monkeypatch.setattr(module, "largest_hoop_stretch", signalled_at_the_second)
    try:
        cut = analyse(scene)
    finally:
        interrupt._flag.clear()
    assert cut.interrupted and cut.incomplete
    branch, image = rotated_pair(cut)  # its image: of the points traced
    n = len(branch.pressure)
    assert image.stop == branch.stop and len(image.pressure) == n
    assert branch.stop.code == StopCode.INTERRUPTED and 2 <= n < len(whole.pressure)
    assert np.max(np.abs(branch.pressure - whole.pressure[:n])) <= 1e-12 * whole.pressure.max()


def test_a_sweep_of_a_capsule_with_surface_branches_is_refused_in_one_line(tmp_path):
    """A sweep member stores no capsule's non-axisymmetric branches: a sweep of such a scene asking for them is
    refused before anything is computed, in one line naming the key, its value and what is allowed."""
    from balloon_cg.app.sweep import SweepError, run_sweep

    with pytest.raises(SweepError) as raised:
        run_sweep(capsule(3.0).with_overrides(SETTINGS), ["M=0:0.001:2"], tmp_path / "sweep.h5")
    message = str(raised.value)
    assert message.startswith("surface.branches = 'first'") and 'allowed in a sweep: "none"' in message
    assert "\n" not in message and not (tmp_path / "sweep.h5").exists()


def test_continue_at_its_m1_label_traces_the_branch_and_its_image(run, capsys):
    """continue at a capsule's m ≥ 1 label switches there as at a sphere's (restart.switch: the branch traced as run
    traces it, ``picture.trace_capsule``, with its image under the rotation by π/m): exit 0, the file holds the
    primary branch as read and both branches, their points the run's (coefficients and P 1e-12: the stored branch
    point, its critical mode at the degree it was located at); its points carry no labels (nothing to continue from)."""
    from balloon_cg.app.cli import main

    _, picture, path, stored = run
    label = next(p["label"] for p in stored["branches"]["primary"]["special_points"] if p["block"] == "m1_held")
    out = path.with_name("continued.h5")
    assert main(["continue", str(path), str(label), "-o", str(out)]) == 0
    assert "branches switched to at label" in capsys.readouterr().out
    continued = read_run(out)
    assert list(continued["branches"]) == ["primary"]
    assert list(continued["meridian_surface"]) == list(picture.meridian_surface)
    for name, branch in picture.meridian_surface.items():
        found = continued["meridian_surface"][name]
        assert found["attrs"].get("image_of", "") == branch.image_of
        for column in ("coefficients", "pressure"):
            ours, theirs = found[column], getattr(branch, column)
            assert ours.shape == theirs.shape and np.max(np.abs(ours - theirs)) <= 1e-12 * np.max(np.abs(theirs))


def test_pressure_pole_draws_it_from_the_stored_points(run):
    """`plot --what pressure-pole` draws the traced branch with the sphere's surface branches' code
    (post/meridian_branches.py): its curve's P the stored pressures, exactly, against the material pole's stretch
    √J (surface/measures.pole_stretch on the capsule basis' point_values); at point 0 (the axisymmetric zero) that
    is the primary branch's λ2(0) at its stored branch point (the axisymmetric disc's own evaluation, 1e-10), at the
    image's points the source's (1e-12); the image, its curve the same, is not drawn twice (as the sphere's rotated
    branches); no stability flags (the legend says solid is stable or not computed)."""
    from balloon_cg.post.plotting import as_run, plot

    _, picture, path, stored = run
    name = next(iter(picture.meridian_surface))
    k, _ = first_held_point(picture.primary)
    viewed = as_run(str(path))["branches"]
    top, image_top = viewed[name]["lam2_top"], viewed[f"{name}_rotated"]["lam2_top"]
    bp = [s for s in stored["branches"]["primary"]["special_points"] if s["kind"] == "BP"][k]
    assert abs(top[0] - bp["lam2_top"]) <= 1e-10 * bp["lam2_top"]
    assert np.max(np.abs(image_top - top)) <= 1e-12 * top.max() and np.all(top > 1)
    fig = plot([str(path)], "pressure-pole")
    ax = fig.axes[0]
    pressure = stored["meridian_surface"][name]["pressure"]
    drawn = [line for line in ax.lines if len(line.get_ydata()) == POINTS
             and np.array_equal(line.get_ydata(), pressure)]
    assert len(drawn) == 1 and np.array_equal(drawn[0].get_xdata(), top)
    from matplotlib.text import Text
    assert any("not computed" in text.get_text() for text in fig.findobj(Text))


def test_surface_draws_the_stored_state(run):
    """`plot --what surface` draws a stored state of the capsule's branch with the sphere's code: its section y = 0
    is the state's x at φ = 0 and π (CapsuleSurfaceBasis.point_values of the stored coefficients on the basis
    rebuilt from the file: the run's final basis, 0 apart), for point 0 and the point asked for; stretch-map (the
    sphere's node layout) is refused in one line."""
    from balloon_cg.post.meridian_branches import stored_meridian_basis
    from balloon_cg.post.plotting import PlotError, as_run, plot

    _, picture, path, stored = run
    name = next(iter(picture.meridian_surface))
    branch = picture.meridian_surface[name]
    basis = stored_meridian_basis(as_run(str(path)), name)
    assert basis == branch.basis
    fig = plot([str(path)], "surface", points=[2], branch=name)
    section = fig.axes[1]
    theta = np.linspace(0.0, np.pi, 181)
    for line, index in zip(section.lines[:2], (0, 2)):
        x = np.concatenate([basis.point_values(branch.coefficients[index], theta, np.full_like(theta, phi))[0]
                            for phi in (0.0, np.pi)], axis=1)
        order = np.r_[np.arange(theta.size), np.arange(2 * theta.size - 1, theta.size - 1, -1)]
        assert np.array_equal(line.get_xdata(), x[0, order]) and np.array_equal(line.get_ydata(), x[2, order])
    with pytest.raises(PlotError) as refused:
        plot([str(path)], "stretch-map", branch=name)
    assert "stretch-map" in str(refused.value) and "\n" not in str(refused.value)


def test_events_are_located_on_it_stored_and_shown(run, tmp_path, capsys):
    """[[events]] on the volume and the pressure (values between its points 1 and 2, and 2 and 3) give UZ points on
    the branch (analysis/surface/meridian/events.py, the sphere's landing): each located between those points, at
    the value (V to the landing's 1e-10 relative, P exactly), an equilibrium of the energy written in
    tests/test_capsule_surface.py (its derivatives below 1e-9 of the elastic part's); its image's the rotated
    points (P, V the same); written, read back and listed by `inspect`."""
    from dataclasses import replace as replaced

    from balloon_cg.analysis.surface.meridian import events, rotation
    from balloon_cg.app.cli import main
    from balloon_cg.scene.events import events_from_list

    scene, picture, _, _ = run
    branch, _ = rotated_pair(picture)
    name = next(iter(picture.meridian_surface))
    volume0 = scene.geometry.reference_volume
    wanted = [{"quantity": "volume", "value": float(volume0 * branch.volume[1:3].mean())},
              {"quantity": "pressure", "value": float(branch.pressure[2:4].mean())}]
    asked = replaced(scene, events=events_from_list(wanted))
    traced = events.with_events(asked, branch, picture.primary.params_at(picture.primary.X[0]))
    (volume, pressure) = traced.events
    assert (volume.index, pressure.index) == (1, 2) and volume.located and pressure.located
    assert abs(volume.volume * volume0 - wanted[0]["value"]) <= 1e-10 * wanted[0]["value"]
    assert pressure.pressure == wanted[1]["value"]
    for point in (volume, pressure):
        assert branch.pressure[point.index + 1] <= point.pressure <= branch.pressure[point.index]
        totals, elastics = written_derivatives(scene, branch.basis, point.coefficients, point.pressure)
        assert np.max(np.abs(totals)) <= 1e-9 * np.max(np.abs(elastics)), (totals, elastics)
    image = rotation.rotated(traced, name)
    signs = rotation.rotation_signs(branch.basis)
    assert all(np.array_equal(e.coefficients, f.coefficients * signs) and e.pressure == f.pressure
               for e, f in zip(image.events, traced.events))
    path = tmp_path / "events.h5"
    write_run(path, asked, picture.branches, meridian_surface={name: traced, f"{name}_rotated": image})
    stored = read_run(path)["meridian_surface"][name]["events"]
    assert [(e["after_point"], e["pressure"], e["located"]) for e in stored] == [
        (p.index, p.pressure, True) for p in traced.events]
    assert np.array_equal(stored[0]["coefficients"], volume.coefficients)
    assert main(["inspect", str(path)]) == 0
    assert f"UZ after point 1    P = {volume.pressure:.10g}" in capsys.readouterr().out


def test_an_event_not_landed_on_makes_the_result_incomplete_once():
    """analysis/picture.meridian_gaps: a UZ point of a capsule's surface branch that Newton did not land on is an
    APPROXIMATE gap (the run exits 1), as a sphere's surface branch's; named on the traced branch only (its image's
    events are the same points, rotated); a landed one is none."""
    from types import SimpleNamespace

    from balloon_cg.analysis.picture import meridian_gaps
    from balloon_cg.analysis.results import IntervalStop
    from balloon_cg.analysis.verdict import Gap, failing
    from balloon_cg.numerics.continuation import Stop

    def branch(image_of, *located):
        events = tuple(SimpleNamespace(index=k, note=f"volume = {k}", located=ok) for k, ok in enumerate(located))
        return SimpleNamespace(stop=Stop(IntervalStop.REJOINED, "rejoined"), limited=False, events=events,
                               image_of=image_of)

    found = meridian_gaps({"m1_bp0": branch("", True, False), "m1_bp0_rotated": branch("m1_bp0", True, False)})
    assert [(g.gap, g.branch, g.message) for g in found] == [(Gap.APPROXIMATE, "m1_bp0", "UZ after point 1: volume = 1")]
    assert failing(found) and meridian_gaps({"m1_bp0": branch("", True, True)}) == []
