"""A sector's readings at the degree they need (issue 37): the state stays on the basis it was traced on (its
quadrature), the perturbations are read on nested sub-bases of the sector (``stability.sub_basis``), rung k
keeping degree L − 4k and order M − k of the sector's (L, M). Rayleigh–Ritz: each value read on a rung is an upper
bound of the sector's, and they decrease to it as the rung refines (spectrally: ~20–50× per two rungs on the
two-coil m = 1 branch, benchmarks/results/surface_subbasis.txt). A rung's values are taken when the next coarser
rung (k + PAIR) agrees with them within AGREE · max(1, |μ|) for every value of every reading (issue 37's "unchanged":
the finer rung is then within ~AGREE/20 of the sector's); else the ladder climbs by PAIR rungs, up to the sector
itself (k = 0), read as before and taken without a comparison. Sectors below ``eigen.FOLLOWING_SIZE`` unknowns and
reads without guesses (a branch's first point) are read on the sector."""
import numpy as np

from . import stability
from ..numerics import eigen

DEGREES_PER_RUNG, ORDERS_PER_RUNG = 4, 1
PAIR = 2  # the rungs compared: k and k + PAIR
AGREE = 1e-9  # relative to max(1, |μ|): issue 37's "unchanged"
MARGIN = 1e-2  # a pair agreeing within MARGIN · AGREE starts the next point's ladder PAIR rungs coarser
FIRST = 4  # the rung a sector's ladder starts from at its first point with guesses


def rung(sector, k: int):
    """The sub-basis of rung k of ``sector`` (the sector itself at k = 0), or None where it has no order or degree
    left."""
    if k == 0:
        return sector
    degree, order = sector.degree - DEGREES_PER_RUNG * k, sector.order - ORDERS_PER_RUNG * k
    return stability.sub_basis(sector, degree, order) if 1 <= order <= degree else None


def agree(coarse: dict, fine: dict) -> float:
    """max over the readings' values of |μ_coarse − μ_fine| / max(1, |μ_fine|) (inf where their counts differ)."""
    worst = 0.0
    for r, values in fine.items():
        if len(coarse[r]) != len(values):
            return np.inf
        worst = max(worst, float(np.max(np.abs(coarse[r] - values) / np.maximum(1.0, np.abs(values)), initial=0.0)))
    return worst


def sector_spectra(eq, c, params, count: int, readings, guesses: dict | None, only: tuple, start: dict) -> dict:
    """``stability.sector_spectra`` of the sectors ``only``, each on the rung it needs (module docstring); ``start``:
    {characters: the rung its ladder starts from} (the previous point's; updated in place for the next)."""
    out = {r: {} for r in readings}
    for sector in eq.basis.sectors():
        key = sector.characters
        if not sector.size or key not in only:
            continue
        following = guesses is not None and all(key in guesses.get(r, {}) for r in readings)
        k = start.get(key, FIRST) if following and sector.size >= eigen.FOLLOWING_SIZE else 0
        while k > 0 and rung(sector, k) is None:
            k -= 1
        values = _read(eq, c, params, count, readings, guesses, sector, k)
        coarse = _read(eq, c, params, count, readings, guesses, sector, k + PAIR) if k else None
        while k > 0 and (coarse is None or agree(coarse, values) > AGREE):
            coarse, k = values, max(k - PAIR, 0)
            values = _read(eq, c, params, count, readings, guesses, sector, k)
        if k:
            start[key] = k + PAIR if agree(coarse, values) <= MARGIN * AGREE else k
        elif following:
            start[key] = 0
        for r in readings:
            out[r][key] = values[r]
    return out


def _read(eq, c, params, count, readings, guesses, sector, k: int) -> dict | None:
    """{reading: values} of ``sector`` read on rung k (None where the rung does not exist)."""
    basis = rung(sector, k)
    if basis is None:
        return None
    key = sector.characters
    spectra = stability.sector_spectra(eq, c, params, count, readings, guesses, (key,),
                                       None if k == 0 else {key: basis})
    return {r: spectra[r][key] for r in readings}
