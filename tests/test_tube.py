"""The uniformly inflated closed tube with sliding ends (model/tube.py) against closed forms derived here.

Energy per 2π and unit reference length e = Φ(λz, λθ) − ½ P λθ² λz: ∂e/∂λθ = 0 gives P = Φ_2/(λθλz), ∂e/∂λz = 0
the closed-end balance N = Φ_1 − λθΦ_2/(2λz) = 0. The pressure maximum along N = 0 is where
det ∂(P, N)/∂(λθ, λz) = 0 (Yu & Fu), solved below with SymPy/mpmath at 30 digits from the strain energy alone.
"""
import mpmath
import numpy as np
import pytest
import sympy as sp
from scipy.optimize import brentq

from balloon_cg.model.membrane import Charged
from balloon_cg.model.tube import (axial_force, bulge_onset, closed_end_axial, closed_end_state, hoop_pressure,
                                   maxwell_pressure, pressure_maximum, pressure_minimum)
from balloon_cg.scene import parse_scene

theta, z = sp.symbols("theta z", positive=True)


def neo_hookean_state(hoop):
    """Neo-Hookean (Φ = λ1² + λ2² + (λ1λ2)⁻² − 3): N = 0 is 2λθ²λz⁴ − λθ⁴λz² − 1 = 0, a quadratic in λz², so
    λz² = (λθ⁴ + sqrt(λθ⁸ + 8λθ²))/(4λθ²), and P = 2(1 − λz⁻²λθ⁻⁴)/λz."""
    axial = sp.sqrt((hoop**4 + sp.sqrt(hoop**8 + 8 * hoop**2)) / (4 * hoop**2))
    return axial, 2 * (1 - axial**-2 * hoop**-4) / axial


def material(preset):
    return parse_scene(f'[material]\npreset = "{preset}"\n').material


def symbolic_energy(m):
    """Φ(λ1 = z, λ2 = θ) of the material ``m`` (Ogden, or the Gent family), its numbers as exact decimals."""
    if hasattr(m, "values"):
        mu, Jm = (sp.Rational(repr(v)) for v in m.values)
        I1 = theta**2 + z**2 + (theta * z) ** -2
        return -(mu * Jm / 2) * sp.log(1 - (I1 - 3) / Jm)
    terms = zip(map(lambda v: sp.Rational(repr(v)), m.mu), map(lambda v: sp.Rational(repr(v)), m.alpha))
    return sum(mu / a * (z**a + theta**a + (z * theta) ** -a - 3) for mu, a in terms)


def closed_end_path(energy):
    """(P(λθ, λz), N(λθ, λz), λz(λθ) on N = 0): lambdified from the energy; λz by brentq (to 1e-15) from the
    bracket [0.3, b], b the first of 2, 5, 10, 30, 100 where N changes sign (and is finite)."""
    P = sp.diff(energy, theta) / (theta * z)
    N = sp.diff(energy, z) - theta * sp.diff(energy, theta) / (2 * z)
    N_of = sp.lambdify((theta, z), N)

    def axial(hoop):
        b = next(b for b in (2, 5, 10, 30, 100) if N_of(hoop, 0.3) * N_of(hoop, b) < 0)
        return brentq(lambda a: N_of(hoop, a), 0.3, b, xtol=1e-15, rtol=1e-15)

    return P, N, axial


def equal_area_integral(energy, pressure: float, cuts, nodes: int = 80) -> tuple:
    """(∫ (P − pressure) dv, ∫ |P − pressure| dv) along the closed-end path N = 0 of ``energy`` from λθ = cuts[0] to
    cuts[-1], v = λθ²λz: dv/dλθ = 2λθλz + λθ² dλz/dλθ with dλz/dλθ = −N_θ/N_z; Gauss–Legendre with ``nodes`` nodes
    on each piece between consecutive cuts."""
    P, N, axial_of = closed_end_path(energy)
    P_of = sp.lambdify((theta, z), P)
    slope_of = sp.lambdify((theta, z), 2 * theta * z - theta**2 * sp.diff(N, theta) / sp.diff(N, z))
    x, w = np.polynomial.legendre.leggauss(nodes)
    signed = absolute = 0.0
    for low, high in zip(cuts, cuts[1:]):
        for hoop, weight in zip((high - low) / 2 * x + (high + low) / 2, (high - low) / 2 * w):
            axial = axial_of(hoop)
            value = (P_of(hoop, axial) - pressure) * slope_of(hoop, axial) * weight
            signed, absolute = signed + value, absolute + abs(value)
    return signed, absolute


@pytest.mark.parametrize("hoop", [1.05, 1.5, 2.5, 6.0])
def test_neo_hookean_uniform_state_is_the_closed_form(hoop):
    state = closed_end_state(material("neo-Hookean"), hoop)
    axial, P = (float(v) for v in neo_hookean_state(sp.Float(hoop, 30)))
    assert abs(state.axial - axial) <= 1e-13 * axial and abs(state.pressure - P) <= 1e-13 * P
    assert abs(axial_force(material("neo-Hookean"), hoop, state.axial)) < 1e-13
    grid = closed_end_axial(material("neo-Hookean"), np.array([hoop, 1.2, 3.0]))  # the scans' path, at once
    assert abs(grid[0] - axial) <= 1e-13 * axial
    assert abs(grid[2] - closed_end_state(material("neo-Hookean"), 3.0).axial) <= 1e-13
    assert hoop_pressure(material("neo-Hookean"), hoop, axial) == pytest.approx(P, rel=1e-14)


