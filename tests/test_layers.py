"""The runtime's layers import only downward (README "How it is built"), numerics knows nothing of balloons and
the runtime never imports SymPy or codegen."""
import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "balloon_cg"
LAYERS = ("scene", "model", "numerics", "galerkin", "surface", "analysis", "tube", "dynamics", "io", "post", "app")
ALLOWED = {layer: set(LAYERS[: i + 1]) | {"generated"} for i, layer in enumerate(LAYERS)}
ALLOWED["numerics"] = {"numerics"}  # balloon-free
# the on-demand kernel cache is the one runtime module that runs the generator (balloon_cg.codegen, with SymPy)
GENERATOR_USERS = {"model/kernel_cache.py"}


def imported_layers(path: Path) -> set:
    """The balloon_cg subpackages a module imports (relative or absolute)."""
    module = path.relative_to(PACKAGE).with_suffix("").parts
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = list(module[: len(module) - node.level])
                target = base + (node.module.split(".") if node.module else [])
                names = [target + [alias.name] for alias in node.names] if not target else [target]
            elif node.module and node.module.split(".")[0] == "balloon_cg":
                names = [node.module.split(".")[1:] or [alias.name for alias in node.names][:1]]
            else:
                names = []
            found |= {name[0] for name in names if name}
        elif isinstance(node, ast.Import):
            found |= {alias.name.split(".")[1] for alias in node.names
                      if alias.name.startswith("balloon_cg.") and alias.name.count(".") >= 1}
    return found


def third_party(path: Path) -> set:
    roots = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            roots |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            roots.add(node.module.split(".")[0])
    return roots


@pytest.mark.parametrize("layer", LAYERS)
def test_layer_imports_only_downward(layer):
    for path in sorted((PACKAGE / layer).rglob("*.py")):
        allowed = ALLOWED[layer] | ({"codegen"} if path.relative_to(PACKAGE).as_posix() in GENERATOR_USERS else set())
        wrong = imported_layers(path) - allowed - {"__init__", "__version__"}
        assert not wrong, f"{path.relative_to(PACKAGE)} imports {sorted(wrong)} (allowed: {sorted(ALLOWED[layer])})"


# analysis/'s rooms, one per question (README, docs/shapes.md), in the order they may import one another: a module
# reads the plain data at the top of analysis/ and the rooms before its own
ROOMS = ("branches", "stability", "points", "switching", "critical", "surface")
TOP = {"results": set(), "timing": set(), "verdict": {"results"}, "picture": set(ROOMS) | {"results", "timing", "verdict"}}


def imported_rooms(path: Path) -> set:
    """The rooms and top-level modules of analysis/ a module of analysis/ imports."""
    module = ("balloon_cg",) + path.relative_to(PACKAGE).with_suffix("").parts
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            target = (list(module[: len(module) - node.level]) if node.level else []) + (
                node.module.split(".") if node.module else [])
            if target[:2] == ["balloon_cg", "analysis"]:
                found |= {target[2]} if len(target) > 2 else {alias.name for alias in node.names}
    return found


@pytest.mark.parametrize("room", ROOMS + tuple(TOP))
def test_analysis_rooms_import_only_earlier_rooms(room):
    paths = sorted((PACKAGE / "analysis" / room).rglob("*.py")) if room in ROOMS else [
        PACKAGE / "analysis" / f"{room}.py"]
    allowed = TOP[room] if room in TOP else set(ROOMS[: ROOMS.index(room) + 1]) | {"results", "timing"}
    for path in paths:
        wrong = imported_rooms(path) - allowed - {room}
        assert not wrong, f"{path.relative_to(PACKAGE)} imports {sorted(wrong)} (allowed: {sorted(allowed)})"


def test_every_analysis_module_is_in_a_room():
    found = {p.relative_to(PACKAGE / "analysis").parts[0].removesuffix(".py")
             for p in (PACKAGE / "analysis").iterdir() if p.name not in ("__init__.py", "__pycache__")}
    assert found == set(ROOMS) | set(TOP), found ^ (set(ROOMS) | set(TOP))


def test_every_module_is_in_a_layer():
    loose = [p.name for p in PACKAGE.glob("*.py") if p.name not in ("__init__.py", "__main__.py")]
    assert loose == [], f"modules outside the layer subpackages: {loose}"
    assert {p.name for p in PACKAGE.iterdir() if p.is_dir() and p.name != "__pycache__"} <= set(LAYERS) | {"scenes"}


def test_runtime_never_imports_sympy_or_codegen():
    for path in PACKAGE.rglob("*.py"):
        assert not third_party(path) & {"sympy", "codegen"}, path
        if path.relative_to(PACKAGE).as_posix() not in GENERATOR_USERS and path.relative_to(PACKAGE).parts[0] in LAYERS:
            assert "codegen" not in imported_layers(path), path
