"""Deformed shapes and stretches of points X = (u, P) on a discretisation, vectorised over points (MODEL.md §1, §6).

From the Legendre series λ2(θ), η(θ) of every point:
    λ2' = −sin θ dλ2/dx,   η' = −sin θ dη/dx   (x = cos θ),
    ρ = λ2 sin θ,          λ1 = sqrt((λ2 cos θ + λ2' sin θ)² + η'²)   (= sqrt(ρ'² + η'²)).
At the poles λ2' = η' = 0, so λ1 = λ2 there. η is measured from the centre of the undeformed sphere.
"""
import numpy as np


EQUATOR = np.array([0.5 * np.pi])


def theta_grid(points: int) -> np.ndarray:
    """The stored θ grid: ``points`` values linspace(0, π)."""
    return np.linspace(0.0, np.pi, points)


def fields(disc, U: np.ndarray, theta: np.ndarray):
    """(λ2, λ2', η, η') for unknowns U (n_points × disc.size), each of shape (n_points, len(theta))."""
    return disc.evaluate(np.atleast_2d(U), theta)


def meridional_stretch(theta, lam2, dlam2, deta):
    """λ1 = sqrt((λ2 cos θ + λ2' sin θ)² + η'²)."""
    return np.hypot(lam2 * np.cos(theta) + dlam2 * np.sin(theta), deta)


def profiles(disc, X: np.ndarray, theta: np.ndarray) -> dict:
    """λ1, λ2, ρ = λ2 sin θ and η on ``theta`` for the rows X = (u, P) of points on ``disc``.

    Each array has shape (n_points, len(theta)).
    """
    lam2, dlam2, eta, deta = fields(disc, np.atleast_2d(X)[:, :-1], theta)
    return {
        "lam1": meridional_stretch(theta, lam2, dlam2, deta),
        "lam2": lam2,
        "rho": lam2 * np.sin(theta),
        "eta": eta,
    }


def equator_values(disc, X: np.ndarray) -> dict:
    """λ1(π/2) = sqrt(λ2'² + η'²) and λ2(π/2) for the rows X = (u, P) of points on ``disc``: arrays
    'lam1_equator', 'lam2_equator'."""
    lam2, dlam2, _, deta = fields(disc, np.atleast_2d(X)[:, :-1], EQUATOR)
    return {
        "lam1_equator": meridional_stretch(EQUATOR, lam2, dlam2, deta)[:, 0],
        "lam2_equator": lam2[:, 0],
    }
