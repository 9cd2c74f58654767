"""The scene classes kernels are generated for: preset exponent sets, named models, and the general class."""
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
    return classes
