"""The non-axisymmetric branch of a tube traced in P (tube/surface/branch.py) from a located m = 1 zero: the held
neo-Hookean tube's sideways buckle (λz = 1.5, L = 10, degree 16; tests/test_tube_surface.py's ``located_zeros``).

Checked against a larger basis (a traced point re-solved with the degree and the orders raised), against the
pitchfork's symmetry (the half traced along −φ is the rotation by π of the half along +φ) and the critical mode it
leaves along, and its stability against the exchange of stability a pitchfork's normal form predicts from the
switched point's (P − P_0)/ε²."""
from dataclasses import replace

import numpy as np
import pytest

from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.scene import Control, SceneError
from balloon_cg.tube import azimuthal
from balloon_cg.tube.surface.basis import TubeSurfaceBasis
from balloon_cg.tube.surface.branch import START_AMPLITUDE, traced_branch
from balloon_cg.tube.surface.equilibrium import MeridianSurfaceEquilibrium
from balloon_cg.tube.surface.stability import SectorStability
from balloon_cg.tube.surface.resolution import harmonics
from balloon_cg.tube.surface.switching import mode_row, point_at_amplitude, switched_point
from balloon_cg.tube.surface.system import TubeSurfaceSystem
from test_tube_surface import located_zeros, tube_scene

POINTS = 6


@pytest.fixture(scope="module")
def traced():
    """(scene, parent branch, its first m = 1 zero, the branch along +φ, along −φ)."""
    scene, branch, found = located_zeros("held")
    zero = found[0]
    halves = [traced_branch(scene, branch.disc, zero, branch.params, direction, POINTS) for direction in (1, -1)]
    return scene, branch, zero, *halves


def larger_point(scene, parent, zero, branch, k, degrees: int, orders: int):
    """Point k of ``branch`` (born at ``zero`` of ``parent``) re-solved at its amplitude on a larger basis: the degree
    raised by ``degrees`` and the orders by ``orders`` multiples of m, Newton from the point itself zero-padded
    (TubeSurfaceBasis.raised); (the SwitchedPoint, the padded start)."""
    small, m = branch.basis, branch.m
    large = TubeSurfaceBasis(replace(small.disc, degree=small.disc.degree + degrees, quadrature=0),
                             harmonics(m, len(small.orders) - 1 + orders))
    origin = TubeSurfaceBasis(parent.disc, (0, m, 2 * m))
    mode = origin.raised(origin.with_mode(np.zeros(origin.size), m, zero.mode), large)[large.block(m)]
    row = mode_row(large, m, mode)
    start = small.raised(branch.coefficients[k], large)
    assert row @ start == pytest.approx(branch.amplitude[k], abs=1e-12)
    return point_at_amplitude(scene, large, start, branch.pressure[k], row, branch.amplitude[k], m,
                              parent.params), start


def test_a_traced_point_agrees_on_a_larger_basis(traced):
    """The branch's last traced point re-solved at the same amplitude with the degree raised by 8 and the orders by
    3: P within the point's error estimate (relative), every coefficient within it times the mean radius; the
    estimate below solver.max_error at every point (the basis refined along the branch, not at its cap: not
    ``limited``) and the re-solved point off the axisymmetric states."""
    scene, parent, zero, plus, _ = traced
    k = len(plus.pressure) - 1
    point, start = larger_point(scene, parent, zero, plus, k, 8, 3)
    assert point.converged, point.message
    estimate = plus.error_estimate[k]
    radius = abs(plus.basis.disc.series(plus.coefficients[k][plus.basis.block(0)])[0][0])
    assert not plus.limited and np.all(plus.error_estimate <= scene.solver.max_error)
    assert len(plus.basis.orders) > 3 and abs(plus.amplitude[k]) > 0.3
    assert abs(point.pressure - plus.pressure[k]) <= estimate * abs(plus.pressure[k]), (point.pressure, estimate)
    assert np.max(np.abs(point.c - start)) <= estimate * radius, (np.max(np.abs(point.c - start)), estimate)


def test_the_branch_leaves_along_the_critical_mode_as_a_pitchfork(traced):
    """Point 0 is the zero; point 1 the switched point at ε = START_AMPLITUDE: its order-1 part is ε φ within O(ε²)
    (G-norm ≤ 2 ε² with φ G-unit) and its orders 0 and 2 move by O(ε²); the half along −φ is the image of the half
    along +φ under the rotation by π about the axis (c_m -> (−1)^m c_m): the same P at every
    point (1e-12 relative) and the same stability, the amplitudes opposite; the trace is a pitchfork from either
    side: P − P_0 the same function of ε."""
    scene, parent, zero, plus, minus = traced
    basis, eps = plus.basis, START_AMPLITUDE
    gram = azimuthal.operators(basis.disc)[1]
    assert np.array_equal(plus.coefficients[0], basis.axisymmetric(zero.u)) and plus.pressure[0] == zero.pressure
    c1 = plus.coefficients[1]
    away = c1[basis.block(1)] - eps * zero.mode
    assert np.sqrt(away @ gram @ away) <= 2 * eps**2
    assert np.max(np.abs(c1[basis.block(0)] - zero.u)) <= 2 * eps**2
    assert np.max(np.abs(c1[basis.block(2)])) <= 2 * eps**2
    assert len(plus.pressure) == len(minus.pressure) == POINTS
    assert np.max(np.abs(plus.pressure - minus.pressure)) <= 1e-12 * zero.pressure
    assert np.max(np.abs(plus.amplitude + minus.amplitude)) <= 1e-10
    flip = np.ones(basis.size)
    for m in basis.orders[1::2]:  # the rotation by π: order m times (−1)^m
        flip[basis.block(m)] = -1
    assert np.max(np.abs(plus.coefficients * flip - minus.coefficients)) <= 1e-9
    for control in plus.unstable:
        assert np.array_equal(plus.unstable[control], minus.unstable[control])
    assert np.all(np.diff(np.abs(plus.amplitude)) > 0)


