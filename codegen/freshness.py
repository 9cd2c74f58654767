"""Whether a folder of generated modules is what the generator prints, read from the modules' headers: no SymPy
derivation, a second of CPU where `make regenerate` takes a minute (the default test suite's staleness check).

A folder is fresh when it holds exactly the modules the scene table names (``build.module_names``), its registry
is ``build.registry_text()``, and every module is ``emit.assembled`` of its own parts with today's generator
digest: its GENERATOR_SOURCES equals ``codegen.sources_digest`` of the generator sources (an edit to codegen/ or
to the runtime modules it reads shows there), and its SIGNATURE, title, inputs and body are consistent (a hand
edit anywhere shows). What this cannot see is a change in the output of SymPy or mpmath themselves (another
version): the byte-for-byte regeneration, a `-m slow` test that CI also runs, checks that.
"""
from pathlib import Path

from . import generator_digest, sources_digest
from .build import module_names, registry_text
from .emit import assembled, parts


def stale(folder: Path, sources: dict | None = None) -> list[str]:
    """One line per stale or missing module of ``folder`` (generated/), none when it is fresh. ``sources``:
    {name: path} of the generator sources (codegen.generator_sources; default: this generator's own)."""
    digest = generator_digest() if sources is None else sources_digest(sources)
    expected = set(module_names())
    present = {path.stem for path in folder.glob("*.py")} - {"__init__"}
    lines = [f"{name}.py: missing" for name in sorted(expected - present)]
    lines += [f"{name}.py: not a module the generator writes" for name in sorted(present - expected)]
    registry = folder / "__init__.py"
    if not registry.is_file() or registry.read_text(encoding="utf-8") != registry_text():
        lines.append("__init__.py: not the registry of today's scene table")
    for name in sorted(expected & present):
        text = (folder / f"{name}.py").read_text(encoding="utf-8")
        found = parts(text)
        if found is None:
            lines.append(f"{name}.py: no generated header")
        elif f'\nGENERATOR_SOURCES = "{digest}"\n' not in text:
            lines.append(f"{name}.py: printed by other generator sources (codegen/ or scene/formula.py, "
                         "scene/energies.py changed since)")
        elif assembled(*found) != text:
            lines.append(f"{name}.py: edited after it was generated (its header does not match its body)")
    return lines
