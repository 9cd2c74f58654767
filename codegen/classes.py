"""The scene classes kernels are generated for: preset exponent sets, named models, the general class, and the
strain-energy families of scene/energies.py (parameters at run time)."""
from balloon_cg.scene.energies import FAMILIES
from balloon_cg.scene.formula import parse_formula

from .functional import SceneClass

EXPONENT_SETS = {
    "spom1": ("1.3", "4", "-2"),
    "spom2": ("1.73", "4", "-2"),
    "fpom1": ("1.3", "-2"),
    "fpom2": ("1.73", "-2"),
    "tpom1": ("1.3",),
    "tpom2": ("1.98",),
    "neo_hookean": ("2",),
    "mooney_rivlin": ("2", "-2"),
}


def scene_classes() -> list[SceneClass]:
    classes = []
    for name, alphas in EXPONENT_SETS.items():
        classes.append(SceneClass(f"ogden_{name}", alphas, field=False))
        classes.append(SceneClass(f"ogden_{name}_field", alphas, field=True))
    classes.append(SceneClass("ogden_general_field", None, field=True))
    return classes + energy_classes()


def energy_class(name: str, formula: str, parameters: tuple, field: bool, electric: bool = False) -> SceneClass:
    """The class of a strain energy: its canonical formula text and parameter names (``electric``: with the
    dielectric term)."""
    return SceneClass(name, None, field, energy=(parse_formula(formula, parameters).text, tuple(parameters)),
                      electric=electric)


def energy_classes() -> list[SceneClass]:
    """``KEY`` and ``KEY_field`` for every family."""
    return [energy_class(f"{key}{'_field' if field else ''}", family.formula, family.parameters, field)
            for key, family in FAMILIES.items() for field in (False, True)]
