"""Shared by the two-parameter tests (test_two_parameter, test_second_parameter): the located pear pitchforks of
a primary branch, and the error of the extended system's Jacobian against central differences of its residual."""
import numpy as np

from balloon_cg.analysis.points import branch_points as bifurcation
from balloon_cg.analysis.critical.pitchfork_curve import ExtendedSystem
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.stability.axisymmetric import SecondVariation, assess_branch


def pear_events(branch) -> list:
    """The pear (odd_held) pitchforks detected on a primary branch by its full stability assessment (to locate)."""
    assessments, _ = assess_branch(branch, branch.disc.degree, True)
    return [e for e in bifurcation.detect(branch, assessments) if e[1] == "odd_held"]


def isola(scene):
    """(scene, its primary branch traced upwards, its two located pear pitchforks): a scene with an isola."""
    branch = trace_primary(scene, down=False)
    events = pear_events(branch)
    assert len(events) == 2  # the isola's two pitchforks
    return scene, branch, [bifurcation.locate(branch, *e) for e in events]


def jacobian_error(branch, bp, parameter: str, q0: float | None = None, seed: int = 1) -> float:
    """max |J d − (F(X0 + h d) − F(X0 − h d)) / 2h| for the extended system F in ``parameter`` at the pitchfork
    ``bp`` (q0: the parameter's value on the branch by default), d random of size 1e-2, h = 1e-4."""
    eq = equilibrium_of(branch)
    odd = bifurcation.block_indices(SecondVariation(eq, branch.disc.degree), "odd_held", False)
    ell = bp.mode[odd] / np.linalg.norm(bp.mode[odd])
    system = ExtendedSystem(eq, branch.params.with_value("P", bp.X[-1]), parameter, ell)
    X0 = system.initial(bp, system.parameter.q0 if q0 is None else q0)
    direction = np.random.default_rng(seed).standard_normal(X0.size) * 1e-2
    h = 1e-4
    fd = (system.residual(X0 + h * direction) - system.residual(X0 - h * direction)) / (2 * h)
    return float(np.abs(fd - system.jacobian(X0) @ direction).max())
