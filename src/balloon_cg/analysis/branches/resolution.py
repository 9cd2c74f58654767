"""The resolution policy: one object deciding when a discretisation holds a solution and how it grows.

A point is resolved on a discretisation when its spectral error estimate (``Discretisation.tail``: the
neglected geometric tail of the Legendre coefficients) is at most ``max_error``. Otherwise the degree grows by
``growth`` (up to ``max_degree``). With a wire map, a re-centred map at the same degree is preferred when it
leaves ``headroom`` · max_error (at most ``max_recentres`` times per degree); when the degree grows, a re-centred map
replaces the current one only where its estimate is lower by the factor ``map_gain`` (``clearly_lower``), so that
a choice between two maps both at the estimate's rounding floor is not made by the BLAS kernels' rounding. Points
moved to another basis (storage on the final basis, a branch point projected to the stability basis in x) may lose
at most ``storage_loss`` · max_error to the projection (``transfer_error``) before the target degree is raised.
The tracer, the storage-basis rule, bifurcation and two-parameter code all ask this object.
"""
from dataclasses import dataclass

import numpy as np

from ...galerkin.discretisation import Discretisation, geometric_fit, geometric_tail
from ...galerkin.elements import group_degrees
from ...numerics import interrupt


# the lowest degree an element group of a graded basis is cut to (``Resolution.element_degrees``)
MIN_ELEMENT_DEGREE = 8


