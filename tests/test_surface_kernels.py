"""Surface kernels (MODEL.md §8, codegen/surface.py): against finite differences, an independent numpy density
(Φ from the eigenvalues of C with the material's own formula), across the Ogden series/closed-form switch, and
against the axisymmetric kernels on axisymmetric states."""
import numpy as np
import pytest

from balloon_cg import generated
from balloon_cg.model.kernels import PLAIN, KernelSet
from balloon_cg.scene.energies import StrainEnergy
from balloon_cg.scene.formula import evaluate
from balloon_cg.scene.materials import Material, get_preset
from codegen.surface import SWITCH

GENERAL = Material("general", (1.1, 0.4, -0.05), (1.7, 3.1, -2.5))
CASES = {  # name: (material, has field, dielectric)
    "SPOM1": (get_preset("SPOM1"), False, False),
    "Gent": (get_preset("Gent"), False, False),
    "general_field": (GENERAL, True, False),
    "SPOM1_dielectric": (get_preset("SPOM1"), False, True),
}
PARAMS = {"P": 0.7, "M": 0.3, "chi": 1.2, "voltage": 0.4}


def terms(has_field: bool, electric: bool) -> tuple:
    """The class's energy terms by name (model/kernels.py: scene_terms)."""
    return PLAIN + (("magnetic",) if has_field else ()) + (("dielectric",) if electric else ())


FIELD_CENTRE = np.array([0.2, -0.1, 0.5])
FIELD_SLOPE = np.array([0.3, -0.2, 0.5])
FIELD_CURVATURE = np.array([[1.0, 0.2, -0.3], [0.2, 0.6, 0.1], [-0.3, 0.1, 0.8]])


@pytest.fixture(scope="module", params=list(CASES))
def case(request):
    material, has_field, electric = CASES[request.param]
    kernels = KernelSet(material, terms(has_field, electric)).surface()
    return material, has_field, electric, kernels


def field_rows(point):
    """Rows Q, Q_x, …, Q_zz of the exactly quadratic H²(x) = 1 + g·δ + ½ δᵀAδ, δ = x − c."""
    delta = point - FIELD_CENTRE
    A = FIELD_CURVATURE
    grad = FIELD_SLOPE + A @ delta
    value = 1 + FIELD_SLOPE @ delta + delta @ A @ delta / 2
    return np.array([value, *grad, A[0, 0], A[0, 1], A[0, 2], A[1, 1], A[1, 2], A[2, 2]])


def values(state, has_field, P=PARAMS["P"]):
    named = {**PARAMS, "P": P, "state": np.ascontiguousarray(state)}
    if has_field:
        named["field"] = field_rows(state[:3])
    return named


def elastic(material, lam1, lam2):
    """Φ(λ1, λ2) by the material's own formula (Ogden sum, or the scene formula of a strain energy)."""
    if isinstance(material, StrainEnergy):
        return evaluate(material.formula, material.parameters, lam1, lam2).real
    return sum(m / a * (lam1**a + lam2**a + (lam1 * lam2) ** -a - 3) for m, a in zip(material.mu, material.alpha))


def reference_density(material, has_field, electric, state, P=PARAMS["P"]):
    """π from numpy: λ1², λ2² the eigenvalues of C = [a_θ·a_θ, a_θ·a_φ; a_φ·a_θ, a_φ·a_φ]."""
    point, a_t, a_p = state[:3], state[3:6], state[6:]
    C = np.array([[a_t @ a_t, a_t @ a_p], [a_p @ a_t, a_p @ a_p]])
    lam2, lam1 = np.sqrt(np.linalg.eigvalsh(C))
    pi = elastic(material, lam1, lam2) - P / 3 * point @ np.cross(a_t, a_p)
    if electric:
        pi -= PARAMS["voltage"] ** 2 * (lam1 * lam2) ** 2
    if has_field:
        pi -= PARAMS["chi"] * PARAMS["M"] * field_rows(point)[0] / 2
    return pi


def random_state(rng):
    """A node state with a_θ, a_φ spanning a random plane, stretches ~0.8–1.6 and some shear."""
    frame, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    F = np.array([[1.3, 0.2], [-0.1, 0.9]]) + rng.uniform(-0.15, 0.15, (2, 2))
    a_t, a_p = frame[:, :2] @ F[:, 0], frame[:, :2] @ F[:, 1]
    return np.concatenate([rng.normal(0, 0.5, 3) + [0, 0, 1], a_t, a_p])