def test_stability_at_the_first_points_follows_the_normal_form(traced):
    """A pitchfork's reduced energy ½ μ(P) ε² + ¼ b ε⁴ gives the branch P − P_0 = p_2 ε², p_2 = −b/μ'(P_0), and on
    it the critical eigenvalue 2 b ε² = −2 μ' p_2 ε². With p_2 from the switched point at ε = 0.05 and
    μ'(P_0) = φᵀ (dH_1/dP) φ along the parent (its tangent at the zero, central differences), the eigenvalue of the
    branch's sector nearest 0 at its first three traced points has the sign of −μ' p_2 and is −2 μ' p_2 ε² to the
    normal form's order (measured 3.9e-7, 1.5e-5, 6.2e-5 relative at ε = 0.05, 0.12, 0.21; 1e-3 asserted), and the
    unstable count under pressure control is the zero's (its zero eigenvalue not counted: it is 0 to rounding, 1e-9
    of the largest) plus one where that sign is negative."""
    scene, parent, zero, plus, _ = traced
    p2 = (switched_point(scene, parent.disc, zero, START_AMPLITUDE, parent.params).pressure - zero.pressure) / 0.05**2
    system = TubeSurfaceSystem(MeridianSurfaceEquilibrium(scene, plus.basis), parent.params, plus.coefficients[0])
    read = SectorStability(system)
    eq = Equilibrium(scene, parent.disc)
    free, h = parent.disc.free, 1e-5
    at = parent.params.with_value("P", zero.pressure)
    rate = np.zeros(parent.disc.size)  # du/dP along the parent at the zero (its m = 0 Jacobian is regular there)
    rate[free] = np.linalg.solve(eq.jacobian(zero.u, at)[np.ix_(free, free)],
                                 -eq.parameter_derivative(zero.u, at, "P")[free])
    moved = [azimuthal.hessian(eq, zero.u + s * h * rate, parent.params.with_value("P", zero.pressure + s * h), 1)
             for s in (1, -1)]
    slope = zero.mode @ (moved[0] - moved[1]) @ zero.mode / (2 * h)  # μ'(P_0) = φᵀ (dH_1/dP) φ, φ G-unit
    sign = np.sign(-slope * p2)
    at_zero = np.linalg.eigvalsh(read.pressure_matrix(plus.coefficients[0], at))
    zero_count = int(np.sum(at_zero < -1e-9 * np.max(np.abs(at_zero))))
    for k in (1, 2, 3):
        values = np.linalg.eigvalsh(read.pressure_matrix(plus.coefficients[k],
                                                         parent.params.with_value("P", plus.pressure[k])))
        critical = values[np.argmin(np.abs(values))]
        predicted = -2 * slope * p2 * plus.amplitude[k]**2
        assert np.sign(critical) == sign and abs(critical / predicted - 1) <= 1e-3, (k, critical, predicted)
        assert plus.unstable[Control.PRESSURE][k] == zero_count + int(sign < 0)


