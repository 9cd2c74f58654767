"""A current loop anywhere (MODEL.md §9): its field against a direct Biot–Savart quadrature, H² and its Cartesian
derivatives, the coaxial loop in the general form, the scene's [[field.coils]] general form and its validation, and
the refusal of a non-axisymmetric field by the axisymmetric commands.

Reference: h = s ∮ dl × (x − l)/|x − l|³ (the factor I/(4π R0) removed, MODEL.md §3) by the trapezoid rule in the
loop angle, which converges exponentially for a point off the wire; its convergence is checked by doubling.
"""
import math
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.app.cli import main
from balloon_cg.model.field import FieldError, coaxial_table, field_components, field_squared
from balloon_cg.model.loop import CARTESIAN, field_squared_cartesian, loop_field, loop_table
from balloon_cg.scene import Coil, SceneError, load_scene, parse_scene

TWO_COILS = Path(__file__).resolve().parents[1] / "scenes" / "spom1_two_coils_M0.002.toml"
TILT = math.radians(30.0)
TILTED = Coil(1.3, 0.8, (0.6, -0.4, 1.1), (math.sin(TILT) * math.cos(0.7), math.sin(TILT) * math.sin(0.7),
                                            math.cos(TILT)))
SECOND = Coil(2.0, -1.5, (-0.3, 0.2, -1.4), tuple(np.array([0.2, -0.5, 0.8]) / np.linalg.norm([0.2, -0.5, 0.8])))


def frame(normal):
    """(u, v) with (u, v, n) a right-handed orthonormal frame."""
    n = np.asarray(normal)
    u = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def biot_savart(points, coil, nodes):
    """h at the columns of ``points``: the trapezoid rule with ``nodes`` nodes in the loop angle ψ over
    s a (−sin ψ u + cos ψ v) × (x − l(ψ))/|x − l(ψ)|³ dψ, l(ψ) = c + a (cos ψ u + sin ψ v)."""
    u, v = frame(coil.normal)
    psi = 2.0 * np.pi * np.arange(nodes) / nodes
    wire = np.asarray(coil.centre)[:, None] + coil.radius * (np.outer(u, np.cos(psi)) + np.outer(v, np.sin(psi)))
    tangent = coil.radius * (-np.outer(u, np.sin(psi)) + np.outer(v, np.cos(psi)))
    separation = points.T[:, :, None] - wire[None]  # (point, component, node)
    integrand = np.cross(tangent[None], separation, axis=1) / np.linalg.norm(separation, axis=1)[:, None] ** 3
    return coil.current * 2.0 * np.pi * integrand.mean(axis=2).T


def wire_gap(points, coil):
    """The distance √((ρ' − a)² + z'²) of each column of ``points`` from the wire of ``coil``."""
    r = points - np.asarray(coil.centre)[:, None]
    z = np.asarray(coil.normal) @ r
    return np.hypot(np.linalg.norm(r - np.outer(coil.normal, z), axis=0) - coil.radius, z)


def points_around(coil, rng, count=100):
    """``count`` points around ``coil``: a fifth on its axis, a fifth within 1e-9 .. 1e-3 of it, the rest anywhere
    within 3 radii of its centre, all at least 0.3 radii from the wire."""
    u, v = frame(coil.normal)
    a, centre, normal = coil.radius, np.asarray(coil.centre), np.asarray(coil.normal)
    out = []
    while len(out) < count:
        kind = len(out) % 5
        z = rng.uniform(-2.0, 2.0) * a
        rho = 0.0 if kind == 0 else 10.0 ** rng.uniform(-9, -3) * a if kind == 1 else rng.uniform(0.0, 3.0) * a
        angle = rng.uniform(0.0, 2.0 * np.pi)
        if math.hypot(rho - a, z) < 0.3 * a:
            continue
        out.append(centre + z * normal + rho * (math.cos(angle) * u + math.sin(angle) * v))
    return np.array(out).T


def field_at(points, coils):
    out = np.empty_like(points)
    loop_field(np.ascontiguousarray(points), loop_table(coils), out)
    return out


def rows_at(points, coils):
    out = np.empty((len(CARTESIAN), points.shape[1]))
    field_squared_cartesian(np.ascontiguousarray(points), loop_table(coils), out)
    return out