def test_neo_hookean_pressure_maximum_is_the_closed_form():
    """dP/dλθ = 0 of the explicit P(λθ) along N = 0, solved at 30 digits."""
    axial, P = neo_hookean_state(theta)
    with mpmath.workdps(30):
        hoop = sp.nsolve(sp.diff(P, theta), theta, 1.5, prec=30)
    found = pressure_maximum(material("neo-Hookean"))
    assert abs(found.hoop - float(hoop)) <= 1e-10
    assert abs(found.pressure - float(P.subs(theta, hoop))) <= 1e-13 * found.pressure


@pytest.mark.parametrize("preset, largest_hoop", [("SPOM1", 10.0), ("TPOM2", 10.0), ("Gent", 5.0)])
def test_pressure_maximum_solves_yu_and_fu(preset, largest_hoop):
    """det ∂(P, N)/∂(λθ, λz) = 0 and N = 0 from the strain energy by SymPy, solved by nsolve at 30 digits from the
    largest P of a coarse scan of the closed-end path (lambdified here, brentq in λz)."""
    energy = symbolic_energy(material(preset))
    P, N, axial_of = closed_end_path(energy)
    det = sp.diff(P, theta) * sp.diff(N, z) - sp.diff(P, z) * sp.diff(N, theta)
    P_of = sp.lambdify((theta, z), P)
    coarse = np.linspace(1.05, largest_hoop, 80)
    k = int(np.argmax([P_of(h, axial_of(h)) for h in coarse]))
    guess = (coarse[k], axial_of(coarse[k]))
    with mpmath.workdps(30):
        hoop, axial = sp.nsolve((N, det), (theta, z), guess, prec=30)
    found = pressure_maximum(material(preset), largest_hoop)
    assert abs(found.hoop - float(hoop)) <= 1e-10 and abs(found.axial - float(axial)) <= 1e-10
    assert abs(found.pressure - float(P.subs({theta: hoop, z: axial}))) <= 1e-12 * found.pressure


def test_a_tube_without_a_pressure_maximum_says_so():
    """Mooney–Rivlin with C2/C1 = 1 (μ = (1, −1), α = (2, −2)): P rises along the whole closed-end path up to
    λθ = 30 (checked on 300 points with P and N lambdified here), and pressure_maximum returns None."""
    stiff = parse_scene("[material]\nmu = [1, -1]\nalpha = [2, -2]\n").material
    P, _, axial_of = closed_end_path(symbolic_energy(stiff))
    P_of = sp.lambdify((theta, z), P)
    pressures = [P_of(h, axial_of(h)) for h in np.geomspace(1.001, 30.0, 300)]
    assert np.all(np.diff(pressures) > 0)
    assert pressure_maximum(stiff, 30.0) is None


def bulge_determinant(energy):
    """det of the period-averaged Hessian in (A, B) of e = Φ(λ1, λ2) − ½ P ρ² η' about the uniform state under
    ρ = λθ + ε A cos kS, η = λz S + ε B sin kS (λ1 = sqrt(ρ'² + η'²), λ2 = ρ), at P = Φ_2/(λθλz), divided by k²:
    a function of (λθ, λz, k). The ε² coefficient is quadratic in (cos kS, sin kS), so its mean over a period is
    half its values at kS = 0 and kS = π/2; and since λ1 − λz and λ2 − λθ are O(ε), it is that of Φ's second-order
    Taylor polynomial about (λz, λθ): derived with symbols Φ_1 … Φ_22, then the energy's derivatives put in (the
    determinant of a Gent energy, expanded whole, is beyond what SymPy simplifies in minutes)."""
    eps, A, B, k, phase, P = sp.symbols("epsilon A B k phase P", real=True)
    F1, F2, F11, F12, F22 = sp.symbols("Phi_1 Phi_2 Phi_11 Phi_12 Phi_22", real=True)
    rho, drho = theta + eps * A * sp.cos(phase), -eps * A * k * sp.sin(phase)
    deta = z + eps * B * k * sp.cos(phase)
    d1, d2 = sp.sqrt(drho**2 + deta**2) - z, rho - theta
    phi = F1 * d1 + F2 * d2 + (F11 * d1**2 + 2 * F12 * d1 * d2 + F22 * d2**2) / 2
    second = sp.diff(phi - P * rho**2 * deta / 2, eps, 2).subs(eps, 0)
    mean = (second.subs(phase, 0) + second.subs(phase, sp.pi / 2)) / 2
    det = sp.expand(sp.hessian(mean, (A, B)).det() / k**2)
    d = lambda *v: sp.diff(energy, *v)
    return det.subs({F1: d(z), F2: d(theta), F11: d(z, z), F12: d(z, theta), F22: d(theta, theta),
                     P: d(theta) / (theta * z)}), k


