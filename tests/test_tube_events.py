"""``[[events]]`` on a tube (tube/events.py): UZ points on its primary and bulge branches, located to the solver's
tolerance, against the neo-Hookean uniform closed tube derived in tests/test_tube.py from the strain energy

    Φ = λ1² + λ2² + (λ1λ2)⁻² − 3:  N = 0 is 2λθ²λz⁴ − λθ⁴λz² − 1 = 0,  P = 2(1 − λz⁻²λθ⁻⁴)/λz,  V/V0 = λθ²λz,

stored in the run file with their event, shown by ``inspect``; quantities without meaning on a shape refused."""
import json

import numpy as np
import pytest
import sympy as sp

import balloon_cg
from balloon_cg.analysis.results import Kind
from balloon_cg.app.cli import main
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.io.tube_file import read_tube_run, stored_branch
from balloon_cg.tube.bulge import bulge_branch
from balloon_cg.tube.primary import primary_branch, scene_parameters, volume_ratio
from test_interval import tube_scene
from test_tube import neo_hookean_state

EVENTS = {"lam2_max": 2.0, "lam2_top": 1.2, "lam2_bottom": 1.4, "lam2_equator": 2.5, "volume_ratio": 4.0,
          "axial_stretch": 1.5, "pressure": 1.0, "amount": 100.0}


def events(**chosen) -> str:
    return "".join(f'[[events]]\nquantity = "{q}"\nvalue = {v}\n' for q, v in chosen.items())


def closed_form(quantity, value):
    """[(λθ, λz, P)] of the neo-Hookean uniform closed tube of length 10 where ``quantity`` = ``value``, in the order
    along the path (λθ rising from 1 to 3), by nsolve at 30 digits on the closed-end path λz(λθ) of
    ``neo_hookean_state``."""
    hoop = sp.Symbol("hoop", positive=True)
    axial, P = neo_hookean_state(hoop)
    q = {"lam2_max": hoop, "lam2_top": hoop, "lam2_bottom": hoop, "lam2_equator": hoop,
         "volume_ratio": hoop**2 * axial, "axial_stretch": axial, "pressure": P,
         "amount": P * hoop**2 * axial * sp.pi * 10}[quantity]
    grid = np.linspace(1.0 + 1e-9, 3.0, 400)
    f = sp.lambdify(hoop, q - value)
    signs = np.sign([float(f(g)) for g in grid])
    roots = [sp.nsolve(q - value, hoop, (grid[i], grid[i + 1]), solver="bisect", prec=30)
             for i in np.flatnonzero(signs[:-1] * signs[1:] < 0)]
    return [(float(r), float(axial.subs(hoop, r)), float(P.subs(hoop, r))) for r in roots]


@pytest.fixture(scope="module")
def uniform():
    """The neo-Hookean closed tube (L = 10, sliding ends, degree 16) traced to a hoop stretch of 3 with one event of
    every quantity of EVENTS."""
    return primary_branch(tube_scene("neo-Hookean", 10.0, "[solver]\ndegree = 16\n[continuation]\nstop_stretch = 3\n"
                                     + events(**EVENTS)))


@pytest.mark.parametrize("quantity", list(EVENTS))
def test_events_on_the_uniform_tube_are_its_closed_form(uniform, quantity):
    """Each event's UZ points are the closed form's states, in order along the path (P = 1 twice: before and past the
    pressure maximum): λθ, λz and P within 1e-10, the quantity at its value within 1e-12 (relative), status located."""
    found = [s for s in uniform.special if s.kind == Kind.UZ and s.note == f"{quantity} = {EVENTS[quantity]:g}"]
    expected = closed_form(quantity, EVENTS[quantity])
    assert len(found) == len(expected) >= 1
    disc = uniform.disc
    for s, (hoop, axial, P) in zip(found, expected):
        assert s.status == "located"
        assert abs(s.u[0] - hoop) <= 1e-10 and abs(s.u[disc.axial_index] - axial) <= 1e-10
        assert abs(s.pressure - P) <= 1e-10
        assert np.abs(s.u[1:disc.axial_index]).max() <= 1e-10  # uniform: a_0 alone


def test_event_points_are_in_order_along_the_branch(uniform):
    """The located points, UZ among the others, lie in order along the branch: their λθ (the path's own coordinate:
    it rises monotonically on the closed-end path) never falls; the first LP (the pressure maximum) between the two
    UZ at P = 1."""
    hoops = [s.u[0] for s in uniform.special]
    assert all(b >= a - 1e-12 for a, b in zip(hoops, hoops[1:]))
    kinds = [(s.kind, s.note) for s in uniform.special]
    first, second = [i for i, k in enumerate(kinds) if k == (Kind.UZ, "pressure = 1")]
    assert first < kinds.index((Kind.LP, "")) < second