def test_a_tilted_off_axis_loop_agrees_with_biot_savart_at_100_points_on_and_off_its_axis():
    points = points_around(TILTED, np.random.default_rng(26))
    reference = biot_savart(points, TILTED, 1200)
    doubled = biot_savart(points, TILTED, 2400)
    scale = np.linalg.norm(doubled, axis=0)
    assert (np.linalg.norm(reference - doubled, axis=0) / scale).max() < 1e-14  # the quadrature has converged
    error = np.linalg.norm(field_at(points, [TILTED]) - doubled, axis=0) / scale
    assert error.max() < 1e-12, error.max()


def test_loops_add_as_vectors():
    points = points_around(TILTED, np.random.default_rng(1), 40)
    points = points[:, wire_gap(points, SECOND) > 0.3 * SECOND.radius]
    both = field_at(points, [TILTED, SECOND])
    assert np.abs(both - field_at(points, [TILTED]) - field_at(points, [SECOND])).max() < 1e-13 * np.abs(both).max()
    reference = biot_savart(points, TILTED, 2400) + biot_savart(points, SECOND, 2400)
    assert (np.linalg.norm(both - reference, axis=0) / np.linalg.norm(reference, axis=0)).max() < 1e-12


def near_axis_and_wire(coil, rng):
    """Points on the loop's axis, within 1e-6 .. 1e-2 of it, and 0.05 .. 0.3 radii from the wire: both forms of
    the quotients by ρ' (loop.py)."""
    u, v = frame(coil.normal)
    a, centre, normal = coil.radius, np.asarray(coil.centre), np.asarray(coil.normal)
    out = [centre + 0.7 * a * normal]
    for _ in range(12):
        angle, z = rng.uniform(0.0, 2.0 * np.pi), rng.uniform(-1.5, 1.5) * a
        out.append(centre + z * normal + 10.0 ** rng.uniform(-6, -2) * a * (math.cos(angle) * u + math.sin(angle) * v))
        d, beta = rng.uniform(0.05, 0.3) * a, rng.uniform(0.0, 2.0 * np.pi)
        radial = math.cos(angle) * u + math.sin(angle) * v
        out.append(centre + (a + d * math.cos(beta)) * radial + d * math.sin(beta) * normal)
    return np.array(out).T


@pytest.mark.parametrize("coils", [[TILTED], [TILTED, SECOND]], ids=["one", "two"])
def test_derivatives_of_H2_against_central_differences_and_the_field(coils):
    points = near_axis_and_wire(TILTED, np.random.default_rng(7))
    rows = rows_at(points, coils)
    h = field_at(points, coils)
    assert np.abs(rows[0] - (h * h).sum(axis=0)).max() <= 1e-14 * rows[0].max()
    step = 1e-5 * np.minimum(TILTED.radius, np.min([wire_gap(points, coil) for coil in coils], axis=0))
    first = [1, 2, 3]
    second = {(0, 0): 4, (0, 1): 5, (0, 2): 6, (1, 1): 7, (1, 2): 8, (2, 2): 9}
    for b in range(3):
        shift = np.zeros((3, points.shape[1]))
        shift[b] = step
        up, down = rows_at(points + shift, coils), rows_at(points - shift, coils)
        gradient = (up[0] - down[0]) / (2 * step)
        scale = np.abs(rows[1:4]).max(axis=0)
        assert (np.abs(rows[first[b]] - gradient) / scale).max() < 1e-8
        for c in range(3):
            row = second[min(b, c), max(b, c)]
            difference = (up[first[c]] - down[first[c]]) / (2 * step)
            scale = np.abs(rows[4:]).max(axis=0)
            assert (np.abs(rows[row] - difference) / scale).max() < 1e-7, (b, c)


COAXIAL = [Coil.coaxial(1.7321, 1.0, 1.0), Coil.coaxial(1.7321, -1.0, -1.0), Coil.coaxial(0.9, 0.5, 0.5)]


