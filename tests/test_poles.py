"""The generated first-order kernels: Jacobians against finite differences, pole limits against pole_series.

y = (λ2, v, η, w), y' = f(θ, y) (MODEL.md §4). At a pole (distance t, θ = t or π − t, σ = ±1) the Taylor start
λ2 = λ0 + c2 t², v = 2σ c2 t sin t, η = η0 + e2 t², w = 2σ e2 t (codegen/poles.py) gives
f ≈ (2σ c2 t, 4 c2 t, 2σ e2 t, 2 e2) with relative error O(t²).
"""
import numpy as np
import pytest

from balloon_cg.model.field import field_squared
from balloon_cg.model.kernels import KernelSet
from balloon_cg.scene.materials import PRESETS, Material, get_preset
from balloon_cg.model.sphere import sphere_pressure

TWO_COILS = np.array([[1.7321, 1.0, 1.0], [1.7321, -1.0, -1.0]])
CUSTOM = Material("custom", (1.5, 0.2, -0.05), (1.8, -1.0, 3.0))  # runtime exponents: ogden_general_field


class System:
    """rhs and friends of one kernel class at (M, χ = 1), with the field re-evaluated at each state."""

    def __init__(self, material, coils, M):
        self.kernels = KernelSet(material, ("pressure", "magnetic") if len(coils) else ("pressure",))
        self.coils, self.M = coils, M

    def field(self, rho, z):
        return field_squared(rho, z, self.coils) if len(self.coils) else np.zeros(6)

    def values(self, theta, c, s, y, P, M=None):
        return {"theta": theta, "cos_theta": c, "sin_theta": s, **self.kernels.state(y), "P": P,
                "M": self.M if M is None else M, "chi": 1.0, "field": self.field(y[0] * s, y[2])}

    def call(self, kernel, theta, y, P, M=None, c=None, s=None):
        c = np.cos(theta) if c is None else c
        s = np.sin(theta) if s is None else s
        return np.array(self.kernels.call(kernel, self.values(theta, c, s, y, P, M)))

    def pole_series(self, lam0, eta0, P):
        q = self.field(0.0, eta0)
        values = {"lam0": lam0, "P": P, "M": self.M, "chi": 1.0, "field_north": q, "field_south": q}
        return self.kernels.call("pole_series", values)


SYSTEMS = {
    "spom1": lambda: System(get_preset("SPOM1"), [], 0.0),
    "spom1_field": lambda: System(get_preset("SPOM1"), TWO_COILS, 0.05),
    "general_field": lambda: System(CUSTOM, TWO_COILS, 0.05),
}


def taut_states(n, seed):
    """Random interior states of a taut membrane: λ2 ~ 1.5, small v, η ~ λ2 cos θ, w ~ −λ2 sin θ."""
    rng = np.random.default_rng(seed)
    for _ in range(n):
        theta = rng.uniform(0.2, np.pi - 0.2)
        lam2 = rng.uniform(1.3, 1.7)
        y = np.array([lam2, rng.uniform(-0.1, 0.1), lam2 * np.cos(theta) + rng.uniform(-0.05, 0.05),
                      -lam2 * np.sin(theta) * rng.uniform(0.9, 1.1)])
        yield theta, y, rng.uniform(1.5, 3.0)


def central(fun, x, h=1e-5):
    return (fun(x + h) - fun(x - h)) / (2 * h)


@pytest.mark.parametrize("name", SYSTEMS)
def test_rhs_derivatives_match_finite_differences(name):
    """rhs_jacobian, rhs_pressure (and rhs_field) against central differences of rhs (h = 1e-5)."""
    system = SYSTEMS[name]()
    for theta, y, P in taut_states(6, seed=11):
        J = system.call("rhs_jacobian", theta, y, P).reshape(4, 4)
        for k in range(4):
            e = np.eye(4)[k]
            fd = central(lambda x: system.call("rhs", theta, y + x * e, P), 0.0)
            assert np.abs(J[:, k] - fd).max() <= 1e-7 * (1 + np.abs(fd).max()), (theta, y, k)
        fd = central(lambda x: system.call("rhs", theta, y, x), P)
        assert np.abs(system.call("rhs_pressure", theta, y, P) - fd).max() <= 1e-7 * (1 + np.abs(fd).max())
        if system.kernels.field_class:
            fd = central(lambda x: system.call("rhs", theta, y, P, M=x), system.M)
            assert np.abs(fd).max() > 1e-2  # the field term is really exercised
            assert np.abs(system.call("rhs_field", theta, y, P) - fd).max() <= 1e-7 * (1 + np.abs(fd).max())


def taylor_start(t, sigma, lam0, eta0, c2, e2):
    return np.array([lam0 + c2 * t * t, 2 * sigma * c2 * t * np.sin(t), eta0 + e2 * t * t, 2 * sigma * e2 * t])


