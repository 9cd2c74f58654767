"""The onset of bulging followed in the held distance of the ends (``critical --parameter axial_stretch``,
tube/onset.py with λ̄ as the curve's parameter) against the dispersion relation derived from the strain energy.

With sliding ends held at λL the primary branch is the uniform tube at λz = λ (fixed: no axial balance), P =
Φ_2/(λθλz), and its first odd branch point is the mode cos(πS/L): where the determinant of the period-averaged second
variation in (A, B) of ρ = λθ + εA cos kS, η = λz S + εB sin kS vanishes at k = π/L (test_tube.bulge_determinant,
derived there from e = Φ(λ1, λ2) − ½Pρ²η'). Along the onset curve every point is such a state at its own λ: λθ
solves det(λθ, λ) = 0 (30 digits here). Where the curve turns back in λ (Gent) the two roots of det(·, λ) meet: the
critical pre-stretch λ_c solves det = ∂det/∂λθ = 0, above which the tube held at λL does not bulge in that mode.
"""
import mpmath
import numpy as np
import pytest
import sympy as sp

from balloon_cg.app.cli import main
from balloon_cg.galerkin.interval import Mirror
from balloon_cg.io.tube_file import read_tube_run
from balloon_cg.tube.onset import OnsetStop, onset_curve
from balloon_cg.scene import parse_scene
from balloon_cg.tube.picture import onset_picture
from balloon_cg.tube.primary import primary_branch
from test_held_tube import held_scene
from test_tube import bulge_determinant, symbolic_energy, theta, z

LENGTH = 10.0


def fixed_stretch_onset(energy, stretch: float, guess: float) -> tuple:
    """(λθ, P) where the determinant of mode cos(πS/L) vanishes at λz = ``stretch``, P = Φ_2/(λθλz), by mpmath at
    30 digits from ``guess``."""
    det, k = bulge_determinant(energy)
    at = {z: sp.Float(stretch, 30), k: sp.pi / sp.Integer(int(LENGTH))}
    condition = sp.lambdify(theta, det.subs(at), "mpmath")
    pressure = sp.lambdify(theta, (sp.diff(energy, theta) / (theta * z)).subs(at), "mpmath")
    with mpmath.workdps(30):
        root = mpmath.findroot(condition, mpmath.mpf(guess))
        return float(root), float(pressure(root))


def curve(preset: str, stretch: float, direction: float, stop: float = 6.0):
    scene = held_scene(preset, LENGTH, stretch, "sliding", 12, stop)
    primary = primary_branch(scene)
    return scene, onset_curve(scene, primary, primary.branch_points(Mirror.ODD)[0], "axial_stretch", direction)


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_onset_in_the_held_stretch_solves_the_fixed_stretch_dispersion_relation(direction):
    """SPOM1, L = 10, sliding ends held from λ = 1.5: upwards the curve lands on λ = 5 (stop stretch_limit: no fold,
    bulging persists, at a falling pressure and, from λ ≈ 3.4, a hoop stretch below 1), downwards on λ = 1 (stop
    unstretched). At every fourth point and the last the state is uniform at λz = λ (λ̄ = q, 1e-12),
    and its λθ and P are the root of the fixed-stretch dispersion relation derived here (1e-8; measured 4.2e-15)."""
    scene, found = curve("SPOM1", 1.5, direction)
    energy = symbolic_energy(scene.material)
    k = found.disc.axial_index
    assert found.stop.code == (OnsetStop.STRETCH_LIMIT if direction > 0 else OnsetStop.UNSTRETCHED)
    assert not found.folds and np.all(np.diff(found.q) * direction > 0)
    assert np.all(np.diff(found.pressure) * direction < 0)  # the onset pressure falls as the ends are pulled apart
    if direction < 0:
        assert found.q[-1] == 1.0
    else:
        assert found.q[-1] == 5.0 and found.states[-1][0] < 1
    for i in [*range(0, len(found.q), 4), len(found.q) - 1]:
        u, P = found.states[i], found.pressure[i]
        assert u[k] == found.q[i] and np.abs(np.delete(u, [0, k])).max() <= 1e-12
        hoop, pressure = fixed_stretch_onset(energy, found.q[i], u[0])
        assert abs(u[0] - hoop) <= 1e-8 and abs(P - pressure) <= 1e-8