@dataclass(frozen=True)
class Resolution:
    max_error: float
    max_degree: int
    growth: float = 1.5
    headroom: float = 0.25
    storage_loss: float = 0.5
    max_recentres: int = 6
    map_gain: float = 2.0

    @classmethod
    def of(cls, scene) -> "Resolution":
        """The policy of a scene's [solver] table (a capsule's too: its piecewise basis converges spectrally,
        galerkin/elements.py, so its tail estimate is read as the sphere's)."""
        return cls(scene.solver.max_error, scene.solver.max_degree)

    def resolved(self, disc: Discretisation, u) -> bool:
        return disc.tail(u) <= self.max_error

    def grow(self, degree: int) -> int:
        """The next degree: ``growth`` times larger, at most max_degree."""
        return min(int(degree * self.growth), self.max_degree)

    def element_degrees(self, disc: Discretisation, u) -> tuple:
        """A degree per element group of a capsule's basis (``elements.groups``), each from its own series: a
        group whose tail T (``Discretisation.element_tails``, decaying by r per degree) is above max_error grows by
        the degrees that tail wants, ln(headroom · max_error / T)/ln r, at least 2 and at most by ``growth``; a
        resolved group keeps its degree unless its series cut at a degree at most 1/growth of it still has a
        tail estimate (``geometric_tail`` of what is kept, the cut coefficients below it too) of at most
        headroom² · max_error, when it is cut to the lowest such degree, not below MIN_ELEMENT_DEGREE (a bulge's
        front leaves the elements it passed uniform); none beyond max_degree. Unchanged degrees: every group
        resolved (and none worth cutting) or at max_degree."""
        out = []
        for degree, envelope in zip(group_degrees(disc.degree, disc.joins, disc.element_degrees),
                                    disc.element_envelopes(u)):
            tail, rate = geometric_fit(envelope)
            if tail <= self.max_error:
                out.append(self._cut(degree, envelope))
                continue
            wanted = np.log(self.headroom * self.max_error / tail) / np.log(rate)
            step = int(np.clip(np.ceil(wanted), 2, max(2, int(degree * (self.growth - 1)))))
            out.append(min(degree + step, self.max_degree))
        return tuple(out)

    def _cut(self, degree: int, envelope: np.ndarray) -> int:
        """The lowest degree ≥ MIN_ELEMENT_DEGREE and ≤ degree/growth at which the series ``envelope`` (one entry per
        degree up to ``degree``) cut there keeps a tail estimate, and drops coefficients, of at most headroom² ·
        max_error; else ``degree`` (``element_degrees``)."""
        limit = self.headroom**2 * self.max_error
        for cut in range(MIN_ELEMENT_DEGREE, int(degree / self.growth) + 1):
            kept = envelope.size - (degree - cut)
            if kept >= 1 and geometric_tail(envelope[:kept]) <= limit and envelope[kept:].max() <= limit:
                return cut
        return degree

    def clearly_lower(self, tail: float, current: float) -> bool:
        """Whether a basis map's tail estimate ``tail`` is clearly below the ``current`` map's: by the factor
        ``map_gain``. Measured (benchmarks/results/refine_choice.txt, three OpenBLAS kernel sets): where both maps
        sit at the estimate's rounding floor the kernels' rounding moves their ratio between 0.6 and 1.6 (it comes
        from upstream too: the maps' widths and the leg's points differ in their last digits, so no floor estimated
        from the solve at hand captures it); the one choice decided by content (x against a map, at 90 -> 135)
        reads 2.4 to 2.6 under every kernel. T itself reads the error only to a factor ~1.5 (tests/test_tail.py)."""
        return tail * self.map_gain < current

    @property
    def recentre_accept(self) -> float:
        """Largest error estimate for which a re-centred map at the same degree is kept."""
        return self.headroom * self.max_error

    @property
    def loss_limit(self) -> float:
        """Largest projection loss of a point moved to a storage basis."""
        return self.storage_loss * self.max_error

    def plain_degree(self, disc: Discretisation, X, start: int | None = None) -> int:
        """The Legendre degree in x that holds the point X = (u, P) of a branch on ``disc`` (``plain_degrees``)."""
        return int(self.plain_degrees(disc, X, start)[0])

    def plain_degrees(self, disc: Discretisation, X, start: int | None = None) -> np.ndarray:
        """Per row X = (u, P): the Legendre degree in x that holds it. Its own degree if the basis is not mapped;
        else grown from ``start`` (default: the mapped degree) until the projection loses at most max_error and
        the projected tail is within max_error (the mapped degree is far below what x needs near a wire), at
        most max_degree. A signal (``numerics.interrupt``) raises ``Interrupted`` at the next degree (near a wire
        the search costs seconds: a projection's pseudo-inverse per degree up to 320)."""
        X = np.atleast_2d(X)
        degree = disc.degree if start is None else start
        degrees = np.full(len(X), disc.degree if disc.mapping is None else degree)
        open_rows = np.arange(len(X)) if disc.mapping is not None else np.arange(0)
        while open_rows.size and degree < self.max_degree:
            interrupt.check()
            plain = Discretisation(degree, disc.symmetric, disc.pin_translation, joins=disc.joins,
                                   held=disc.held)
            moved = disc.transfer(X[open_rows], plain)
            loss = transfer_error(disc, X[open_rows], plain, moved)
            tails = np.array([plain.tail(row[: plain.size]) for row in moved])
            open_rows = open_rows[np.maximum(loss, tails) > self.max_error]
            degree = self.grow(degree)
            degrees[open_rows] = degree
        return degrees


def transfer_error(source: Discretisation, X, target: Discretisation, moved, n_theta: int = 721) -> np.ndarray:
    """Per row: max |Δλ2|, |Δη| / |a_0| on a θ grid between X in ``source`` and ``moved`` = its transfer to
    ``target`` (zero when the transfer is exact: same map, no lower degree)."""
    X, moved = np.atleast_2d(X), np.atleast_2d(moved)
    if source.nests_in(target):
        return np.zeros(len(X))
    theta = np.linspace(0.0, np.pi, n_theta)
    before = source.evaluate(X[:, : source.size], theta)
    after = target.evaluate(moved[:, : target.size], theta)
    difference = np.maximum(np.abs(before[0] - after[0]).max(axis=1), np.abs(before[2] - after[2]).max(axis=1))
    return difference / np.abs(before[0][:, 0])