def test_a_coaxial_loop_in_the_general_form_is_the_coaxial_form():
    rng = np.random.default_rng(3)
    x, y, z = rng.uniform(-3.0, 3.0, (3, 200))
    x[:10], y[:10] = 0.0, 0.0  # on the axis
    table = coaxial_table(COAXIAL)
    rho = np.hypot(x, y)
    h_rho, h_z = field_components(rho, z, table)
    with np.errstate(invalid="ignore"):
        ex, ey = np.where(rho > 0, x / rho, 0.0), np.where(rho > 0, y / rho, 0.0)
    points = np.array([x, y, z])
    general = field_at(points, COAXIAL)
    coaxial = np.array([h_rho * ex, h_rho * ey, h_z])
    scale = sum(np.linalg.norm(field_at(points, [coil]), axis=0) for coil in COAXIAL)  # the sum's condition
    assert (np.linalg.norm(general - coaxial, axis=0) / scale).max() < 1e-14
    # the rows in the half plane y = 0, x ≥ 0, where Q_x = Q_ρ, Q_xx = Q_ρρ, Q_yy = Q_ρ/ρ (Q_ρρ on the axis) ...
    x = np.abs(x)
    rows = rows_at(np.array([x, np.zeros_like(x), z]), COAXIAL)
    q, q_r, q_z, q_rr, q_rz, q_zz = np.array([field_squared(r, zz, table) for r, zz in zip(x, z)]).T
    with np.errstate(invalid="ignore", divide="ignore"):
        q_yy = np.where(x > 0, q_r / x, q_rr)
    expected = np.array([q, q_r, 0 * q, q_z, q_rr, 0 * q, q_rz, q_yy, 0 * q, q_zz])
    # at each point, relative to the largest entry of the same order; the (ρ, z) second derivatives are themselves
    # accurate to ~4e-14 (docs/numerics.md §5), and the two routes to Q_yy (Q_ρ/ρ; the field equations) differ so
    for order, tolerance in ((slice(0, 1), 1e-14), (slice(1, 4), 1e-14), (slice(4, 10), 1e-13)):
        scale = np.abs(rows[order]).max(axis=0)
        assert (np.abs(rows[order] - expected[order]).max(axis=0) <= tolerance * scale).all(), order
    # ... and turned about the axis: Q is invariant, its gradient turns with the point
    turn = 0.9
    turned = rows_at(np.array([x * math.cos(turn), x * math.sin(turn), z]), COAXIAL)
    assert np.abs(turned[0] - rows[0]).max() <= 1e-14 * rows[0].max()
    assert np.abs(turned[1] - math.cos(turn) * rows[1]).max() <= 1e-14 * np.abs(rows[1]).max()


def test_the_field_is_not_a_number_on_a_wire():
    u, _ = frame(TILTED.normal)
    on_wire = (np.asarray(TILTED.centre) + TILTED.radius * u)[:, None]
    assert np.isnan(field_at(on_wire, [TILTED])).all() and np.isnan(rows_at(on_wire, [TILTED])).all()


# --- the scene ---------------------------------------------------------------------------------------------

MATERIAL = '[material]\npreset = "SPOM1"\n[field]\nM = 0.002\n'


def coil_text(**keys):
    return MATERIAL + "[[field.coils]]\n" + "".join(f"{k} = {v}\n" for k, v in keys.items())


def test_the_general_form_reads_normalised_and_writes_back():
    scene = parse_scene(coil_text(radius=3.0, centre="[1.5, 0.0, 0.5]", normal="[0, 3, 4]", current=2))
    (coil,) = scene.field.coils
    assert coil.centre == (1.5, 0.0, 0.5) and coil.normal == (0.0, 0.6, 0.8) and not coil.is_coaxial
    assert parse_scene(scene.to_toml()).field == scene.field
    assert "centre = [1.5, 0.0, 0.5]" in scene.to_toml() and "height" not in scene.to_toml()


def test_a_coaxial_loop_in_the_general_form_is_stored_as_the_coaxial_form():
    written = parse_scene(coil_text(radius=1.7321, height=1.0, current=1.0))
    general = parse_scene(coil_text(radius=1.7321, centre="[0, 0, 1.0]", normal="[0, 0, 2]", current=1.0))
    reversed_normal = parse_scene(coil_text(radius=1.7321, centre="[0, 0, 1.0]", normal="[0, 0, -1]", current=-1.0))
    assert general.field == written.field == reversed_normal.field
    assert general.to_toml() == written.to_toml()
    assert written.field.coils[0].to_table() == {"radius": 1.7321, "height": 1.0, "current": 1.0}