def test_gent_stops_bulging_above_a_critical_prestretch():
    """Gent, L = 10, sliding ends held from λ = 1.5: the onset curve turns back at λ_c (a located fold in λ) and
    returns along the upper root of the dispersion relation (where the uniform tube is stable again) until its hoop
    stretch passes stop_stretch. λ_c and its λθ, P solve det = ∂det/∂λθ = 0 derived here (1e-8): above λ_c the held
    tube has no bulge of this mode (measured: λ_c 1.3e-15, λθ 2.4e-10, P 1.6e-11; along the curve 1.3e-13)."""
    scene, found = curve("Gent", 1.5, 1.0)
    assert len(found.folds) == 1 and found.folds[0].status == "located"
    assert found.stop.code == "hoop_stretch"
    fold, critical = found.folds[0], float(found.fold_q[0])
    energy = symbolic_energy(scene.material)
    det, k = bulge_determinant(energy)
    det = det.subs(k, sp.pi / sp.Integer(int(LENGTH)))
    with mpmath.workdps(30):
        hoop, stretch = sp.nsolve((det, sp.diff(det, theta)), (theta, z), (fold.u[0], critical), prec=30)
    P = float((sp.diff(energy, theta) / (theta * z)).subs({theta: hoop, z: stretch}))
    assert abs(critical - float(stretch)) <= 1e-8 and abs(fold.u[0] - float(hoop)) <= 1e-8
    assert abs(fold.pressure - P) <= 1e-8
    assert found.q.max() <= critical + 1e-12 and found.q[-1] < critical - 0.2  # back below λ_c along the upper root
    hoop, P = fixed_stretch_onset(energy, found.q[-1], found.states[-1][0])
    assert hoop > 5 and abs(found.states[-1][0] - hoop) <= 1e-8 and abs(found.pressure[-1] - P) <= 1e-8


