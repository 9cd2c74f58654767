"""post/tube_measures.py: the stretches along a tube against the uniform tube and central differences of the
profile, and the front of a profile against the closed form of a tanh front."""
import numpy as np
import pytest

from balloon_cg.galerkin.interval import IntervalDiscretisation
from balloon_cg.post.tube_measures import front, stretches
from balloon_cg.scene.tables import Ends


def test_uniform_tube_has_its_two_stretches_everywhere():
    disc = IntervalDiscretisation(12, 10.0)
    s = np.linspace(0.0, 10.0, 31)
    axial, hoop = stretches(disc, disc.uniform(1.7, 1.3), s)
    assert np.abs(axial - 1.3).max() <= 1e-14 and np.abs(hoop - 1.7).max() <= 1e-14


@pytest.mark.parametrize("ends", [Ends.SLIDING, Ends.PLUGGED])
def test_stretches_are_the_profiles_rates(ends):
    """At a random state: λ2 = ρ and λ1 = sqrt(ρ'² + η'²), the rates by central differences of ``profile`` (h = 1e-5:
    to 1e-8 of the rates)."""
    disc = IntervalDiscretisation(10, 7.0, ends=ends)
    rng = np.random.default_rng(4)
    u = disc.reference() * 1.2 + 0.05 * rng.standard_normal(disc.size) / (1 + np.arange(disc.size) % 11)
    s, h = np.linspace(0.1, 6.9, 25), 1e-5
    axial, hoop = stretches(disc, u, s)
    rho, _ = disc.profile(u, s)
    (rho_up, eta_up), (rho_down, eta_down) = disc.profile(u, s + h), disc.profile(u, s - h)
    rate = np.hypot(rho_up - rho_down, eta_up - eta_down) / (2 * h)
    assert np.abs(hoop - rho).max() <= 1e-14 * np.abs(rho).max()
    assert np.abs(axial - rate).max() <= 1e-8 * rate.max()


@pytest.mark.parametrize("descending", [False, True])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_front_of_a_tanh_profile(descending, sign):
    """ρ = 4 − 2.5 sign tanh((z − 7.3)/0.8) on [0, 20]: position where ρ = m, the mid level of ρ(0) and ρ(20)
    (7.3 + 0.8 artanh((4 − m)/(2.5 sign)), 1.3e-8 from 7.3: the ends are not quite saturated), to 1e-9; width 1.6,
    its error falling as h² (central differences: h²/(3δ²) relative, 1.3e-5 at 4001 samples; a quarter at twice)."""
    profile = lambda z: 4.0 - 2.5 * sign * np.tanh((z - 7.3) / 0.8)
    middle = 0.5 * (profile(0.0) + profile(20.0))
    crossing = 7.3 + 0.8 * np.arctanh((4.0 - middle) / (2.5 * sign))
    errors = []
    for samples in (4001, 8001):
        z = np.linspace(0.0, 20.0, samples)[:: -1 if descending else 1]
        found = front(z, profile(z))
        assert abs(found.position - crossing) <= 1e-9
        assert abs(found.low - 1.5) <= 1e-7 and abs(found.high - 6.5) <= 1e-7
        errors.append(abs(found.width - 1.6) / 1.6)
    assert errors[0] <= 2e-5 and 3.5 < errors[0] / errors[1] < 4.5


def test_a_uniform_profile_has_no_front():
    found = front(np.linspace(0.0, 5.0, 11), np.full(11, 1.6))
    assert np.isnan(found.position) and np.isnan(found.width) and found.low == found.high == 1.6


def test_a_profile_without_a_single_narrow_front_has_none():
    """No front (position and width NaN) where there is none to single out: the onset's mode ρ = 1.6 + 0.05 cos(πz/ℓ)
    over the whole tube (one mid-level crossing, at the middle, but a width 2ℓ/π: it drew a spike near the onset),
    a bump in the middle (two crossings nearer than twice its width: a coil's bulge), and a tanh front of width 1.6 too near an end (z_f < 1.5 w:
    the part beyond it shorter than the front is wide); the same front at 1.5 w + 0.1 from the end has one."""
    z = np.linspace(0.0, 11.2, 4001)
    for rho in (1.6 + 0.05 * np.cos(np.pi * z / 11.2), 1.6 + 0.05 * np.exp(-((z - 5.6) / 1.5) ** 2),
                4.0 - 2.5 * np.tanh((z - 2.3) / 0.8)):
        found = front(z, rho)
        assert np.isnan(found.position) and np.isnan(found.width) and found.high > found.low
    found = front(z, 4.0 - 2.5 * np.tanh((z - 2.5) / 0.8))
    assert abs(found.position - 2.5) < 5e-3 and abs(found.width - 1.6) < 5e-3  # the end at 2.5 is not saturated


@pytest.mark.parametrize("descending", [False, True])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_middle_bulge_has_its_front_nearest_the_first_sample(descending, sign):
    """A bulge (sign 1) or a neck (−1) in the middle, ρ = 2.75 + 1.25 sign (tanh((z − 6)/0.8) − tanh((z − 14)/0.8))
    on [0, 20]: two fronts, mirror images; the one nearest the first sample (z = 0, or z = 20 sampled descending) is
    reported: its position the crossing of the mid level of the samples, solved by brentq on the profile (1e-6), its
    width 1.6 (2e-4: the other front's tail and the central differences). Four crossings (the bulge split in its
    middle) have none."""
    from scipy.optimize import brentq

    profile = lambda z: 2.75 + 1.25 * sign * (np.tanh((z - 6.0) / 0.8) - np.tanh((z - 14.0) / 0.8))
    z = np.linspace(0.0, 20.0, 4001)[:: -1 if descending else 1]
    rho = profile(z)
    middle = 0.5 * (rho.max() + rho.min())
    near = (10.0, 20.0) if descending else (0.0, 10.0)
    found = front(z, rho)
    assert abs(found.position - brentq(lambda x: profile(x) - middle, *near, xtol=1e-14)) <= 1e-6
    assert abs(found.width - 1.6) <= 2e-4
    split = front(z, rho + 1.25 * np.exp(-((z - 10.0) / 0.3) ** 2) * -sign * 2)
    assert np.isnan(split.position)