def stretched_state(r, lam2=1.1, angle=0.4):
    """A node state with d/m = (λ1² − λ2²)/(λ1² + λ2²) = r exactly up to rounding (r = 0: a sphere state)."""
    lam1 = lam2 * np.sqrt((1 + r) / (1 - r))
    c, s = np.cos(angle), np.sin(angle)
    return np.array([0.3, -0.2, 1.0, lam1 * c, lam1 * s, 0.0, -lam2 * s, lam2 * c, 0.0])


def switch_side(state) -> bool:
    """True where the kernels take the closed form: D > SWITCH² m², D and I computed as the kernels do."""
    a_t, a_p = state[3:6], state[6:]
    c11, c22, c12 = a_t @ a_t, a_p @ a_p, a_t @ a_p
    return ((c11 - c22) / 2) ** 2 + c12**2 > float(SWITCH**2 / 4) * (c11 + c22) ** 2


def switch_neighbours():
    """Two states a few ulps of d/m apart on either side of d/m = SWITCH (the series below, the closed form above)."""
    r0 = float(SWITCH)
    for ulps in range(1, 64):
        below, above = (stretched_state(r0 * (1 + sign * ulps * 2e-16)) for sign in (-1, 1))
        if not switch_side(below) and switch_side(above):
            return below, above
    raise AssertionError("no pair of states straddles the switch")


def full_hessian(kernels, state, named):
    H = np.empty((9, 9))
    for (i, j), value in zip(generated.SURFACE_PAIRS, kernels.call("surface_hessian", named)):
        H[i, j] = H[j, i] = value
    return H


def fd_gradient(function, state, step=1e-5):
    return np.array([(function(state + step * e) - function(state - step * e)) / (2 * step) for e in np.eye(9)])


def assert_close(a, b, rel):
    scale = max(np.max(np.abs(a)), np.max(np.abs(b)))
    assert np.max(np.abs(np.asarray(a) - np.asarray(b))) <= rel * scale


def test_registry_lists_a_surface_module_per_class():
    assert set(generated.SURFACE_CLASSES) == set(generated.CLASSES) | set(generated.ENERGY_CLASSES)
    assert generated.SURFACE_PAIRS == tuple((i, j) for i in range(9) for j in range(i, 9))


def test_energy_gradient_hessian_against_numpy_and_differences(case):
    material, has_field, electric, kernels = case
    rng = np.random.default_rng(7)
    energy = lambda s: kernels.call("surface_energy", values(s, has_field))[0]  # noqa: E731
    gradient = lambda s: np.array(kernels.call("surface_gradient", values(s, has_field)))  # noqa: E731
    reference = lambda s: reference_density(material, has_field, electric, s)  # noqa: E731
    for _ in range(3):
        state = random_state(rng)
        assert energy(state) == pytest.approx(reference(state), rel=1e-12)
        assert_close(gradient(state), fd_gradient(reference, state), 1e-7)
        H = full_hessian(kernels, state, values(state, has_field))
        assert_close(H, fd_gradient(gradient, state), 1e-7)
        assert_close(H, fd_gradient(lambda s: fd_gradient(reference, s, 1e-4), state, 1e-4), 1e-5)


def test_parameter_gradients_are_derivatives_of_the_gradient(case):
    material, has_field, electric, kernels = case
    state = random_state(np.random.default_rng(11))
    named = values(state, has_field)
    for kernel, parameter in [("surface_pressure_gradient", "P"), ("surface_field_gradient", "M"),
                              ("surface_voltage_gradient", "voltage")]:
        if kernel not in kernels.module.KERNELS:
            continue
        step = 1e-5
        up, down = ({**named, parameter: named[parameter] + sign * step} for sign in (1, -1))
        expected = (np.array(kernels.call("surface_gradient", up)) - kernels.call("surface_gradient", down)) / (2 * step)
        assert_close(kernels.call(kernel, named), expected, 1e-8)


