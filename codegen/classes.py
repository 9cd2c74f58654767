"""The scene table: the energy terms a class may have, and the classes kernels are committed for (preset exponent
sets, named models, the general class, and the strain-energy families of scene/energies.py, parameters at run
time)."""
from balloon_cg.scene.energies import FAMILIES
from balloon_cg.scene.formula import parse_formula

from .functional import SceneClass
from .terms.dielectric import DIELECTRIC
from .terms.elastic import Elastic
from .terms.magnetic import MAGNETIC
from .terms.pressure import PRESSURE

KNOWN_TERMS = (PRESSURE, MAGNETIC, DIELECTRIC)  # in kernel order

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


PLAIN, FIELD = ("pressure",), ("pressure", "magnetic")  # the term sets classes are committed for


def terms(names) -> tuple:
    """The terms of a class beyond the elastic one from their names (the runtime's, model/kernels.py:
    ``scene_terms``), in kernel order; ValueError for a name no term has."""
    unknown = set(names) - {t.name for t in KNOWN_TERMS}
    if unknown:
        raise ValueError(f"unknown energy terms {sorted(unknown)}; known: {[t.name for t in KNOWN_TERMS]}")
    return tuple(t for t in KNOWN_TERMS if t.name in names)


def strain_energy(formula: str, parameters: tuple) -> Elastic:
    """The elastic term of a strain energy: its canonical formula text and parameter names."""
    return Elastic(energy=(parse_formula(formula, parameters).text, tuple(parameters)))


def scene_classes() -> list[SceneClass]:
    classes = []
    for name, alphas in EXPONENT_SETS.items():
        classes.append(SceneClass(f"ogden_{name}", Elastic(alphas), terms(PLAIN)))
        classes.append(SceneClass(f"ogden_{name}_field", Elastic(alphas), terms(FIELD)))
    classes.append(SceneClass("ogden_general_field", Elastic(None), terms(FIELD)))
    return classes + energy_classes()


def energy_classes() -> list[SceneClass]:
    """``KEY`` and ``KEY_field`` for every family."""
    return [SceneClass(f"{key}{'_field' if field else ''}", strain_energy(family.formula, family.parameters),
                       terms(FIELD if field else PLAIN))
            for key, family in FAMILIES.items() for field in (False, True)]