def test_critical_axial_stretch_from_the_command_line(tmp_path, capsys):
    """``critical --parameter axial_stretch`` writes what onset_curve computes to /onset, prints the critical
    pre-stretch (Gent: exit 0), ``inspect`` lists the curve with its hoop stretch, ``plot --what onset`` draws it;
    closed ends and a held stretch outside [1, 5] exit 2 with one line and no file."""
    scene = held_scene("Gent", LENGTH, 1.5, "sliding", 12, 6.0)
    path = tmp_path / "gent.toml"
    path.write_text(scene.to_toml())
    out = tmp_path / "gent.h5"
    assert main(["critical", str(path), "--parameter", "axial_stretch", "-o", str(out), "--quiet"]) == 0
    _, expected = curve("Gent", 1.5, 1.0)
    printed = capsys.readouterr().out
    assert printed.startswith(f"critical axial_stretch = {expected.fold_q[0]:.12g} (P = ")
    onset = read_tube_run(out)["onset"]
    assert onset["attrs"]["parameter"] == "axial_stretch" and onset["attrs"]["q0"] == 1.5
    assert np.array_equal(onset["q"], expected.q) and np.array_equal(onset["pressure"], expected.pressure)
    assert np.allclose(onset["hoop_stretch"], expected.states[:, 0], rtol=0, atol=1e-12)  # uniform: ρ = λθ
    assert main(["inspect", str(out)]) == 0
    shown = capsys.readouterr().out
    assert "onset in axial_stretch (from axial_stretch = 1.5)" in shown and "largest hoop stretch" in shown
    assert f"fold in axial_stretch at axial_stretch = {expected.fold_q[0]:.10g}" in shown
    assert main(["plot", str(out), "--what", "onset", "-o", str(tmp_path / "onset.png")]) == 0
    assert (tmp_path / "onset.png").stat().st_size > 0
    closed = tmp_path / "closed.toml"
    closed.write_text('[material]\npreset = "SPOM1"\n[geometry]\nshape = "tube"\nlength = 10\naxial = "closed"\n')
    far = tmp_path / "far.toml"
    far.write_text(scene.to_toml().replace("axial_stretch = 1.5", "axial_stretch = 6"))
    for given, message in ((closed, 'has closed ends (geometry.axial = "closed", the default: the distance free, '
                                    "none held); hold them apart with geometry.axial_stretch = λ (in [1, 5])"),
                           (far, "geometry.axial_stretch = 6: must be in [1, 5]")):
        target = tmp_path / f"{given.stem}.h5"
        assert main(["critical", str(given), "--parameter", "axial_stretch", "-o", str(target), "--quiet"]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1 and not target.exists()


FIELD = "[field]\nM = {value!r}\n[[field.coils]]\nradius = 2.5\nheight = 0.0\ncurrent = 1.0\n"  # around the middle
ELECTRIC = "[electric]\nvoltage = {value!r}\n"


def onset_at_reference_length(table: str, value: float | None):
    """The onset curve in λ of SPOM1, L = 10, sliding ends held at 1.5L, degree 12, with ``table`` at ``value`` (None:
    without it), traced down to λ = 1 as ``critical --parameter axial_stretch --direction -1`` traces it."""
    text = ('[material]\npreset = "SPOM1"\n[geometry]\nshape = "tube"\nlength = 10\nends = "sliding"\n'
            'axial_stretch = 1.5\n[solver]\ndegree = 12\n[stability]\nm_max = 0\n[continuation]\nstop_stretch = 6.0\n'
            'step_max = 0.5\n')
    scene = parse_scene(text + ("" if value is None else table.format(value=value)))
    return onset_picture(scene, "axial_stretch", -1.0).onset


@pytest.mark.parametrize("table, values", [(FIELD, (1e-4, 5e-5, 2.5e-5)),
                                           (ELECTRIC, (0.02, 0.02 / 2 ** 0.5, 0.01))], ids=["coil", "voltage"])
def test_onset_in_the_held_stretch_tends_to_the_field_free_one(table, values):
    """The onset curve in λ (down to λ = 1, landed: stop unstretched) in the field of a coaxial coil around the
    tube's middle (radius 2.5) and under a voltage across its wall. With the term present at M = 0 (Φ̄ = 0) every
    point is the field-free curve's (1e-8; measured 2e-16). The field moves it: at λ = 1 the onset pressure falls by
    ΔP ∝ M (Φ̄²: the magnetic energy is linear in M, the dielectric one quadratic in Φ̄), checked at three values
    halving M (Φ̄²) — each ΔP above 1e-6, halving to 1 % — and their Richardson extrapolation to M → 0 (Φ̄ → 0),
    (8ΔP(q/4) − 6ΔP(q/2) + ΔP(q))/3 in q = M (Φ̄²), is the field-free onset within 1e-8 (measured 4.5e-11 and
    1.6e-12)."""
    free = onset_at_reference_length(table, None)
    off = onset_at_reference_length(table, 0.0)
    assert free.stop.code == off.stop.code == OnsetStop.UNSTRETCHED and off.q.size == free.q.size
    assert np.abs(off.q - free.q).max() <= 1e-8 and np.abs(off.pressure - free.pressure).max() <= 1e-8
    assert np.abs(off.states - free.states).max() <= 1e-8
    moved = []
    for value in values:
        found = onset_at_reference_length(table, value)
        assert found.stop.code == OnsetStop.UNSTRETCHED and found.q[-1] == 1.0
        moved.append(found.pressure[-1] - free.pressure[-1])
    assert all(d < -1e-6 for d in moved)
    assert abs(moved[1] / moved[0] - 0.5) <= 0.01 and abs(moved[2] / moved[1] - 0.5) <= 0.01
    assert abs((8 * moved[2] - 6 * moved[1] + moved[0]) / 3) <= 1e-8


def plugged_scene(degree: int, stop: float = 7.0):
    """SPOM1, L = 10, plugged ends held at 2L (docs/tubes.md: taut to its pressure maximum and beyond)."""
    return held_scene("SPOM1", LENGTH, 2.0, "plugged", degree, stop).with_overrides({"stability.m_max": 0})


def test_plugged_onset_curve_folds_in_the_held_stretch_converged_in_the_degree(tmp_path, capsys):
    """SPOM1, L = 10, plugged ends held at 2L: the onset curve traced down in λ turns back at λ_c = 1.7896071 (P =
    0.73849), a fold converged in the degree — λ_c at 60, 80, 100 within 3.4e-6 and 3.9e-8 of the next, P within
    4.4e-5 and 1.7e-7, each fold state's Legendre tail 8-13× smaller per 20 degrees (docs/tubes.md's table) — not an
    artefact; but at degree 30 its state is not resolved (tail 8.6e-3: λ_c 1.7977, P 0.687, 7 % off), and
    ``critical`` says so in one line on stderr (the value printed, exit 0, as run flags an unresolved branch) and
    ``inspect`` marks the fold and counts the curve's unresolved points. The stop (hoop stretch 4.5) names the last
    stored point's λ, not the step's that passed it."""
    folds = {}
    for degree in (60, 80, 100):
        scene = plugged_scene(degree)
        primary = primary_branch(scene)
        found = onset_curve(scene, primary, primary.branch_points(Mirror.ODD)[0], "axial_stretch", -1.0, 40)
        assert len(found.folds) == 1 and found.folds[0].status == "located"
        folds[degree] = (float(found.fold_q[0]), found.folds[0].pressure, float(found.fold_tail[0]))
    (q60, P60, t60), (q80, P80, t80), (q100, P100, t100) = folds.values()
    assert abs(q60 - q80) <= 1e-5 and abs(q80 - q100) <= 1e-7 and abs(q80 - q100) < abs(q60 - q80) / 10
    assert abs(P60 - P80) <= 1e-4 and abs(P80 - P100) <= 1e-6 and t100 < t80 / 5 and t80 < t60 / 5
    path = tmp_path / "plugged.toml"
    path.write_text(plugged_scene(30, 4.5).to_toml())
    out = tmp_path / "plugged.h5"
    assert main(["critical", str(path), "--parameter", "axial_stretch", "--direction", "-1", "-o", str(out),
                 "--quiet"]) == 1  # printed, but unresolved: exit 1
    captured = capsys.readouterr()
    assert captured.out.startswith("critical axial_stretch = 1.7976960")
    assert captured.err.count("\n") == 1 and "the fold's state is not resolved at solver.degree = 30: its Legendre " \
                                                "tail 0.0086 is above solver.max_error = 1e-09" in captured.err
    onset = read_tube_run(out)["onset"]
    assert abs(onset["folds"][0]["q"] - q100) > 5e-3
    assert onset["attrs"]["stop_message"].endswith(f"after axial_stretch = {onset['q'][-1]:.6g}, the last point")
    assert main(["inspect", str(out)]) == 0
    shown = capsys.readouterr().out
    assert "located  unresolved (tail 0.0086)" in shown and "points unresolved (Legendre tail above" in shown
