"""Scene layer: materials, TOML parsing, validation messages, overrides and round trips."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balloon_cg.scene.materials import PRESETS, Material, get_preset, material_from_table
from balloon_cg.scene import (
    Coil, Continuation, Field, Output, Scene, SceneError, Solver, Stability, load_scene, parse_scene,
)

SCENES = sorted((Path(__file__).resolve().parents[1] / "scenes").glob("*.toml"))

PAIR = (Coil.coaxial(1.7321, 1.0, 1.0), Coil.coaxial(1.7321, -1.0, -1.0))

TWO_COILS = """
[material]
preset = "SPOM1"
[field]
M = 0.002
[[field.coils]]
radius = 1.7321
height = 1.0
current = 1.0
[[field.coils]]
radius = 1.7321
height = -1.0
current = -1.0
"""


@pytest.mark.parametrize("name", PRESETS)
def test_presets(name):
    material = PRESETS[name]
    assert len(material.mu) == len(material.alpha)
    assert abs(material.shear_modulus_sum - 4) < 2e-3
    assert parse_scene(f'[material]\npreset = "{name.upper()}"').material == material
    assert get_preset(name.lower()) is material


def test_preset_terms():
    assert PRESETS["FPOM1"] == Material("FPOM1", (3.04969, -0.0177), (1.3, -2.0))
    assert PRESETS["TPOM2"].alpha == (1.98,)
    mr = PRESETS["Mooney-Rivlin"]
    assert mr.mu == (1.8181818181818181, -0.18181818181818182)
    assert -mr.mu[1] / mr.mu[0] == pytest.approx(0.1)  # C2/C1


def test_custom_material():
    m = material_from_table({"mu": [1, 1], "alpha": [2, 2.0]})
    assert m == Material("custom", (1.0, 1.0), (2.0, 2.0))
    assert material_from_table({"preset": "tpom1", "name": "mine"}).mu == PRESETS["TPOM1"].mu


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.name)
def test_scene_files_parse(path):
    scene = load_scene(path)
    assert scene.name == path.stem
    assert scene.text.startswith("#")
    stop = {"spom1": 6.0, "tube_spom1_L10": 9.0, "tube_spom1_L10_coil": 9.0, "tube_gent_L10_held": 8.0,
            "tube_spom1_L6_plugged_held3": 7.0}.get(path.stem, 5.0)  # spom1: the whole isola; the tubes: their
    # plateau; the held Gent tube: its onset curve back along the upper root; the plugged one: past its minimum
    assert scene.continuation.stop_stretch == stop
    if "two_coils" in path.name:
        assert scene.field.coils == PAIR and scene.field.M == float(path.stem.split("_M")[1])


def test_scene_set_is_complete():
    names = {p.name for p in SCENES}
    for stem in ("spom1", "spom2", "fpom1", "fpom2", "tpom1", "tpom2", "spom1_single_coil"):
        assert f"{stem}.toml" in names
    for material in ("spom1", "tpom1"):
        for M in ("0.001", "0.002", "0.003"):
            assert f"{material}_two_coils_M{M}.toml" in names


def test_defaults():
    scene = parse_scene('[material]\npreset = "TPOM1"', name="t")
    assert scene.name == "t"
    assert scene.field == Field() == Field(1.0, 0.0, ())
    assert scene.continuation == Continuation()
    assert scene.continuation.stop_pressure is None and scene.continuation.symmetry == "auto"
    assert scene.solver == Solver(40, 0, 1e-11, 25)
    assert scene.stability == Stability(20, 1)
    assert scene.output == Output(181)
    assert isinstance(scene.solver.degree, int) and isinstance(scene.field.M, float)


def test_symmetry():
    assert Field(M=0.002, coils=PAIR).is_equator_symmetric
    assert Field(coils=(Coil.coaxial(1.7321, 1.0, 1.0), Coil.coaxial(1.7321, -1.0, 1.0))).is_equator_symmetric
    assert Field(coils=(Coil.coaxial(4.0, 0.0, 1.0),)).is_equator_symmetric
    assert Field().is_equator_symmetric
    assert not Field(coils=(Coil.coaxial(4.0, 0.5, 1.0),)).is_equator_symmetric
    assert not Field(coils=(Coil.coaxial(1.7321, 1.0, 1.0), Coil.coaxial(1.7321, -1.0, 2.0))).is_equator_symmetric
    # a coil at h = 0 pairs with itself (same sign): it breaks the opposite-sign pair's symmetry
    assert not Field(coils=PAIR + (Coil.coaxial(4.0, 0.0, 1.0),)).is_equator_symmetric
    assert parse_scene(TWO_COILS + '[continuation]\nsymmetry = "equator"').continuation.symmetry == "equator"


def test_round_trip():
    for text in (TWO_COILS, '[material]\nmu = [1.5, 0.5]\nalpha = [2, -2]\n[continuation]\nstop_pressure = 3'):
        scene = parse_scene(text, name="rt")
        again = parse_scene(scene.to_toml(), name="rt")
        assert replace(again, text="") == replace(scene, text="")
        assert again.to_dict() == scene.to_dict()
    d = parse_scene(TWO_COILS).to_dict()
    assert d["field"]["coils"][1] == {"radius": 1.7321, "height": -1.0, "current": -1.0}
    assert d["material"] == {"name": "SPOM1", "mu": [3.00508, 0.0145, -0.0177], "alpha": [1.3, 4.0, -2.0]}
    assert d["continuation"]["stop_pressure"] is None


def test_with_overrides():
    scene = parse_scene(TWO_COILS, name="two")
    swept = scene.with_overrides({"field.M": np.float64(0.003), "solver.degree": np.int64(60),
                                  "field.coils[1].current": -2.0})
    assert swept.field.M == 0.003 and swept.solver.degree == 60 and swept.field.coils[1].current == -2.0
    assert swept.name == "two_M0.003_current1=-2" and parse_scene(swept.text, name=swept.name) == swept


    assert scene.field.M == 0.002  # the original is untouched
    assert swept.with_overrides({"material.preset": "tpom2"}).material == PRESETS["TPOM2"]
    custom = swept.with_overrides({"material.alpha": np.array([1.3, 4.0, -2.5])})
    assert custom.material.alpha == (1.3, 4.0, -2.5) and custom.material.name == "SPOM1 (alpha3 = -2.5)"
    assert parse_scene(custom.text, name=custom.name) == custom  # named as what it is, read back the same
    assert swept.with_overrides({"material.mu": [1.0], "material.alpha": [2.0]}).material.name == "custom"
    gent = swept.with_overrides({"material.preset": "gent"})
    assert gent.with_overrides({"material.parameters.Jm": 50}).material.name == "Gent (Jm = 50)"
    assert swept.with_overrides({"field.M": 0.001}).material.name == "SPOM1"  # the material untouched
    assert swept.with_overrides({"field.M": None}).field.M == 0.0
    for overrides, key in (
        ({"field.M": -0.1}, "field.M"),
        ({"material.alpha": [1.3, 0, -2]}, "material.alpha[1]"),
        ({"solver.degre": 50}, "solver.degre"),
        ({"field.coils[2].current": 1.0}, "field.coils[2]"),
        ({"field.coils[0].height": 0.5, "continuation.symmetry": "equator"}, "continuation.symmetry"),
    ):
        with pytest.raises(SceneError) as err:
            scene.with_overrides(overrides)
        assert str(err.value).startswith(f"two: {key}")


def test_a_new_preset_and_its_parameters_in_one_override():
    """`--set material.preset=Gent --set material.parameters.Jm=50` on an Ogden scene: the parameter is the new
    preset's (it was checked against the old material, which has none), in either order; every other material
    key applies to the new preset too."""
    scene = parse_scene(TWO_COILS, name="two")
    for overrides in ({"material.preset": "Gent", "material.parameters.Jm": 50.0},
                      {"material.parameters.Jm": 50.0, "material.preset": "Gent"}):
        gent = scene.with_overrides(overrides)
        assert gent.material.family == "gent" and gent.material.parameters == {"mu": 2.0, "Jm": 50.0}
        assert parse_scene(gent.text, name=gent.name) == gent
    with pytest.raises(SceneError, match="no parameter 'Jm'"):
        scene.with_overrides({"material.preset": "Yeoh", "material.parameters.Jm": 50.0})
    # the preset first in any order: a material key given before it was silently dropped
    assert scene.with_overrides({"material.name": "mine", "material.preset": "TPOM1"}).material.name == "mine"
    for overrides in ({"material.alpha": [1.5, 4.0, -2.0], "material.preset": "TPOM1"},
                      {"material.preset": "TPOM1", "material.alpha": [1.5, 4.0, -2.0]}):
        with pytest.raises(SceneError, match="give one of preset"):
            scene.with_overrides(overrides)


def test_with_overrides_takes_the_bare_names_of_the_command_line():
    """{"M": x} is {"field.M": x} (the one table with that key), as `--set M=x`; an ambiguous or unknown bare
    name is refused naming the tables."""
    scene = parse_scene(TWO_COILS, name="spom1_two_coils_M0.002")
    bare = scene.with_overrides({"M": 0.0025, "stop_stretch": 3.0, "preset": "TPOM1"})
    dotted = scene.with_overrides({"field.M": 0.0025, "continuation.stop_stretch": 3.0, "material.preset": "TPOM1"})
    assert bare == dotted and bare.name == "spom1_two_coils_M0.0025_tpom1"
    assert scene.canonical_key("M") == "field.M" and scene.canonical_key("solver.degree") == "solver.degree"
    for key, words in (("degree", "a bare name must name a key of exactly one scene table; 'degree' is in tables "
                                  "solver, stability (write one of solver.degree, stability.degree)"),
                       ("stop_strech", "not a scene key (did you mean stop_stretch?)")):
        with pytest.raises(SceneError) as err:
            scene.with_overrides({key: 3})
        assert str(err.value).startswith(f"spom1_two_coils_M0.002: {key}: {words}")
    with pytest.raises(SceneError, match="field.M is given twice"):
        scene.with_overrides({"M": 0.001, "field.M": 0.003})


def test_with_overrides_renames_after_physical_keys():
    scene = parse_scene(TWO_COILS, name="spom1_two_coils_M0.002")
    assert scene.with_overrides({"field.M": 0.0025}).name == "spom1_two_coils_M0.0025"  # the token updated
    assert scene.with_overrides({"field.coils[0].radius": 2.5}).name == "spom1_two_coils_M0.002_radius2.5"
    assert scene.with_overrides({"material.preset": "TPOM1"}).name == "spom1_two_coils_M0.002_tpom1"
    assert scene.with_overrides({"continuation.max_points": 10}).name == scene.name  # numerics keep the name
    assert scene.with_overrides({"field.M": 0.001}, name="mine").name == "mine"
    both = scene.with_overrides({"field.coils[0].radius": 3.5, "field.coils[1].radius": 3.0})
    assert both.name == "spom1_two_coils_M0.002_radius3.5_radius1=3"  # index past 0 kept, no ambiguity
    coils = [{"radius": 3.0, "height": 0.0, "current": 1.0}]
    assert scene.with_overrides({"field.coils": coils}).name == scene.name  # tables and lists: no token
    assert scene.with_overrides({"material.name": "my balloon/v2"}).name == "spom1_two_coils_M0.002_my-balloon-v2"


def test_shipped_scenes_by_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert load_scene("spom1").name == "spom1" and load_scene("spom1_two_coils_M0.002.toml").field.M == 0.002
    (tmp_path / "spom1.toml").write_text('[material]\npreset = "TPOM1"\n')
    assert load_scene("spom1.toml").material.name == "TPOM1"  # a file of that name comes first
    with pytest.raises(FileNotFoundError, match=r"nor the name of a scene shipped .*\(fpom1, fpom2, spom1, "):
        load_scene("no_such_scene")  # a typo of a shipped name is told which names there are



def test_file_error_names_file(tmp_path):
    path = tmp_path / "spom1.toml"
    path.write_text('[material]\npreset = "SPOM1"\n[field]\nM = -0.1\n')
    with pytest.raises(SceneError) as err:
        load_scene(path)
    assert str(err.value) == "spom1.toml: field.M = -0.1: must be in [0, 1000]"


MAT = '[material]\npreset = "SPOM1"\n'
COIL = "[[field.coils]]\nradius = {a}\nheight = {h}\ncurrent = {s}\n"
FIELD = MAT + "[field]\nM = 0.002\n"


def coil(a=1.7321, h=1.0, s=1.0):
    return COIL.format(a=a, h=h, s=s)


BAD = [
    # (id, toml text, text the message must contain)
    ("malformed", MAT + "[field\nM = 1", "line 3"),
    ("unknown-table", MAT + "[materail]\npreset = 1", "[materail]"),
    ("top-level-key", "M = 0.1\n" + MAT, "M = 0.1: unknown top-level key"),
    ("unknown-key", MAT + "[solver]\ndegre = 50", "solver.degre"),
    ("unknown-material-key", '[material]\nprest = "SPOM1"', "material.prest"),
    ("unknown-coil-key", FIELD + coil() + "radiu = 2", "field.coils[0].radiu"),
    ("no-material", "[field]\nchi = 1.0", "material"),
    ("material-not-table", "material = 3", "material"),
    ("unknown-preset", '[material]\npreset = "SPOM3"', "material.preset"),
    ("preset-not-string", "[material]\npreset = 1", "material.preset"),
    ("preset-and-mu", '[material]\npreset = "SPOM1"\nmu = [2]\nalpha = [2]', "material.preset"),
    ("mu-without-alpha", "[material]\nmu = [2]", "material.alpha"),
    ("mismatched", "[material]\nmu = [2, 1]\nalpha = [2]", "material.alpha"),
    ("empty", "[material]\nmu = []\nalpha = []", "material.mu"),
    ("alpha-zero", "[material]\nmu = [2, 1]\nalpha = [2, 0]", "material.alpha[1] = 0: exponents must be nonzero"),
    ("mu-nan", "[material]\nmu = [nan]\nalpha = [2]", "material.mu[0]"),
    ("alpha-inf", "[material]\nmu = [2]\nalpha = [inf]", "material.alpha[0]"),
    ("mu-string", '[material]\nmu = ["2"]\nalpha = [2]', "material.mu[0]"),
    ("mu-not-list", "[material]\nmu = 2\nalpha = [2]", "material.mu"),
    ("shear-negative", "[material]\nmu = [-2]\nalpha = [2]", "material.mu"),
    ("too-many-terms", "[material]\nmu = [1, 1, 1, 1, 1, 1, 1]\nalpha = [1, 1, 1, 1, 1, 1, 1]", "material.mu"),
    ("name-not-string", "[material]\nname = 3\nmu = [2]\nalpha = [2]", "material.name"),
    ("M-string", MAT + '[field]\nM = "0.1"', "field.M"),
    ("M-negative", MAT + "[field]\nM = -0.1", "field.M = -0.1: must be in [0, 1000]"),
    ("M-inf", MAT + "[field]\nM = inf\n" + coil(), "field.M"),
    ("chi-negative", MAT + "[field]\nchi = -1", "field.chi"),
    ("chi-nan", MAT + "[field]\nchi = nan", "field.chi"),
    ("chi-bool", MAT + "[field]\nchi = true", "field.chi"),
    ("M-without-coils", FIELD, "field.M = 0.002 needs at least one [[field.coils]]"),
    ("coils-not-array", MAT + "[field]\ncoils = 3", "field.coils"),
    ("coil-missing-key", FIELD + "[[field.coils]]\nradius = 2\nheight = 0", "field.coils[0].current"),
    ("radius-zero", FIELD + coil(a=0, h=2), "field.coils[0].radius"),
    ("radius-negative", FIELD + coil(a=-2), "field.coils[0].radius"),
    ("radius-inf", FIELD + coil(a="inf"), "field.coils[0].radius"),
    ("radius-string", FIELD + coil(a='"2"'), "field.coils[0].radius"),
    ("current-zero", FIELD + coil(s=0), "field.coils[0].current"),
    ("current-nan", FIELD + coil(s="nan"), "field.coils[0].current"),
    ("height-inf", FIELD + coil(h="-inf"), "field.coils[0].height"),
    ("wire-on-membrane", FIELD + coil(a=1, h=0),
     "field.coils[0]: wire at distance 1 from the centre lies on the undeformed membrane (a² + h² must be > 1)"),
    ("wire-near-membrane", FIELD + coil(a=0.6, h=0.8), "lies on the undeformed membrane"),
    ("wire-inside", FIELD + coil(a=0.5, h=0.5), "field.coils[0]: wire at distance 0.707107"),
    ("identical-coils", FIELD + coil() + coil(s=-1), "field.coils[1]"),
    ("start-stretch", MAT + "[continuation]\nstart_stretch = 1.0", "continuation.start_stretch"),
    ("stop-stretch", MAT + "[continuation]\nstart_stretch = 2\nstop_stretch = 1.5\nmin_stretch = 1.1",
     "continuation.stop_stretch"),
    ("min-stretch-high", MAT + "[continuation]\nmin_stretch = 1.02", "continuation.min_stretch"),
    ("min-stretch-one", MAT + "[continuation]\nmin_stretch = 1", "continuation.min_stretch"),
    ("stop-pressure", MAT + "[continuation]\nstop_pressure = -1", "continuation.stop_pressure"),
    ("step-zero", MAT + "[continuation]\nstep_min = 0", "continuation.step_min"),
    ("step-above-max", MAT + "[continuation]\nstep = 0.5", "continuation.step"),
    ("step-below-min", MAT + "[continuation]\nstep_min = 0.1\nstep = 0.05", "continuation.step"),
    ("step-max-below-min", MAT + "[continuation]\nstep_min = 0.1\nstep_max = 0.01", "continuation.step_max"),
    ("max-points-zero", MAT + "[continuation]\nmax_points = 0", "continuation.max_points"),
    ("max-points-huge", MAT + "[continuation]\nmax_points = 100001", "continuation.max_points"),
    ("max-points-float", MAT + "[continuation]\nmax_points = 10.0", "continuation.max_points"),
    ("wire-gap", MAT + "[continuation]\nwire_gap = 0", "continuation.wire_gap"),
    ("symmetry-unknown", MAT + '[continuation]\nsymmetry = "mirror"', "continuation.symmetry"),
    ("symmetry-equator", FIELD + coil(a=2, h=0.5) + '[continuation]\nsymmetry = "equator"',
     "continuation.symmetry"),
    ("degree-low", MAT + "[solver]\ndegree = 7", "solver.degree"),
    ("degree-high", MAT + "[solver]\ndegree = 401", "solver.degree"),
    ("degree-float", MAT + "[solver]\ndegree = 40.0", "solver.degree"),
    ("degree-bool", MAT + "[solver]\ndegree = true", "solver.degree"),
    ("quadrature", MAT + "[solver]\nquadrature = 40", "solver.quadrature"),
    ("tol-zero", MAT + "[solver]\ntol = 0.0", "solver.tol"),
    ("tol-large", MAT + "[solver]\ntol = 0.01", "solver.tol"),
    ("max-newton", MAT + "[solver]\nmax_newton = 0", "solver.max_newton"),
    ("solver-not-table", "solver = 1\n" + MAT, "solver = 1: must be a table"),
    ("stability-degree", MAT + "[stability]\ndegree = 3", "stability.degree"),
    ("m-max", MAT + "[stability]\nm_max = 9", "stability.m_max"),
    ("theta-points", MAT + "[output]\ntheta_points = 2", "output.theta_points"),
    ("dynamics-count", MAT + "[dynamics]\ncount = 51", "dynamics.count = 51: must be an integer in [1, 50]"),
    ("dynamics-m-max", MAT + "[dynamics]\nm_max = -1", "dynamics.m_max = -1: must be an integer in [0, 8]"),
    ("dynamics-flag", MAT + '[dynamics]\nfrequencies = "yes"', 'dynamics.frequencies = "yes": must be true or false'),
    ("dynamics-unknown", MAT + "[dynamics]\nshapes = 3", "dynamics.shapes = 3: unknown key"),
    ("dynamics-modes", MAT + "[dynamics]\nmodes = 3", "dynamics.modes = 3: must be true or false"),
    ("unknown-key-newline", MAT + '[output]\n"a\\nb" = 1', "output."),
]


@pytest.mark.parametrize("text, expected", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_input(text, expected):
    with pytest.raises(SceneError) as err:
        parse_scene(text, name="bad.toml")
    message = str(err.value)
    assert "\n" not in message and len(message.splitlines()) == 1
    assert message.startswith("bad.toml: ")
    assert expected in message


def test_unknown_names_are_listed():
    with pytest.raises(SceneError, match="allowed: SPOM1, SPOM2, FPOM1, FPOM2, TPOM1, TPOM2, neo-Hookean"):
        parse_scene('[material]\npreset = "nope"')
    with pytest.raises(SceneError, match="allowed keys: degree, quadrature, tol, max_newton"):
        parse_scene(MAT + "[solver]\ndegre = 50")
    with pytest.raises(SceneError, match="allowed tables: material, field, continuation"):
        parse_scene(MAT + "[contination]")


def test_scene_is_frozen():
    scene = parse_scene(MAT)
    assert isinstance(scene, Scene)
    with pytest.raises(AttributeError):
        scene.name = "x"
