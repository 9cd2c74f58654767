"""Branch switching at the pitchforks of a primary branch traced on the whole sphere (analysis/surface_pitchforks.py):
the reflection of a field on the coefficients, the reflections a broken mode keeps, and the two-coil scene turned by
30° (an exact rotation of the axisymmetric problem): its pitchfork odd under the inversion is the axisymmetric pear
point, and the branch born there is the pear branch turned."""
import math

import numpy as np
import pytest

from balloon_cg.analysis import verdict
from balloon_cg.analysis.results import Kind, Origin, Status
from balloon_cg.analysis.surface_pitchforks import kept_reflections
from balloon_cg.surface.basis import EQUATOR, HALF_TURN, INVERSION, MIRROR_Y, SphericalBasis

MIRROR_X = (-1, 1, 1)


@pytest.mark.parametrize("S", [MIRROR_Y, MIRROR_X, EQUATOR, HALF_TURN, INVERSION])
def test_the_reflection_signs_map_a_field_to_its_image(S):
    """v(X) = S u(S X) evaluated pointwise at random points equals the field of the sign-flipped coefficients
    (``reflection_signs``) to rounding: the sign rule per (component, l, m, type) against geometry."""
    basis = SphericalBasis(7)
    rng = np.random.default_rng(5)
    c = rng.normal(size=basis.size)
    theta, phi = rng.uniform(0.05, 3.1, 40), rng.uniform(0.0, 2 * np.pi, 40)
    X = np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
    SX = np.array(S, dtype=float)[:, None] * X
    u_at_SX = basis.point_values(c, np.arccos(SX[2]), np.arctan2(SX[1], SX[0]))[0] - SX
    image = basis.point_values(c * basis.reflection_signs(S), theta, phi)[0] - X
    assert np.abs(image - np.array(S, dtype=float)[:, None] * u_at_SX).max() < 1e-12 * np.abs(u_at_SX).max()


def test_a_broken_mode_keeps_the_reflections_it_is_even_under():
    assert kept_reflections((MIRROR_Y, INVERSION), (1, -1)) == (MIRROR_Y,)
    assert kept_reflections((MIRROR_Y, INVERSION), (-1, 1)) == (INVERSION,)
    assert kept_reflections((MIRROR_Y, INVERSION), (-1, -1)) == ((-1, 1, -1),)  # y → −y and the inversion: x → −x, z → −z
    assert kept_reflections((MIRROR_Y,), (-1,)) == ()


def test_a_branch_point_in_the_own_sector_is_a_typed_limitation():
    """A branch point that is not a pitchfork is Gap.NOT_SWITCHED: listed, named, not a failure."""
    found = verdict.incomplete([], not_switched=(("bp2", "crosses in the state's own symmetry sector"),))
    assert [(item.gap, item.branch) for item in found] == [(verdict.Gap.NOT_SWITCHED, "bp2")]
    assert not verdict.failing(found)
