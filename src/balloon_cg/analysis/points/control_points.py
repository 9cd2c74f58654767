"""Stability changes under every control mode on a branch without equator symmetry: LP, LV, LN or BP.

On an assessed branch of the general layout (a field that breaks the equator symmetry, the balloon held; or
continuation.symmetry = "none"), the axisymmetric (m = 0) second variation is one block per control mode
(``stability``): all_held (pressure control, H), all_volume_held (volume control, H on gᵀδ = 0) and all_gas_held
(gas control, H + (P/Ṽ) g gᵀ); all_free, ... on a branch of the free reading (b_0 an unknown). Each sign
change of an eigenvalue μ_k of one of them between points i and i + 1 is a special point:

    located as the zero of μ_k(s) on the chord corrector R(X(s)) = 0, d·X(s) = d·X_i + s (Brent's method, as
    ``azimuthal_points`` for m ≥ 1), at the larger perturbation degree of the two bracketing points;
    a fold of the control's parameter q (P, V or n = P V: ``control``) where q is stationary along the branch,
    |∇q·τ| ≤ FOLD_TOL |∇q| (τ the unit tangent at the located point): LP, LV or LN;
    else a branch point of the axisymmetric problem (BP, m = 0, the block's name).

A crossing in the interval of a fold of that kind the tracer located already (LP; LV or LN under the scene's own
control mode) is that fold. LOCATED when Brent converged and μ_k is converged at the bracketing points between
that degree and its check degree (``stability.convergence_problems``), else APPROXIMATE with the reason. Only the
branch's own reading is searched: a held branch's states carry a net axial force (the reaction), so they are not
equilibria of the free balloon and its free blocks' crossings are no special points of it (``results.Gauge``).
"""
import numpy as np

from ...numerics import continuation
from ...numerics.newton import newton
from ...scene import Control
from ..branches.control import FOLD_KIND, control_gradient
from ..stability.crossings import sign_changes
from ..branches.problem import branch_system
from ..results import Block, Branch, Gauge, Kind, SpecialPoint, approximate, located_or_bracketed
from ..stability.axisymmetric import Variations, assessed_degrees, convergence_problems

BLOCKS = {Gauge.FREE: {Control.PRESSURE: Block.ALL_FREE, Control.VOLUME: Block.ALL_VOLUME_FREE,
                       Control.GAS: Block.ALL_GAS_FREE},
          Gauge.HELD: {Control.PRESSURE: Block.ALL_HELD, Control.VOLUME: Block.ALL_VOLUME_HELD,
                       Control.GAS: Block.ALL_GAS_HELD}}  # by the branch's reading (both: no field, held blocks)
FOLD_TOL = 1e-6  # |∇q·τ| / |∇q| below this at the located point: a fold of q


def crossings(branch: Branch) -> list[tuple[int, Control, int]]:
    """(index, control, k) of every sign change of μ_k of a control mode's block (BLOCKS) that is not at a fold of
    its kind the tracer located (module docstring), ordered by index."""
    located = {(s.kind, s.index) for s in branch.special}
    return sorted((n, control, k) for control, block in blocks_of(branch).items()
                  for n, k in sign_changes(branch.stability, block.value)
                  if (FOLD_KIND[control], n) not in located)


def blocks_of(branch: Branch) -> dict:
    """The m = 0 block of each control mode in the reading of ``branch`` (BLOCKS)."""
    return BLOCKS[Gauge.FREE if branch.gauge == Gauge.FREE else Gauge.HELD]


def find(branch: Branch) -> list[SpecialPoint]:
    """The special points of the stability changes of ``branch`` under every control mode (module docstring)."""
    degrees = assessed_degrees(branch)
    return [locate(branch, index, control, k, max(degrees[index], degrees[index + 1]))
            for index, control, k in crossings(branch)]


def eigenvalue(variations: Variations, system, X, block: Block, k: int, degree: int) -> float:
    """μ_k of the m = 0 ``block`` at the point X of the branch's system, perturbation degree ``degree``."""
    return float(variations[degree].lowest(X[:-1], system.params_at(X), False, block.value)[k])


def fold_rate(system, X, direction, control: Control) -> float:
    """|∇q·τ| / |∇q| at X (τ the unit tangent oriented along ``direction``): 0 at a fold of q."""
    tangent = continuation.tangent(system, X, direction)
    gradient = np.eye(X.size)[-1] if control == Control.PRESSURE else control_gradient(system, X, control)
    return float(abs(gradient @ tangent) / np.linalg.norm(gradient))


def locate(branch: Branch, index: int, control: Control, k: int, degree: int) -> SpecialPoint:
    """The zero of μ_k of ``control``'s block between points index and index + 1 (module docstring)."""
    system, solver, block = branch_system(branch), branch.scene.solver, blocks_of(branch)[control]
    variations = Variations(system.eq)
    X0, X1 = branch.X[index], branch.X[index + 1]
    d = (X1 - X0) / np.linalg.norm(X1 - X0)

    def value_at(s):
        result = newton(system.residual, system.jacobian, X0 + s * d, d, d @ X0 + s, solver.tol, solver.max_newton)
        if not result.converged:
            raise ArithmeticError(result.message)
        return eigenvalue(variations, system, result.x, block, k, degree), result.x

    what = f"stability change under {control.value} control ({block.value} block)"
    found = continuation.locate_root(value_at, float(np.linalg.norm(X1 - X0)))
    if found is None:
        fields = approximate(branch.disc, X0, X1, f"{what}: the corrector failed at every evaluation inside its "
                                                  "bracket; its start is stored")
        return SpecialPoint(Kind.BP, index, X0, block=block, note=what, **fields)
    fields = located_or_bracketed(found.status, branch.disc, X0, X1, what)

    def stored_or_computed(n, N):
        a = branch.stability[n]
        return float(a.blocks[block.value][k]) if a.degree == N else eigenvalue(variations, system, branch.X[n],
                                                                                 block, k, N)

    problems = convergence_problems(branch, index, stored_or_computed, (degree, degree))
    if problems and not fields.get("reason"):
        fields = approximate(branch.disc, X0, X1, f"{what}: " + "; ".join(problems))
    fold = fold_rate(system, found.payload, d, control) <= FOLD_TOL
    kind = FOLD_KIND[control] if fold else Kind.BP
    return SpecialPoint(kind, index, found.payload, block=Block.NONE if fold else block, note=what, **fields)
