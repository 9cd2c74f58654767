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

This package imports SymPy and never numba; the runtime (``balloon_cg``) never imports SymPy.
"""

GENERATOR_VERSION = "2"  # part of every module's signature and of the on-demand cache key (no SymPy needed here)