def dispersion_onset(energy, lengths, largest_hoop=4.0):
    """[(λθ, λz)] at the onset of the mode cos(πS/L) for each L of ``lengths``: N = 0 and ``bulge_determinant`` of
    ``energy`` at k = π/L, solved at 30 digits from the first sign change + → − on a coarse scan up to
    ``largest_hoop``."""
    _, N, axial_of = closed_end_path(energy)
    det, k = bulge_determinant(energy)
    onsets = []
    for length in lengths:
        det_L = det.subs(k, sp.pi / length)
        det_of = sp.lambdify((theta, z), det_L)
        coarse = np.linspace(1.05, largest_hoop, 120)
        values = [det_of(h, axial_of(h)) for h in coarse]
        j = next(j for j in range(len(coarse)) if values[j] > 0 >= values[j + 1])
        with mpmath.workdps(30):
            onsets.append(sp.nsolve((N, det_L), (theta, z), (coarse[j], axial_of(coarse[j])), prec=30))
    return onsets


@pytest.mark.parametrize("preset", ["neo-Hookean", "SPOM1", "Gent"])
def test_bulge_onset_solves_the_dispersion_relation(preset):
    """The onset of the mode cos(πS/L) on tubes of length 10 and 40: bulge_onset against N = 0 and the determinant
    of the second variation derived here, solved at 30 digits from a sign change on a coarse scan."""
    energy = symbolic_energy(material(preset))
    for length, (hoop, axial) in zip((10.0, 40.0), dispersion_onset(energy, (10.0, 40.0))):
        found = bulge_onset(material(preset), length, largest_hoop=3.0)  # Gent's closed-end path ends near λθ = 6
        assert abs(found.hoop - float(hoop)) <= 1e-10 and abs(found.axial - float(axial)) <= 1e-10


def test_bulge_onset_tends_to_the_pressure_maximum():
    """λθ at the onset of cos(πS/L) minus λθ at the pressure maximum falls like 1/L² (the condition is the long-wave
    one plus Φ_1Φ_11 k²/λz, k = π/L): SPOM1, L = 10, 20, 40, 80, 160 (docs/tubes.md has the table); the ratio of
    successive gaps is 4 within 1 % from L = 20 on, and the onset pressure approaches the maximum from below."""
    spom1 = material("SPOM1")
    peak = pressure_maximum(spom1)
    onsets = [bulge_onset(spom1, length) for length in (10.0, 20.0, 40.0, 80.0, 160.0)]
    gaps = np.array([o.hoop - peak.hoop for o in onsets])
    assert np.all(gaps > 0) and np.all([o.pressure < peak.pressure for o in onsets])
    assert np.all(np.abs(gaps[1:-1] / gaps[2:] - 4) < 0.04)


@pytest.mark.parametrize("voltage", [0.0, 0.1])
def test_maxwell_pressure_is_the_equal_area_rule(voltage):
    """SPOM1's Maxwell pressure (maxwell_pressure: equal energies e(a) = e(b) of the two uniform states) against the
    equal-area rule written here: along N = 0, ∫_a^b (P − P_M) dv = 0 with v = λθ²λz, dv/dλθ = 2λθλz + λθ² dλz/dλθ
    and dλz/dλθ = −N_θ/N_z (from the energy derived here), by Gauss–Legendre on the pieces between a, the pressure
    maximum, the minimum and b. The integral's derivative in P_M is −(v_b − v_a) (P = P_M at both ends), so the
    rule's own P_M is P_M + ∫(P − P_M) dv/(v_b − v_a): the same to 1e-12 relative (measured 6e-16, 2e-16 under the
    voltage; 40 and 120 nodes per piece agree); a and b at P_M; neo-Hookean (P falls throughout beyond its maximum)
    has none. Under the voltage Φ̄ = 0.1 (model/membrane.Charged: the effective energy Φ − Φ̄²λ1²λ2², written here)
    the same rule holds with P_M = 0.2590 (0.4450 without), b at λθ = 14.6 (11.0)."""
    spom1 = material("SPOM1")
    energy_of = spom1 if voltage == 0 else Charged(spom1, voltage)
    found, a, b = maxwell_pressure(energy_of)
    assert abs(a.pressure - found) <= 1e-12 and abs(b.pressure - found) <= 1e-12 and a.hoop < 1.2 < 10 < b.hoop
    energy = symbolic_energy(spom1) - sp.Rational(repr(voltage)) ** 2 * theta**2 * z**2
    cuts = [a.hoop, pressure_maximum(energy_of).hoop, 3.0, pressure_minimum(energy_of).hoop, b.hoop]
    signed, absolute = equal_area_integral(energy, found, cuts)
    assert abs(signed) <= 1e-9 * absolute
    equal_area = found + signed / (b.hoop**2 * b.axial - a.hoop**2 * a.axial)
    assert abs(equal_area - found) <= 1e-12 * found
    assert maxwell_pressure(material("neo-Hookean")) is None
