"""Coordinate maps that cluster the Legendre basis where the membrane passes close to a coil wire.

The unknowns are expanded in P_k(s), s = h(x), x = cos θ, with

    H(x) = Σ_j asinh((x − c_j)/ε_j),    h(x) = −1 + 2 (H(x) − H(−1)) / (H(1) − H(−1)),

monotone and analytic on [−1, 1] with h(±1) = ±1 and h' > 0, so a function smooth in x near a pole is smooth in
s there (pole regularity is kept) and the pole values are those of the s-polynomials at s = ±1. Node density
dh/dx ∝ Σ_j 1/sqrt(ε_j² + (x − c_j)²) is concentrated within ε_j of each centre c_j (a symmetric set of
centres gives an odd h, which keeps the equator parity of λ2 and η). The forward map x = g(s) is not needed
in closed form: it is found at the Gauss nodes by bisection and Newton.

Measured (docs/numerics.md, "The membrane near a wire"): two coils, M = 0.002, λ = 1.8, gap 0.17: relative P
error 4.7e-10 at N = 64 with ε = 0.08 at x_w = ±0.50, against 1.7e-4 for Legendre in x at the same N.
"""
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class WireMap:
    """s = h(x) with centres c_j ∈ (−1, 1) and widths ε_j > 0 (module docstring); hashable."""

    centres: tuple
    widths: tuple

    def __post_init__(self):
        if len(self.centres) != len(self.widths) or not self.centres:
            raise ValueError(f"WireMap: {len(self.centres)} centres and {len(self.widths)} widths: need ≥ 1 each, "
                             "as many widths as centres")
        if not all(-1.0 < c < 1.0 for c in self.centres) or not all(e > 0.0 for e in self.widths):
            raise ValueError(f"WireMap: centres {self.centres} must lie in (−1, 1), widths {self.widths} be > 0")
        object.__setattr__(self, "_c", np.array(self.centres, dtype=float)[:, None])
        object.__setattr__(self, "_e", np.array(self.widths, dtype=float)[:, None])
        low, high = self._sum(np.array([-1.0, 1.0]))
        object.__setattr__(self, "_low", float(low))
        object.__setattr__(self, "_scale", 2.0 / float(high - low))

    def _sum(self, x):
        return np.arcsinh((np.asarray(x, dtype=float) - self._c) / self._e).sum(axis=0)

    def close_to(self, other: "WireMap | None", rtol: float = 0.05) -> bool:
        """Same centres and widths to within rtol of the widths (re-centring on such a map gains nothing)."""
        return (other is not None and len(other.centres) == len(self.centres)
                and all(abs(c - d) <= rtol * e and abs(e - f) <= rtol * e
                        for c, d, e, f in zip(self.centres, other.centres, self.widths, other.widths)))

    def mirrored(self) -> "WireMap":
        """The map of the reflection x → −x: centres −c_j (in reversed order, so that sorted centres stay sorted),
        the same widths. Its h̃ is exactly h̃(x) = −h(−x) (H̃(x) = −H(−x) in the module docstring's H), so
        P_k(h̃(x)) = (−1)^k P_k(h(−x)): a function of this map's basis, reflected, has the coefficients times (−1)^k
        on the mirrored map (``Discretisation.reflect``)."""
        return WireMap(tuple(-c for c in reversed(self.centres)), tuple(reversed(self.widths)))

    def s(self, x):
        """h(x), exactly ±1 at x = ±1 (the rounded sum can fall one ulp short there, and an m ≥ 1 field's pole
        factor √(1 − s²) would read ~1e-8 for 0)."""
        x = np.asarray(x, dtype=float)
        return np.where(np.abs(x) == 1.0, x, -1.0 + self._scale * (self._sum(x) - self._low))

    def ds_dx(self, x):
        """h'(x) > 0."""
        return self._scale * (1.0 / np.hypot(self._e, np.asarray(x, dtype=float) - self._c)).sum(axis=0)

    def d2s_dx2(self, x):
        """h''(x)."""
        d = np.asarray(x, dtype=float) - self._c
        return -self._scale * (d / np.hypot(self._e, d) ** 3).sum(axis=0)

    def x(self, s):
        """g(s) = h⁻¹(s): bisection to ~1e-12, then two Newton steps (h is monotone; g(±1) = ±1 exactly)."""
        s = np.asarray(s, dtype=float)
        low, high = -np.ones_like(s), np.ones_like(s)
        for _ in range(40):
            middle = 0.5 * (low + high)
            above = self.s(middle) < s
            low, high = np.where(above, middle, low), np.where(above, high, middle)
        x = 0.5 * (low + high)
        for _ in range(2):
            x = np.clip(x - (self.s(x) - s) / self.ds_dx(x), -1.0, 1.0)
        return np.where(np.abs(s) == 1.0, s, x)
