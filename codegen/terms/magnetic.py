"""The magnetic term of a soft magnetic membrane in the field of the coils (MODEL.md §2, §8):

    π += −½ χ M H²(x),

H² at the deformed point. H² is not symbolic: the runtime's field kernels supply its value and derivatives at
the node, so the term carries a second-order Taylor proxy of H² about the node's point, in (ρ, η) for the
axisymmetric kernels (rows FIELD) and in (x, y, z) on the whole sphere (rows SURFACE_FIELD), whose expansion point
is put back after differentiation: exact for every derivative of order ≤ 2, which is all the kernels use.
Continued in M: field_gradient, rhs_field, surface_field_gradient; χ is a runtime parameter too.
"""
from dataclasses import dataclass

import sympy as sp

from ..functional import eta, lam2, sin_theta
from ..kernels import Arg
from ..second_variation import eps, epsilon_order, phi_average
from . import Term

M, chi = sp.symbols("M chi", real=True)
# H² and its derivatives in (ρ, η) at the node
Q, Q_r, Q_z, Q_rr, Q_rz, Q_zz = FIELD = sp.symbols("Q Q_r Q_z Q_rr Q_rz Q_zz", real=True)
_rho0, _eta0 = sp.symbols("rho0 eta0", real=True)
# H² and its derivatives in (x, y, z) at a surface node
SURFACE_FIELD = sp.symbols("Q Q_x Q_y Q_z Q_xx Q_xy Q_xz Q_yy Q_yz Q_zz", real=True)
_X0 = sp.symbols("x0 y0 z0", real=True)
# H²_η and H²_ρρ on the axis at the north and south poles (the pole series' field)
POLE_FIELD = {letter: sp.symbols(f"Q_z_{letter} Q_rr_{letter}", real=True) for letter in "NS"}


def field_proxy(rho, z):
    """H² near (ρ0, η0): Q + Q_r δρ + Q_z δη + ½(Q_rr δρ² + Q_zz δη²) + Q_rz δρ δη (rows FIELD)."""
    dr, dz = rho - _rho0, z - _eta0
    return Q + Q_r * dr + Q_z * dz + (Q_rr * dr**2 + Q_zz * dz**2) / 2 + Q_rz * dr * dz


def surface_field_proxy(point):
    """H² near (x0, y0, z0): Q + Σ Q_i δ_i + ½ Σ Q_ii δ_i² + Σ_{i<j} Q_ij δ_i δ_j (rows SURFACE_FIELD)."""
    dx = [p - p0 for p, p0 in zip(point, _X0)]
    Q0, Qx, Qy, Qz, Qxx, Qxy, Qxz, Qyy, Qyz, Qzz = SURFACE_FIELD
    first = Qx * dx[0] + Qy * dx[1] + Qz * dx[2]
    second = (Qxx * dx[0] ** 2 + Qyy * dx[1] ** 2 + Qzz * dx[2] ** 2) / 2
    mixed = Qxy * dx[0] * dx[1] + Qxz * dx[0] * dx[2] + Qyz * dx[1] * dx[2]
    return Q0 + first + second + mixed


@dataclass(frozen=True)
class MagneticField(Term):
    name = "magnetic"
    parameters = (M, chi)
    continuation = (M, "field", "M")

    def axisymmetric(self, c, s, metric):
        return -chi * M * field_proxy(lam2 * s, eta) / 2 * metric

    def surface(self, point, a_t, a_p, areal):
        return -chi * M * surface_field_proxy(point) / 2

    def second_order(self, x, x_t, x_p, metric, closed=True):
        """H²(|x_h|, z) with |x_h| = √(x² + y²) expanded to O(ε²) about ρ0 = λ2 sin θ: with x² + y² = ρ0² + ε q1 +
        ε² q2, |x_h| = ρ0 + ε q1/(2ρ0) + ε² (q2/(2ρ0) − q1²/(8ρ0³))."""
        rho_sq = x[0] ** 2 + x[1] ** 2
        rho0 = lam2 * sin_theta
        q1, q2 = epsilon_order(rho_sq, 1), epsilon_order(rho_sq, 2)
        radius = rho0 + eps * q1 / (2 * rho0) + eps**2 * (q2 / (2 * rho0) - q1**2 / (8 * rho0**3))
        H2 = sp.expand(field_proxy(radius, x[2])).subs(self.expansion(sin_theta))
        return -chi * M * phi_average(epsilon_order(H2, 2)) / 2 * metric

    def pole(self, lam, z, q, s, z0, metric):
        """H² = Q + H²_η (η − η0) + ½ H²_ρρ ρ² near the axis (H²_ρ = H²_ρη = 0 there, H² even in ρ)."""
        return -chi * M * (Q + Q_z * (z - z0) + Q_rr * (lam * s) ** 2 / 2) * s / 2 * metric

    def pole_values(self, letter: str) -> dict:
        return dict(zip((Q_z, Q_rr), POLE_FIELD[letter]))

    def expansion(self, radius) -> dict:
        """The node's point (ρ0, η0) = (λ2 R, η): R = sin θ on a meridian with poles, 1 on a tube."""
        return {_rho0: lam2 * radius, _eta0: eta}

    def surface_expansion(self, point) -> dict:
        return dict(zip(_X0, point))

    def rows(self) -> tuple:
        return (Arg.node_rows("field", FIELD),)

    def pole_rows(self) -> tuple:
        return (Arg.param_array("pole_field", POLE_FIELD["N"] + POLE_FIELD["S"]),)

    def surface_rows(self) -> tuple:
        return (Arg.node_rows("field", SURFACE_FIELD),)

    def inputs(self) -> dict:
        return {"field": True}


MAGNETIC = MagneticField()
