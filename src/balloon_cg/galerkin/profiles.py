"""Deformed shapes and stretches of points X = (u, P) on a discretisation, vectorised over points (MODEL.md §1, §6).

From the Legendre series λ2(θ), η(θ) of every point:
    λ2' = −sin θ dλ2/dx,   η' = −sin θ dη/dx   (x = cos θ),
    ρ = λ2 sin θ,          λ1 = sqrt((λ2 cos θ + λ2' sin θ)² + η'²)/S'   (= sqrt(ρ'² + η'²)/S'),
S' = dS/dθ of the reference meridian (model/meridian.py: 1 on the sphere). At the poles λ2' = η' = 0, so
λ1 = λ2 there. η is measured from the centre of the reference surface.
"""
import numpy as np

from ..model import meridian
from ..scene.tables import Geometry


EQUATOR = np.array([0.5 * np.pi])


def theta_grid(points: int) -> np.ndarray:
    """The stored θ grid: ``points`` values linspace(0, π)."""
    return np.linspace(0.0, np.pi, points)


def fields(disc, U: np.ndarray, theta: np.ndarray):
    """(λ2, λ2', η, η') for unknowns U (n_points × disc.size), each of shape (n_points, len(theta))."""
    return disc.evaluate(np.atleast_2d(U), theta)


def meridional_stretch(theta, lam2, dlam2, deta, geometry: Geometry = Geometry()):
    """λ1 = sqrt((λ2 cos θ + λ2' sin θ)² + η'²)/S' on the reference ``geometry``."""
    c, s = np.cos(theta), np.sin(theta)
    return meridian.meridional_stretch(geometry, c, s, lam2, dlam2 * s, deta)


def profiles(disc, X: np.ndarray, theta: np.ndarray, geometry: Geometry = Geometry()) -> dict:
    """λ1, λ2, ρ = λ2 R (R = sin θ but on a capsule: model/meridian.py) and η on ``theta`` for the rows X = (u, P) of points on ``disc`` (a scene of reference
    ``geometry``).

    Each array has shape (n_points, len(theta)).
    """
    lam2, dlam2, eta, deta = fields(disc, np.atleast_2d(X)[:, :-1], theta)
    return {
        "lam1": meridional_stretch(theta, lam2, dlam2, deta, geometry),
        "lam2": lam2,
        "rho": lam2 * meridian.hoop(geometry, np.cos(theta), np.sin(theta)),
        "eta": eta,
    }


def equator_values(disc, X: np.ndarray, geometry: Geometry = Geometry()) -> dict:
    """λ1(π/2) = sqrt(λ2'² + η'²)/S' and λ2(π/2) for the rows X = (u, P) of points on ``disc``: arrays
    'lam1_equator', 'lam2_equator'."""
    lam2, dlam2, _, deta = fields(disc, np.atleast_2d(X)[:, :-1], EQUATOR)
    return {
        "lam1_equator": meridional_stretch(EQUATOR, lam2, dlam2, deta, geometry)[:, 0],
        "lam2_equator": lam2[:, 0],
    }
