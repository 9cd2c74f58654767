"""Second variation of the M = 0 balloon energy about the inflated sphere, axisymmetric Legendre modes.

Independent of the project's Galerkin code: this starts from the continuum functional of MODEL.md §2,

    E = ∫_0^π [Φ(λ1, λ2) sin θ + ½ P ρ² η'] dθ,      λ1 = sqrt(ρ'² + η'²),  λ2 = ρ / sin θ,

perturbs the sphere ρ = λ sin θ, η = λ cos θ by a normal displacement w and a tangential (meridional)
displacement u,

    (ρ, η) = (λ + ε w) e_r + ε u e_θ,   e_r = (sin θ, cos θ),  e_θ = (cos θ, −sin θ),
    w = W P_n(cos θ),   u = U dP_n(cos θ)/dθ,

and computes d²E/dε² at ε = 0 exactly (polynomial integrals in x = cos θ) for n = 0..N_MAX, with Φ kept as a
general function through its derivatives at (λ, λ): Φ1, Φ2, Φ11, Φ12, Φ22. It then checks, for each n:

  1. the first variation vanishes iff P = (Φ1 + Φ2)/λ² and Φ1 = Φ2 at (λ, λ) (true for any isotropic Φ):
     P = 2Φ1/λ²,
  2. the Hessian in (W, U) divided by c_n = ∫ P_n² sin θ dθ = 2/(2n+1) equals the closed form K_n below
     (with Φ2 = Φ1, Φ22 = Φ11, N = n(n+1), t = Φ1/λ, S = Φ11 + Φ12):

        K_n = [[ 2S + (N − 4) t,          −N (S − t)                ],
               [ −N (S − t),              N ((N − 1) Φ11 + Φ12 − t) ]]

  3. and, symbolically in N, det K_n = N (N − 2) Δ_n with
        Δ_n = Φ11² − Φ12² + t ((N − 1) Φ11 + 3 Φ12) − 2 t².

Run:  python docs/derivations/sphere_second_variation.py [N_MAX]   (prints OK lines; raises on any mismatch)
"""
import sys

import sympy as sp

x, lam, eps, W, U, P = sp.symbols("x lambda epsilon W U P", real=True)
F1, F2, F11, F12, F22 = sp.symbols("Phi1 Phi2 Phi11 Phi12 Phi22", real=True)
Nsym = sp.Symbol("N", real=True)
s = sp.sqrt(1 - x**2)  # sin θ on θ ∈ (0, π)


def d_theta(f):
    """d/dθ of an expression in x = cos θ."""
    return -s * sp.diff(f, x)


def closed_form(N, phi1=F1, phi11=F11, phi12=F12, stretch=lam):
    t = phi1 / stretch
    S = phi11 + phi12
    return sp.Matrix([[2 * S + (N - 4) * t, -N * (S - t)], [-N * (S - t), N * ((N - 1) * phi11 + phi12 - t)]])


def second_variation(n):
    """(first-variation coefficient, 2×2 Hessian in (W, U)) of E for mode n, exact."""
    psi = sp.legendre(n, x)
    w, u = W * psi, U * d_theta(psi)
    rho = (lam + eps * w) * s + eps * u * x
    eta = (lam + eps * w) * x - eps * u * s
    drho, deta = d_theta(rho), d_theta(eta)
    # Stretch increments, exact to O(ε²): λ1 = sqrt(ρ'² + η'²), λ2 = ρ/sin θ.
    l1sq = sp.expand(drho**2 + deta**2)
    l1_0 = lam
    l1sq_1 = sp.diff(l1sq, eps).subs(eps, 0)
    l1sq_2 = sp.diff(l1sq, eps, 2).subs(eps, 0) / 2
    assert sp.simplify(l1sq.subs(eps, 0) - lam**2) == 0
    # sqrt(λ² + ε a + ε² b) = λ + ε a/(2λ) + ε² (b/(2λ) − a²/(8λ³)) + O(ε³)
    d1 = eps * l1sq_1 / (2 * l1_0) + eps**2 * (l1sq_2 / (2 * l1_0) - l1sq_1**2 / (8 * l1_0**3))
    d2 = sp.expand(sp.cancel(rho / s) - lam)  # λ2 − λ, exact (linear in ε)
    # Φ(λ + d1, λ + d2) to O(ε²) through a general Φ's derivatives at (λ, λ).
    phi = F1 * d1 + F2 * d2 + (F11 * d1**2 + 2 * F12 * d1 * d2 + F22 * d2**2) / 2
    # ∫ (·) dθ over (0, π) = ∫_{-1}^{1} (·)/sin θ dx.
    density = phi * s + P * rho**2 * deta / 2
    out = []
    for k in (1, 2):
        coeff = sp.expand(sp.diff(density, eps, k).subs(eps, 0) / sp.factorial(k))
        integrand = sp.expand(sp.cancel(coeff / s))
        assert not integrand.has(sp.sqrt), integrand
        out.append(sp.expand(sp.integrate(integrand, (x, -1, 1))))
    first, second = out
    hess = sp.Matrix(2, 2, lambda i, j: sp.diff(second, (W, U)[i], (W, U)[j]))
    return first, hess


def check_mode(n):
    first, hess = second_variation(n)
    c = sp.Rational(2, 2 * n + 1)
    # 1. Equilibrium: the first variation is (Φ1 + Φ2 − P λ²) ∫ w sin θ dθ + (Φ2 − Φ1) ∫ u cos θ dθ; the first
    #    term lives in n = 0 only, the second (n even ≥ 2: (Φ1 − Φ2)(1 + (−1)^n) U) vanishes for isotropic Φ.
    expected_first = (F1 + F2 - P * lam**2) * W * 2 if n == 0 else (F1 - F2) * (1 + (-1) ** n) * U
    assert sp.simplify(first - expected_first) == 0, (n, first)
    # 2. Symmetric Φ at the equilibrium pressure: closed form.
    sym = {F2: F1, F22: F11, P: 2 * F1 / lam**2}
    K = (hess.subs(sym) / c).applyfunc(sp.simplify)
    N = n * (n + 1)
    diff = (K - closed_form(N)).applyfunc(sp.simplify)
    assert diff == sp.zeros(2, 2), (n, K)
    return K


def check_determinant():
    K = closed_form(Nsym)
    t = F1 / lam
    delta = F11**2 - F12**2 + t * ((Nsym - 1) * F11 + 3 * F12) - 2 * t**2
    assert sp.expand(K.det() - Nsym * (Nsym - 2) * delta) == 0
    # n = 1 (N = 2): K_1 = 2 (S − t) [[1, −1], [−1, 1]]: rigid translation (W, U) = (1, 1) is a null vector.
    K1 = closed_form(2)
    assert (K1 * sp.Matrix([1, 1])).applyfunc(sp.expand) == sp.zeros(2, 1)
    assert sp.expand(K1.trace() - 4 * (F11 + F12 - t)) == 0
    return delta


if __name__ == "__main__":
    n_max = int(sys.argv[1]) if len(sys.argv) > 1 else 6
    for n in range(n_max + 1):
        K = check_mode(n)
        print(f"n = {n}: OK  K_n = {K.tolist()}")
    print("det K_n = N (N - 2) * Delta_n,  Delta_n =", check_determinant(), " OK")