@pytest.mark.parametrize("keys, message", [
    ({"radius": 2, "centre": "[1, 0, 0]", "normal": "[0, 0, 0]", "current": 1},
     "field.coils[0].normal = [0, 0, 0]: must have a nonzero length"),
    ({"radius": 2, "height": 1, "centre": "[0, 0, 1]", "current": 1},
     "field.coils[0]: both height = 1 and centre = [0, 0, 1] given"),
    ({"radius": 2, "current": 1}, "field.coils[0]: neither given"),
    ({"radius": 2, "centre": "[1, 0]", "current": 1}, "field.coils[0].centre = [1, 0]: must be 3 numbers"),
    ({"radius": 2, "centre": "[1, 0, 2000]", "current": 1}, "field.coils[0].centre = [1, 0, 2000]: each entry"),
    # a wire through the sphere: its closest approach (|c⊥| − a)² + (c·n)² = 0.3² + 0.2²
    ({"radius": 1.0, "centre": "[0.7, 0, 0.2]", "current": 1},
     "field.coils[0]: wire at distance 0.360555 from the centre lies inside the undeformed membrane"),
    # tilted by 90° about an axis through the centre, at distance 1: the wire touches the sphere
    ({"radius": 1.0, "centre": "[0, 0, 0]", "normal": "[1, 0, 0]", "current": 1},
     "field.coils[0]: wire at distance 1 from the centre lies on the undeformed membrane"),
], ids=["zero-normal", "height-and-centre", "no-place", "short-centre", "far-centre", "wire-inside", "wire-on"])
def test_invalid_general_coils_are_refused_in_one_line(keys, message):
    with pytest.raises(SceneError) as error:
        parse_scene(coil_text(**keys))
    assert message in str(error.value) and "\n" not in str(error.value)


def test_the_same_loop_twice_is_refused():
    text = coil_text(radius=3, centre="[1, 0, 0.5]", normal="[0, 1, 0]", current=1) + \
        "[[field.coils]]\nradius = 3\ncentre = [1, 0, 0.5]\nnormal = [0, -1, 0]\ncurrent = 3\n"
    with pytest.raises(SceneError, match=r"field.coils\[1\]: same radius = 3.0, centre = \[1.0, 0.0, 0.5\] and "
                                         r"normal = ±\[0.0, -1.0, 0.0\] as field.coils\[0\]"):
        parse_scene(text)


def test_a_coaxial_scene_in_the_general_form_traces_the_same_primary_branch():
    scene = load_scene(TWO_COILS)
    general = parse_scene(scene.text.replace("height = 1.0", "centre = [0.0, 0.0, 1.0]\nnormal = [0, 0, 1]")
                          .replace("height = -1.0", "centre = [0, 0, -1.0]\nnormal = [0, 0, -1]")
                          .replace("current = -1.0", "current = 1.0"), scene.name)
    assert "normal = [0, 0, -1]" in general.text
    P = [trace_primary(s, stop_stretch=1.5).X[:, -1] for s in (scene, general)]
    assert P[0].shape == P[1].shape and np.abs(P[0] - P[1]).max() <= 1e-12 * np.abs(P[0]).max()


# --- a non-axisymmetric field is not traced by the axisymmetric solver --------------------------------------

def test_the_axisymmetric_commands_refuse_a_coil_that_is_not_coaxial(tmp_path, capsys):
    """solve, critical and sweep work on axisymmetric primary branches: one line, exit 2, nothing written (run
    traces such a scene on the whole sphere: tests/test_surface_primary.py)."""
    path = tmp_path / "tilted.toml"
    path.write_text(coil_text(radius=2.0, centre="[0.5, 0, 0]", normal="[0, 0, 1]", current=1))
    out = tmp_path / "tilted.h5"
    for argv in (["solve", str(path), "--pole-stretch", "1.5"],
                 ["critical", str(path), "--parameter", "M", "-o", str(out)],
                 ["sweep", str(path), "--vary", "M=0.001,0.002", "-o", str(out)]):
        assert main(argv) == 2
        line = capsys.readouterr().err
        assert line.count("\n") == 1 and ("coil 0 is not coaxial (centre [0.5, 0.0, 0.0], normal [0.0, 0.0, 1.0]): "
                                          f"{argv[0]} works on axisymmetric fields only") in line
    assert not out.exists()
    with pytest.raises(FieldError, match="coil 0 is not coaxial"):
        trace_primary(load_scene(path))
