"""The perturbation degree follows the mode (analysis/stability/crossings.py): every sign change a branch-point search reads
is confirmed at raised degrees before it is located.

On model spectra μ(n, N) = c(n) + a(n)·(20/N)³ (converged value c, an under-resolution error that decays
with the degree N): a spurious crossing disappears and the raised points carry the converged sign; a real
crossing is kept in its interval, at the degree it was found when it is resolved there, moved to its true
interval when the coarse degree displaced it; one that cannot be resolved below the maximum degree is kept (and
then reported). On a traced branch (TPOM1 between two coils, M = 0.003, stability degree 20):
tests/test_azimuthal_points.py::test_under_resolved_m1_crossings_are_refined_away.
"""
from dataclasses import dataclass

import numpy as np

from balloon_cg.analysis.stability.crossings import branch_point_crossings, follow_modes, resolved, sign_changes
from balloon_cg.analysis.results import Block

BLOCK = Block.M1_HELD


@dataclass
class Model:
    """A branch of ``points`` points whose one block has one eigenvalue c(n) + a(n)·(20/N)³ (and a second,
    positive, one); check degree 2N up to ``max_degree``, N/1.5 at it."""

    converged: np.ndarray
    error: np.ndarray
    max_degree: int = 320

    def assess(self, n, N):
        mu = self.converged[n] + self.error[n] * (20.0 / N) ** 3
        return Assessment({BLOCK: np.array(sorted([mu, 1.0]))}, N)

    def check_degree(self, N):
        return min(2 * N, self.max_degree) if N < self.max_degree else int(N / 1.5)

    def follow(self, degree=20):
        start = [self.assess(n, degree) for n in range(len(self.converged))]
        return follow_modes(start, [degree] * len(start), self.assess, self.check_degree,
                            lambda found: branch_point_crossings(found, 1))


@dataclass
class Assessment:
    blocks: dict
    degree: int


def lowest(followed):
    return np.array([a.blocks[BLOCK][0] for a in followed.assessments])


def test_resolved_is_sign_and_half_the_size():
    assert resolved(-0.0109, -0.0108) and resolved(2.0, 1.01)
    assert not resolved(0.004041, -0.006724)  # TPOM1, one coil, λ2(0) 5.33: N = 40 against 80
    assert not resolved(-0.00282, -0.00711)  # the same sign, but moved by more than half of itself


def test_spurious_crossing_disappears_and_the_raised_points_are_converged():
    """Converged value −0.01 everywhere; from point 5 on the coarse value is positive: the refinement walks to the
    end of the branch, and every point it raised holds the converged sign, within its check to the limit."""
    n = np.arange(12)
    model = Model(np.full(12, -0.01), np.where(n >= 5, 0.02, 0.0))
    assert sign_changes([model.assess(i, 20) for i in n], BLOCK) == [(4, 0)]
    followed = model.follow()
    assert branch_point_crossings(followed.assessments, 1) == []
    assert followed.degrees == [20] * 5 + [40] * 7
    values = lowest(followed)
    assert np.all(values < 0)
    assert np.all(np.abs(values - (-0.01)) <= 0.5 * np.abs(values))


def test_resolved_real_crossing_is_kept_at_its_degree():
    n = np.arange(10)
    model = Model(0.01 * (n - 4.5), np.full(10, 1e-4))
    followed = model.follow()
    assert branch_point_crossings(followed.assessments, 1) == [(4, BLOCK, 0)]
    assert followed.degrees == [20] * 10  # nothing raised: one check per bracketing point
    assert set(followed.checked) == {4, 5}


def test_displaced_real_crossing_moves_to_its_interval():
    """The coarse error shifts the crossing from (4, 5) to (1, 2); the refinement follows it back."""
    n = np.arange(10)
    model = Model(0.01 * (n - 4.5), np.full(10, 0.03))
    assert sign_changes([model.assess(i, 20) for i in n], BLOCK) == [(1, 0)]
    followed = model.follow()
    assert branch_point_crossings(followed.assessments, 1) == [(4, BLOCK, 0)]
    assert all(resolved(followed.assessments[p].blocks[BLOCK][0], followed.checked[p].blocks[BLOCK][0])
               for p in (4, 5))


def test_unresolvable_crossing_is_kept_for_the_report():
    """With max_degree 40 the spurious crossing cannot be resolved (it needs 80): it stays, at the maximum degree,
    for ``convergence_problems`` to report (the branch point is then approximate)."""
    n = np.arange(8)
    model = Model(np.full(8, -0.01), np.where(n >= 4, 0.3, 0.0), max_degree=40)
    followed = model.follow()
    ((index, _, _),) = branch_point_crossings(followed.assessments, 1)
    assert followed.degrees[index + 1] == 40
    point = followed.assessments[index + 1]
    assert not resolved(point.blocks[BLOCK][0], model.assess(index + 1, 80).blocks[BLOCK][0])
