"""The shortcuts of the hot loops against the plain computations they replace.

- Equator-symmetric states integrate on the Gauss nodes x ≥ 0 with doubled weights (``even_half``): the
  residual, Hessian, ∂R/∂M, energy and volume of a symmetric discretisation against the general one (every
  node) at the same state, with two coils; the stability blocks (m = 0 and m = 1) against the full assembly.
- Below SMALL_SYSTEM unknowns the node state and the Hessian, below SMALL_GRADIENT the gradient, are jitted loops:
  against an einsum of the node tables.
- The lowest eigenvalues below SMALL_EIGEN rows (tridiagonalisation and bisection) against LAPACK's full
  spectrum, with clustered, repeated and tiny eigenvalues; orthogonal Gram factors against Cholesky.
- The node state and coil field the Equilibrium holds (in arrays of its own) against Discretisation.node_state
  and field_squared_nodes; the kernels on the held arrays with the scalars refilled in a
  bound argument list against binding by name; the held state against a fresh Equilibrium after other iterates.
- Parameters.with_value against the dataclass constructor.
"""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import linalg

from balloon_cg.analysis.stability import azimuthal
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.branches.problem import equilibrium_of
from balloon_cg.analysis.stability.axisymmetric import SecondVariation
from balloon_cg.galerkin.discretisation import SMALL_GRADIENT, SMALL_SYSTEM, HESSIAN_ROW, Discretisation, gauss_nodes
from balloon_cg.galerkin.equilibrium import Equilibrium, Parameters
from balloon_cg.model import field
from balloon_cg.numerics import eigen
from balloon_cg.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
TWO_COILS = ROOT / "scenes" / "spom1_two_coils_M0.002.toml"


@pytest.fixture(scope="module")
def two_coils():
    scene = load_scene(TWO_COILS).with_overrides({"continuation.stop_stretch": 1.6})
    return scene, trace_primary(scene, down=False)


def _embed(symmetric: Discretisation, general: Discretisation, u):
    """The symmetric unknowns u as unknowns of the general discretisation (same functions)."""
    a, b = symmetric.split(u)
    return general.join(a, b)


