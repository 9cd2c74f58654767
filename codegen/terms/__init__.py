"""Energy terms as data: each term of the functional is one small module saying what it adds.

A scene class (``functional.SceneClass``) is its elastic term (``elastic``: the strain energy Φ(λ1, λ2) of the
material, one per class) and a tuple of further terms:

- ``pressure``    −P V, the pressure's work (every class);
- ``magnetic``    −½ χ M H², a soft magnetic membrane in the field of the coils;
- ``dielectric``  −Φ̄² λ1² λ2², an ideal dielectric elastomer under a voltage.

Every stage (equations, poles, second_variation, surface, build) loops over the class's terms and reads the
interface of ``Term``; none of them knows a term by name. Adding a term (a hard-magnetic one, a new loading) is
a new module here and a row of the scene table (``codegen/classes.py``).
"""
import sympy as sp


class Term:
    """What one energy term contributes; the defaults contribute nothing.

    ``name``: how the runtime and the registry (generated/__init__.py) name it: a class is the set of its terms'
    names (model/kernels.py: ``scene_terms``).
    ``parameters``: its runtime scalars (kernel 'param' arguments, in this order after the class's earlier terms').
    ``continuation``: (symbol, word, shown) of the parameter the runtime continues in, or None: the term adds the
    kernels WORD_gradient (∂²π̂/∂SHOWN∂state), rhs_WORD (∂f/∂SHOWN) and surface_WORD_gradient.
    Subclasses are frozen dataclasses (hashable: the stages cache per class).
    """

    name = ""
    parameters: tuple = ()
    continuation: tuple | None = None

    def membrane(self, l1, l2):
        """Its part of Φ(λ1, λ2), the energy per reference area as a function of the principal stretches alone."""
        return sp.S.Zero

    def axisymmetric(self, c, s, metric):
        """Its part of π̂ = Π/sin θ (MODEL.md §2) beyond Φ, in the node's (cos θ, sin θ) = (c, s) and the state;
        ``metric`` is the reference meridian's S' = dS/dθ there (codegen/meridian.py), the factor of a density per
        reference area."""
        return sp.S.Zero

    def surface(self, point, a_t, a_p, areal):
        """Its part of π per reference area on the whole sphere (MODEL.md §8) at the deformed point x with
        a_θ, a_φ and J = |a_θ × a_φ|."""
        return sp.S.Zero

    def second_order(self, x, x_t, x_p, metric, closed=True):
        """Its part of the φ-averaged ε² coefficient of the energy per d(cos θ) along the perturbed surface
        (x, x_θ, x_φ) of codegen/second_variation.py (``metric``: as for ``axisymmetric``; ``closed``: the
        meridian has poles, else it is a tube's between its end planes)."""
        return sp.S.Zero

    def pole(self, lam, z, q, s, z0, metric):
        """Its part of the Lagrangian L = Π of the pole series (codegen/poles.py) in λ2 = lam, η = z, η' = q near
        the pole (s = sin θ, z0 = η at the pole, ``metric`` as for ``axisymmetric``), the stretches' part excluded
        (Φ enters there abstractly)."""
        return sp.S.Zero

    def pole_values(self, letter: str) -> dict:
        """Substitutions into the pole series at the pole 'N' or 'S' (its node values there)."""
        return {}

    def expansion(self, radius) -> dict:
        """Substitutions that put a Taylor proxy's expansion point back after differentiation (axisymmetric), with
        ``radius`` the reference meridian's R at the node (ρ = λ2 R there)."""
        return {}

    def surface_expansion(self, point) -> dict:
        """The same for the surface kernels, at the deformed point x."""
        return {}

    def rows(self) -> tuple:
        """Node-matrix arguments (``kernels.Arg``) of the axisymmetric pointwise kernels, after the material's."""
        return ()

    def pole_rows(self) -> tuple:
        """Its arguments of the pole_series kernel, after the material's."""
        return ()

    def surface_rows(self) -> tuple:
        """Its arguments of the surface kernels, after the material's."""
        return ()

    def off(self) -> dict:
        """The substitution that removes the term from an expression derived with it: its parameters at 0."""
        return {p: 0 for p in self.parameters}

    def inputs(self) -> dict:
        """Its entries in a module's header (``INPUTS``)."""
        return {}

    def title(self, surface: bool) -> str | None:
        """Its phrase in a module's title line (None: none)."""
        return None