def test_event_on_the_bulge_branch_is_its_landed_volume_end():
    """SPOM1, L = 10, degree 16: the bulge branch with an event V/V0 = 3.5 and lam2_top = 3 (the bulge at S = 0) has
    one UZ of each, equilibria (residual ≤ 1e-10) where the quantity holds (1e-12); the V/V0 one is the state the same
    branch traced to continuation.stop_volume = 3.5 πL lands its end on (P within 1e-9), and the lam2_top one has
    λ2(0) = 3 from the profile."""
    extra = "[solver]\ndegree = 16\n[continuation]\nstop_stretch = 4\nstep_max = 0.5\n"
    scene = tube_scene("SPOM1", 10.0, extra + events(volume_ratio=3.5, lam2_top=3.0))
    primary = primary_branch(scene)
    onset = primary.branch_points("odd")[0]
    bulge = bulge_branch(scene, primary, onset, stop_stretch=4.0)
    found = {s.note: s for s in bulge.special if s.kind == Kind.UZ}
    assert sorted(found) == ["lam2_top = 3", "volume_ratio = 3.5"]
    eq = Equilibrium(scene, bulge.disc)
    for s in found.values():
        assert s.status == "located"
        assert np.abs(eq.residual(s.u, Parameters(s.pressure))[bulge.disc.free]).max() <= 1e-10
    volume = found["volume_ratio = 3.5"]
    assert volume_ratio(eq, np.append(volume.u, volume.pressure)) == pytest.approx(3.5, rel=1e-12)
    assert bulge.disc.profile(found["lam2_top = 3"].u, np.array([0.0]))[0][0] == pytest.approx(3.0, rel=1e-12)
    ended = bulge_branch(scene, primary, onset, stop_volume=3.5 * np.pi * scene.geometry.length, stop_stretch=4.0)
    assert ended.volume[-1] == pytest.approx(3.5, rel=1e-12)
    assert abs(ended.pressure[-1] - volume.pressure) <= 1e-9


def test_run_stores_the_events_and_inspect_shows_them(tmp_path, capsys):
    """``run`` on a tube scene with events: the file's UZ points carry their event (``note``) and read back through
    ``stored_branch`` and ``load``'s table; ``inspect`` lists them with it; ``--json`` too."""
    scene = tmp_path / "t.toml"
    scene.write_text(tube_scene("neo-Hookean", 10.0, "[solver]\ndegree = 16\n[continuation]\nstop_stretch = 2.5\n"
                                + events(volume_ratio=4.0)).to_toml())
    out = tmp_path / "t.h5"
    assert main(["run", str(scene), "-o", str(out), "--quiet", "--primary-only"]) == 0
    run = read_tube_run(out)
    uz = [s for s in run["branches"]["primary"]["special_points"] if s["kind"] == "UZ"]
    assert [s["note"] for s in uz] == ["volume_ratio = 4"] and uz[0]["volume"] == pytest.approx(4.0, rel=1e-12)
    branch = stored_branch(run, "primary", scene_parameters(tube_scene("neo-Hookean")))
    assert [s.note for s in branch.special if s.kind == Kind.UZ] == ["volume_ratio = 4"]
    special = balloon_cg.load(out).to_dataframe("special")
    assert list(special.loc[special["kind"] == "UZ", "note"]) == ["volume_ratio = 4"]
    capsys.readouterr()
    assert main(["inspect", str(out)]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if " UZ " in line]
    assert len(lines) == 1 and "volume_ratio = 4" in lines[0] and "V/V0 = 4" in lines[0]
    assert main(["inspect", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert [s["note"] for s in summary["branches"]["primary"]["special_points"] if s["kind"] == "UZ"] == \
        ["volume_ratio = 4"]


@pytest.mark.parametrize("geometry, quantity, message", [
    ("", "lam2_max", 'events[0].quantity = "lam2_max": located on a tube\'s branches only, not on a sphere'),
    ('shape = "tube"\nlength = 10\nends = "plugged"\n', "lam2_bottom",
     'events[0].quantity = "lam2_bottom": the plugs hold the hoop stretch at a plugged tube\'s ends at 1'),
    ('shape = "tube"\nlength = 10\naxial_stretch = 1.2\n', "axial_stretch",
     'events[0].quantity = "axial_stretch": the ends are held apart'),
])
def test_meaningless_quantities_are_refused_in_one_line(tmp_path, capsys, geometry, quantity, message):
    """A quantity without meaning on the shape: exit 2, one line naming the event, its quantity, why and the
    allowed ones, no file written."""
    scene = tmp_path / "s.toml"
    scene.write_text(f'[material]\npreset = "SPOM1"\n[geometry]\n{geometry}' + events(**{quantity: 2.0}))
    assert main(["run", str(scene), "-o", str(tmp_path / "s.h5")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0] and "allowed: " in err[0], err
    assert quantity not in err[0].split("allowed: ")[1]
    assert not (tmp_path / "s.h5").exists()