def pole_errors(system, sigma, lam0, eta0, P, distances):
    """|f − prediction| per component on the Taylor-start state at each distance t from the pole."""
    c2n, e2n, c2s, e2s = system.pole_series(lam0, eta0, P)
    c2, e2 = (c2n, e2n) if sigma > 0 else (c2s, e2s)
    out = []
    for t in distances:
        y = taylor_start(t, sigma, lam0, eta0, c2, e2)
        theta = t if sigma > 0 else np.pi - t
        # cos θ, sin θ from t: np.sin(np.pi - t) carries an absolute error 1e-16, i.e. a relative one of 1e-16/t
        f = system.call("rhs", theta, y, P, c=sigma * np.cos(t), s=np.sin(t))
        out.append(np.abs(f - np.array([2 * sigma * c2 * t, 4 * c2 * t, 2 * sigma * e2 * t, 2 * e2])))
    return np.array(out), c2, e2


@pytest.mark.parametrize("sigma", [1.0, -1.0], ids=["north", "south"])
@pytest.mark.parametrize("name", ["spom1", "spom1_field"])
def test_rhs_near_the_pole_approaches_the_pole_series(name, sigma):
    """f on the Taylor start → pole-series prediction with relative error O(t²), at both poles.

    w' = F2 shows the t² law at t = 1e-3, 1e-4, 1e-5. v' = F1 is formed by cancelling O(1) terms down to
    O(t): its absolute error has a roundoff floor ~ ε_mach/t that overtakes the O(t³) truncation error below
    t ~ 1e-3, so its t² law (relative) is checked from t = 1e-2 to 1e-3 and the floor below. λ2' = v/s and
    η' = w are identities on this state.
    """
    system = SYSTEMS[name]()
    if system.kernels.field_class:
        system.M = 0.002  # the paper's two-coil intensity; the pole field enters (c2, e2)
    lam0, eta0, P = 1.5, sigma * 1.4967, 2.47
    errors, c2, e2 = pole_errors(system, sigma, lam0, eta0, P, [1e-2, 1e-3, 1e-4, 1e-5])
    assert abs(c2) > 1e-3 and abs(e2) > 0.5
    w_ratios = errors[1:-1, 3] / errors[2:, 3]
    assert np.all((90 < w_ratios) & (w_ratios < 110)), w_ratios
    assert 900 < errors[0, 1] / errors[1, 1] < 1100, errors[:, 1]
    assert np.all(errors[2:, 1] <= 1e-14 / np.array([1e-4, 1e-5]))
    assert np.all(errors[:, [0, 2]] <= 1e-15)


def test_pole_series_changes_sign_with_the_field_gradient_between_poles():
    """Mirror symmetry z → −z: the south coefficients equal the north ones of the mirrored field,
    c2_S(H²_z) = c2_N(−H²_z), e2_S(H²_z) = −e2_N(−H²_z)."""
    system = SYSTEMS["spom1_field"]()
    qz, qrr = 3.7, -1.3

    def pole_series(north, south):
        """pole_series with H²_z, H²_ρρ on the axis at the north and south pole (rows FIELD_ROWS)."""
        rows = system.kernels.module.FIELD_ROWS
        at = lambda z, rr: np.array([{"Q_z": z, "Q_rr": rr}.get(row, 0.0) for row in rows])  # noqa: E731
        values = {"lam0": 1.4, "P": 2.2, "M": 0.01, "chi": 1.0, "field_north": at(*north), "field_south": at(*south)}
        return system.kernels.call("pole_series", values)

    c2n, e2n, _, _ = pole_series((-qz, qrr), (0.0, 0.0))
    _, _, c2s, e2s = pole_series((0.0, 0.0), (qz, qrr))
    assert c2s == pytest.approx(c2n, rel=1e-13)
    assert e2s == pytest.approx(-e2n, rel=1e-13)


@pytest.mark.parametrize("preset", list(PRESETS))
def test_pole_series_of_the_exact_sphere(preset):
    """At M = 0 and the sphere pressure, λ2 ≡ λ0 and η = ±λ0 cos t: c2 = 0, e2 = ∓λ0/2 (north/south)."""
    material = get_preset(preset)
    system = System(material, [], 0.0)
    for lam0 in (1.05, 1.5, 3.0):
        c2n, e2n, c2s, e2s = system.pole_series(lam0, lam0, sphere_pressure(material, lam0))
        assert abs(c2n) < 1e-12 and abs(c2s) < 1e-12
        assert e2n == pytest.approx(-lam0 / 2, rel=1e-12)
        assert e2s == pytest.approx(lam0 / 2, rel=1e-12)