def test_vectorised_kernels_match_the_scalar_ones(case):
    _, has_field, _, kernels = case
    rng = np.random.default_rng(5)
    states = np.stack([random_state(rng) for _ in range(4)], axis=1)
    named = {**PARAMS, "state": states}
    if has_field:
        named["field"] = np.stack([field_rows(s[:3]) for s in states.T], axis=1)
    out = kernels.nodes("surface_hessian", named)
    for i in range(states.shape[1]):
        single = {**named, "state": states[:, i].copy()}
        if has_field:
            single["field"] = named["field"][:, i].copy()
        assert np.array_equal(out[:, i], kernels.call("surface_hessian", single))


@pytest.mark.parametrize("name", ["SPOM1", "general_field"])
def test_sphere_states_and_the_series_switch(name):
    """d = 0 (a_θ ⊥ a_φ, |a_θ| = |a_φ|): finite, equal to the numpy density and to differences of the gradient;
    just below/above d/m = SWITCH: value, gradient and Hessian continuous to rounding."""
    material, has_field, electric = CASES[name]
    kernels = KernelSet(material, terms(has_field, electric)).surface()
    gradient = lambda s: np.array(kernels.call("surface_gradient", values(s, has_field)))  # noqa: E731
    for r in (0.0, 1e-3):
        state = stretched_state(r)
        assert kernels.call("surface_energy", values(state, has_field))[0] == pytest.approx(
            reference_density(material, has_field, electric, state), rel=1e-13)
        H = full_hessian(kernels, state, values(state, has_field))
        assert np.all(np.isfinite(H))
        assert_close(H, fd_gradient(gradient, state), 1e-7)
    below, above = switch_neighbours()
    for kernel, rel in [("surface_energy", 1e-13), ("surface_gradient", 1e-12), ("surface_hessian", 1e-12)]:
        assert_close(kernels.call(kernel, values(below, has_field)), kernels.call(kernel, values(above, has_field)), rel)
    H = full_hessian(kernels, above, values(above, has_field))
    assert_close(H, fd_gradient(gradient, above), 1e-7)


def axisymmetric_node(theta, phi, lam2, v, eta, w):
    """(x, a_θ, a_φ) of the axisymmetric state (λ2, v, η, w) at (θ, φ): ρ = λ2 sin θ, ρ' = λ2 cos θ + v."""
    rho, drho = lam2 * np.sin(theta), lam2 * np.cos(theta) + v
    c, s = np.cos(phi), np.sin(phi)
    return np.array([rho * c, rho * s, eta, drho * c, drho * s, w, -lam2 * s, lam2 * c, 0.0])


def test_axisymmetric_states_give_the_axisymmetric_energy():
    """Φ(λ1, λ2) of generated/ogden_spom1 (its energy_density at P = 0) equals surface_energy at P = 0; with P the
    two pressure terms differ by a total θ-derivative, so their integrals over the sphere agree."""
    material = get_preset("SPOM1")
    axisymmetric = KernelSet(material)
    surface = axisymmetric.surface()
    assert surface.module.__name__.endswith("surface_ogden_spom1")
    # a smooth axisymmetric state: λ2 = 1.3 + 0.2 cos θ, η = 1.1 cos θ + 0.3 cos² θ
    nodes, weights = np.polynomial.legendre.leggauss(40)
    theta = np.arccos(nodes)
    lam2 = 1.3 + 0.2 * nodes
    v = -0.2 * np.sin(theta) ** 2
    eta = 1.1 * nodes + 0.3 * nodes**2
    w = -np.sin(theta) * (1.1 + 0.6 * nodes)
    axi, surf = {}, {}
    for P in (0.0, 1.0):
        named = {"cos_theta": nodes, "sin_theta": np.sin(theta), "lam2": lam2, "v": v, "eta": eta, "w": w, "P": P}
        axi[P] = axisymmetric.nodes("energy_density", named)[0]
        states = np.stack([axisymmetric_node(t, 0.7, *y) for t, *y in zip(theta, lam2, v, eta, w)], axis=1)
        surf[P] = surface.nodes("surface_energy", {"P": P, "state": states})[0]
    assert np.allclose(surf[0.0], axi[0.0], rtol=1e-13, atol=0)
    assert weights @ (surf[1.0] - surf[0.0]) == pytest.approx(weights @ (axi[1.0] - axi[0.0]), rel=1e-12)

