"""Symbolic layer of balloon-cg: the energy functional -> equations -> kernel IR -> numba modules.

Stages (each a pure function, testable on its own):

0. ``terms``        the energy terms as data (elastic, pressure, magnetic, dielectric), one module each;
   ``classes`` the scene table (which terms each committed class has).
1. ``functional``   Π(θ, λ2, v, η, w; P, M) of MODEL.md §2 for one scene class: the sum of its terms.
2. ``equations``    energy gradient/Hessian, the first-order Euler–Lagrange system y' = f and its Jacobians.
3. ``poles``        the θ → 0, π limits (truncated Taylor series of the Euler–Lagrange equations).
4. ``field``        per-coil Biot–Savart field and derivatives from the Stokes stream function.
5. ``kernels``      kernel IR: ordered, CSE'd assignments.
6. ``printer`` / ``emit``  numba source text with a content-keyed header.
7. ``freshness``    whether generated/ is what the generator sources print, without deriving (the default test).

This package imports SymPy and never numba; the runtime (``balloon_cg``) never imports SymPy.
"""

import functools
import hashlib
from pathlib import Path

GENERATOR_VERSION = "2"  # part of every module's signature and of the on-demand cache key (no SymPy needed here)


def generator_sources() -> dict:
    """{name: path} of every file the generator's output is a function of: codegen/**/*.py and the runtime modules
    it reads (scene/formula.py: the formula parser it walks; scene/energies.py: the strain-energy families). The
    versions of SymPy and mpmath are not among them: the byte-for-byte regeneration checks those (make regenerate)."""
    from balloon_cg.scene import energies, formula

    here = Path(__file__).resolve().parent
    sources = {f"codegen/{path.relative_to(here).as_posix()}": path for path in here.rglob("*.py")}
    return sources | {f"balloon_cg/scene/{Path(m.__file__).name}": Path(m.__file__) for m in (formula, energies)}


def sources_digest(sources: dict) -> str:
    """SHA-256 over the names and bytes of ``sources`` ({name: path}), in the order of their names."""
    digest = hashlib.sha256()
    for name in sorted(sources):
        data = sources[name].read_bytes()
        digest.update(f"{name}\0{len(data)}\0".encode() + data)
    return digest.hexdigest()


@functools.cache
def generator_digest() -> str:
    """``sources_digest`` of ``generator_sources()``: printed in every generated module's header
    (GENERATOR_SOURCES) and part of the on-demand cache key, so that an edit to the generator shows even where
    GENERATOR_VERSION was not raised."""
    return sources_digest(generator_sources())