def test_run_file_and_inspect_carry_the_branch(traced, tmp_path):
    """A tube scene's [surface] branches default to "first", to "none" with coils, a voltage (where "first" is taken
    when asked for) or stability.m_max = 0 (and the default is left out of the scene's text); with "none" no branch
    is traced; with "first" the primary branch's first m = 1 zero starts "m1_bp0" (tube/picture.with_surface),
    written to the run file and read back (io/tube_surface_file.py) with its parent, points, stability, stop and
    ``limited``, and shown by ``inspect`` (text and the JSON summary) and drawn by ``plot --what pressure-volume``
    beside the axisymmetric branches; "first" with m_max = 0 is refused in one line naming the key, its value and what
    is allowed."""
    from balloon_cg.app.tube_summary import summarise_tube, format_tube
    from balloon_cg.io.tube_file import read_tube_run, write_tube_run
    from balloon_cg.post.tube_plots import tube_figure
    from balloon_cg.tube.picture import TubePicture, with_modes, with_surface

    scene, parent, zero, plus, _ = traced
    assert scene.surface.branches == "first" and "surface" not in scene.to_dict()
    coil = "[field]\nM = 0.5\n[[field.coils]]\nradius = 1.5\nheight = 0.0\ncurrent = 1.0\n"
    for extra in (coil, "[electric]\nvoltage = 0.1\n", "[stability]\nm_max = 0\n"):
        unbuilt = tube_scene(extra=extra)
        assert unbuilt.surface.branches == "none" and "surface" not in unbuilt.to_dict()
    picture = with_modes(scene, TubePicture({"primary": parent}, None))
    assert with_surface(scene.with_overrides({"surface.branches": "none"}), picture).surface is None
    first = scene.with_overrides({"surface.max_points": 4})
    picture = with_surface(first, picture)
    branch = picture.surface["m1_bp0"]
    assert branch.parent == ("primary", 0) and len(branch.pressure) == 4
    assert np.max(np.abs(branch.pressure - plus.pressure[:4])) <= 1e-12 * zero.pressure
    read = read_tube_run(write_tube_run(tmp_path / "tube.h5", first, picture))["surface_branches"]["m1_bp0"]
    assert np.array_equal(read["coefficients"], branch.coefficients) and read["attrs"]["parent_branch"] == "primary"
    assert np.array_equal(read["unstable_pressure"], branch.unstable[Control.PRESSURE])
    summary = summarise_tube(read_tube_run(tmp_path / "tube.h5"))
    shown = summary["surface_branches"]["m1_bp0"]
    assert shown["points"] == 4 and shown["parent"] == {"branch": "primary", "zero": 0}
    assert shown["stop_code"] == "max_points" and shown["stable_points"] == 0 and shown["limited"] is False
    assert "surface branch m1_bp0 (m = 1, from zero 0 of block m = 1 of primary): 4 points" in format_tube(summary)
    figure = tube_figure(read_tube_run(tmp_path / "tube.h5"), "pressure-volume")
    drawn = [line for line in figure.axes[0].lines if np.array_equal(line.get_xdata(), branch.volume)]
    assert [line.get_label() for line in drawn][0] == "m1_bp0 ($m$ = 1)" and len(drawn) == 2  # solid, dashed
    assert np.array_equal(np.fmax(drawn[0].get_ydata(), drawn[1].get_ydata()), branch.pressure)
    for extra in (coil, "[electric]\nvoltage = 0.1\n"):
        assert tube_scene(extra='[surface]\nbranches = "first"\n' + extra).surface.branches == "first"
    with pytest.raises(SceneError) as error:
        tube_scene(extra='[surface]\nbranches = "first"\n[stability]\nm_max = 0\n')
    message = str(error.value)
    assert 'surface.branches = "first"' in message and "stability.m_max" in message and "allowed" in message, message
    assert "\n" not in message


def test_a_signal_while_reading_the_stability_keeps_the_points_read(traced, monkeypatch):
    """The branch's points are read after its trace (dense eigensolves: minutes on a large basis): a signal during
    them ends the branch INTERRUPTED with the points read so far, each the uninterrupted branch's, and no point
    unread (a tube run ignored SIGTERM for 388 s there)."""
    from balloon_cg.analysis.results import StopCode
    from balloon_cg.numerics import interrupt
    from balloon_cg.tube.surface import branch as module

    scene, parent, zero, whole, _ = traced
    calls = []

    class Signalled(SectorStability):
        def __call__(self, *args):
            calls.append(1)
            if len(calls) == 2:
                interrupt.request()  # during the second point's reading
            return super().__call__(*args)

    monkeypatch.setattr(module, "SectorStability", Signalled)
    try:
        cut = traced_branch(scene, parent.disc, zero, parent.params, 1, POINTS)
    finally:
        interrupt._flag.clear()
    assert len(whole.pressure) > 2 and len(calls) == 2
    assert cut.stop.code == StopCode.INTERRUPTED
    assert len(cut.pressure) == len(cut.lowest) == len(cut.coefficients) == 2
    assert np.array_equal(cut.pressure, whole.pressure[:2]) and np.array_equal(cut.lowest, whole.lowest[:2])
    assert all(index < 1 for index, _ in cut.folds)


def test_a_signal_during_the_trace_keeps_every_traced_point_read(traced, monkeypatch):
    """A signal during the trace stops it at its next point (INTERRUPTED): every point traced is kept and read (the
    readings' own cut is for a signal that comes while they run), each the uninterrupted branch's."""
    from balloon_cg.analysis.results import StopCode
    from balloon_cg.numerics import interrupt
    from balloon_cg.tube.surface import branch as module

    scene, parent, zero, whole, _ = traced
    calls, stretch = [], module.largest_hoop_stretch

    def signalled_at_the_third(*args):
        calls.append(1)
        if len(calls) == 3:
            interrupt.request()
        return stretch(*args)

    monkeypatch.setattr(module, "largest_hoop_stretch", signalled_at_the_third)
    try:
        cut = traced_branch(scene, parent.disc, zero, parent.params, 1, POINTS)
    finally:
        interrupt._flag.clear()
    n = len(cut.pressure)
    assert cut.stop.code == StopCode.INTERRUPTED and 3 <= n < len(whole.pressure)
    assert len(cut.lowest) == n and np.array_equal(cut.lowest, whole.lowest[:n])
    assert np.array_equal(cut.pressure, whole.pressure[:n])