@pytest.mark.parametrize("degree", [12, 40])  # jitted loops (< SMALL_SYSTEM unknowns) and BLAS
def test_symmetric_half_nodes_match_every_node(two_coils, degree):
    scene, branch = two_coils
    sym = Discretisation(degree, True, False)
    assert (sym.size < SMALL_SYSTEM) == (degree == 12)
    full = Discretisation(degree, False, False, quadrature=gauss_nodes(degree))
    assert sym.cos_theta.size < full.cos_theta.size and sym.x.size == full.x.size
    X = branch.disc.transfer(branch.X[len(branch.X) // 2], sym)
    u, params = X[:-1], branch.params.with_value("P", X[-1])
    eq_sym, eq_full = Equilibrium(scene, sym), Equilibrium(scene, full)
    v = _embed(sym, full, u)
    keep = np.concatenate([full.a_index[full.a_index % 2 == 0], full.a_index.size + full.b_index[full.b_index % 2 == 1]])
    R, J = eq_full.residual(v, params), eq_full.jacobian(v, params)
    scale = np.abs(J).max()
    assert np.abs(eq_sym.residual(u, params) - R[keep]).max() <= 1e-13 * scale
    assert np.abs(eq_sym.jacobian(u, params) - J[np.ix_(keep, keep)]).max() <= 1e-13 * scale
    dM = eq_full.parameter_derivative(v, params, "M")[keep]
    assert np.abs(eq_sym.parameter_derivative(u, params, "M") - dM).max() <= 1e-13 * np.abs(dM).max()
    assert eq_sym.energy(u, params) == pytest.approx(eq_full.energy(v, params), rel=1e-13)
    assert eq_sym.volume(u) == pytest.approx(eq_full.volume(v), rel=1e-13)


@pytest.mark.parametrize("degree", [8, 12])
def test_small_system_loops_match_the_node_sums(degree):
    disc = Discretisation(degree, False, True)
    assert disc.size < SMALL_SYSTEM
    rng = np.random.default_rng(3)
    n_q = disc.weights.size
    hessian_rows, gradient_rows = rng.normal(size=(10, n_q)), rng.normal(size=(4, n_q))
    h = np.array([[hessian_rows[HESSIAN_ROW[k, l]] for l in range(4)] for k in range(4)])  # (4, 4, n_q)
    ops = disc.ops  # (4, n_q, size)
    expected = np.einsum("kqi,klq,q,lqj->ij", ops, h, disc.weights, ops)
    assert np.abs(disc.hessian(hessian_rows) - expected).max() <= 1e-13 * np.abs(expected).max()
    gradient = np.einsum("kqi,kq,q->i", ops, gradient_rows, disc.weights)
    assert np.abs(disc.gradient(gradient_rows) - gradient).max() <= 1e-13 * np.abs(gradient).max()
    u = rng.normal(size=disc.size)
    state = np.einsum("kqi,i->kq", ops, u)
    assert np.abs(disc.node_state(u) - state).max() <= 1e-13 * np.abs(state).max()


def test_gradient_loops_up_to_small_gradient_match_the_node_sums():
    disc = Discretisation(40, False, True)
    assert SMALL_SYSTEM <= disc.size < SMALL_GRADIENT
    rows = np.random.default_rng(4).normal(size=(4, disc.weights.size))
    gradient = np.einsum("kqi,kq,q->i", disc.ops, rows, disc.weights)
    assert np.abs(disc.gradient(rows) - gradient).max() <= 1e-13 * np.abs(gradient).max()


def test_stability_blocks_on_half_nodes_match_the_full_assembly(two_coils):
    scene, branch = two_coils
    eq = equilibrium_of(branch)
    X = branch.X[-1]
    u, params = X[:-1], branch.params.with_value("P", X[-1])
    variation = SecondVariation(eq, 20)
    H, g = variation.matrices(u, params)
    He, ge = variation._even_matrices(u, params)
    i = variation.index
    even, odd = np.concatenate([i["a_even"], i["b_odd"]]), np.concatenate([i["a_odd"], i["b_even"]])
    for idx in (even, odd):
        assert np.abs(He[np.ix_(idx, idx)] - H[np.ix_(idx, idx)]).max() <= 1e-13 * np.abs(H).max()
    assert np.abs(ge[even] - g[even]).max() <= 1e-13 * np.abs(g).max()
    b = azimuthal.perturbation_basis(eq, 1, 20)
    full, halves = azimuthal._hessian(eq, u, params, 1, b), azimuthal._class_hessians(eq, u, params, 1, b)
    for c, half in zip(b.classes, halves):
        assert np.abs(half - full[np.ix_(c, c)]).max() <= 1e-13 * np.abs(full).max()


def _spectrum(n, kind, rng):
    if kind == "random":
        return rng.normal(size=n) * 10.0
    if kind == "clustered":  # a double and a nearly double eigenvalue at the bottom, one near zero
        return np.concatenate([[-1.0, -1.0, -1.0 + 1e-10, 1e-13], rng.uniform(2.0, 50.0, max(n - 4, 0))])[:n]
    return np.concatenate([[0.0] * 3, np.arange(1.0, n - 2)])[:n]  # repeated zeros


@pytest.mark.parametrize("n", [1, 2, 3, 5, 20, 31, eigen.SMALL_EIGEN - 1])
@pytest.mark.parametrize("kind", ["random", "clustered", "degenerate"])
def test_small_lowest_eigenvalues_match_lapack(n, kind):
    rng = np.random.default_rng(n)
    values = _spectrum(n, kind, rng)
    Q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    A = (Q * values) @ Q.T
    A = 0.5 * (A + A.T)
    count = min(3, n)
    expected = linalg.eigvalsh(A)[:count]
    got = eigen.lowest_of(A.copy(), count)
    assert got.shape == (count,)
    assert np.abs(got - expected).max() <= 1e-13 * max(1.0, np.abs(values).max())


def test_orthogonal_gram_factor_is_the_cholesky_one():
    b = azimuthal.basis(1, 20, 60)
    rng = np.random.default_rng(0)
    H = rng.normal(size=(b.size, b.size))
    H = H + H.T
    normals = rng.normal(size=(2, b.size))
    general = eigen.lowest(H, eigen.GramFactor(b.gram), 3, normals)
    assert np.abs(eigen.lowest(H, b.factor, 3, normals) - general).max() <= 1e-12 * np.abs(H).max()


def test_held_state_and_field_are_node_state_and_field(two_coils):
    _, branch = two_coils
    eq = equilibrium_of(branch)
    X = branch.X[-1]
    eq._pointwise("energy_gradient", X[:-1], branch.params.with_value("P", X[-1]))
    state = eq.disc.node_state(X[:-1])
    assert np.array_equal(eq.nodes.state, state)
    expected = np.empty((6, state.shape[1]))
    field.field_squared_nodes(state[0] * eq.disc.sin_theta, state[2], eq.coils, expected)
    assert np.array_equal(eq.nodes.field, expected)


@pytest.mark.parametrize("kernel", ["energy_gradient", "energy_hessian", "pressure_gradient", "field_gradient"])
def test_kernels_on_held_arrays_match_binding_by_name(two_coils, kernel):
    _, branch = two_coils
    eq = equilibrium_of(branch)
    X = branch.X[-1]
    u, params = X[:-1], branch.params.with_value("P", X[-1])
    fast = eq._pointwise(kernel, u, params)
    assert np.array_equal(fast, eq.kernels.nodes(kernel, eq.nodes.values, params))
    other = branch.params.with_value("P", 1.5 * X[-1])  # only the scalars of the bound list change
    assert np.array_equal(eq._pointwise(kernel, u, other), eq.kernels.nodes(kernel, eq.nodes.values, other))


def test_held_state_follows_the_iterate(two_coils):
    scene, branch = two_coils
    eq = equilibrium_of(branch)
    (u1, P1), (u2, P2) = (branch.X[-1][:-1], branch.X[-1][-1]), (branch.X[1][:-1], branch.X[1][-1])
    p1, p2 = branch.params.with_value("P", P1), branch.params.with_value("P", P2)
    eq.residual(u1, p1)
    eq.jacobian(u2, p2)
    for u, p in ((u1, p1), (u2, p2)):
        fresh = Equilibrium(scene, eq.disc)
        assert np.array_equal(eq.residual(u, p), fresh.residual(u, p))
        assert np.array_equal(eq.bordered_jacobian(u, p, "P"), fresh.bordered_jacobian(u, p, "P"))


def test_with_value_is_the_constructor():
    params = Parameters(P=1.0, M=0.002, chi=0.5, mu=(1.0, 2.0), alpha=(1.3, 5.0))
    assert params.with_value("M", 3) == Parameters(P=1.0, M=3.0, chi=0.5, mu=(1.0, 2.0), alpha=(1.3, 5.0))
    assert params.P == 1.0
    with pytest.raises(TypeError, match="no field 'Q'"):
        params.with_value("Q", 1.0)


def test_a_default_run_compiles_every_jitted_loop_once(tmp_path):
    """numba types a read-only array apart from a writable one: a second variation's node tables handed to the
    loops as writable arrays compiled energy_hessian_nodes, its assembly and the gradient loops a second time
    (~1.8 s of a cold start). After a default run (a fresh process) every dispatcher of balloon_cg holds one
    signature."""
    code = f"""
import gc
from numba.core.registry import CPUDispatcher
from balloon_cg.app.cli import main
try:
    main(["run", {str(ROOT / "scenes" / "spom1.toml")!r}, "-o", {str(tmp_path / "run.h5")!r}, "--quiet"])
except SystemExit as stop:
    assert not stop.code, stop.code
for obj in gc.get_objects():
    if isinstance(obj, CPUDispatcher) and obj.py_func.__module__.startswith("balloon_cg"):
        print(obj.py_func.__module__, obj.py_func.__name__, len(obj.signatures))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    counts = [line.rsplit(" ", 1) for line in out.splitlines()]
    assert any(name.endswith("energy_hessian_nodes") for name, _ in counts)
    assert [name for name, count in counts if int(count) > 1] == []
