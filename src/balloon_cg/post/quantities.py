"""What users look at (MODEL.md §6): stresses, wrinkling, the applied field on the surface, Gaussian curvature.

Every quantity is evaluated from the stored unknowns of a point (λ2 = Σ a_k P_k(s), η = Σ b_k P_k(s),
s = x = cos θ, or s = h(x) for a branch stored with a coordinate map; a capsule's piecewise basis φ_k, each element
a Legendre series in its own coordinate: galerkin/elements.py) on a θ grid, poles included. θ-derivatives by the
chain rule, regular at the poles, with R(θ) the reference hoop radius (model/meridian.py: sin θ on a sphere):

    d/dθ = −sin θ d/dx,    d²/dθ² = sin²θ d²/dx² − cos θ d/dx,
    ρ = λ2 R,   ρ' = λ2' R + λ2 R',   ρ'' = λ2'' R + 2 λ2' R' + λ2 R'',
    s' = sqrt(ρ'² + η'²) (the deformed arclength per dθ),   λ1 = s'/S'
(S' = dS/dθ of the reference meridian, model/meridian.py: 1 on the sphere, where λ1 = s').

Geometry (t, n unit tangent along increasing θ and outward normal in the (e_ρ, e_z) plane):

    t = (ρ', η')/s',   n = (−η', ρ')/s'          (on a sphere n = (sin θ, cos θ), away from the centre),
    k_m = −(ρ'η'' − ρ''η')/s'³                   meridian curvature,
    k_p = −η'/(ρ s') = (dη/dx)(sin θ/R)/(λ2 s')   parallel curvature (sin θ/R → 1/|R'| at a pole: no 0/0),
    κ = k_m k_p = η'(ρ'η'' − ρ''η')/(ρ (ρ'² + η'²)²)  Gaussian curvature (κ R0²);

both principal curvatures are 1/λ on a sphere of radius λ, and at a pole k_p = k_m, so κ there is the square of
the meridian curvature. Stresses are Cauchy stresses in units of μ/2 (the moduli's units, MODEL.md §2); the
applied field h is in units of I/(4π R0) (MODEL.md §3), so that M H² is the nondimensional magnetic energy scale.
"""
import numpy as np
from numpy.polynomial import legendre

from ..galerkin.coordinate_map import WireMap
from ..galerkin.discretisation import Discretisation
from ..galerkin.elements import cylinder_coordinates, element_series, layout
from ..model.field import coaxial_table, coil_table, field_components, field_squared_nodes
from ..model.stresses import elastic_stresses
from ..model.meridian import hoop, hoop_acceleration, hoop_rate, metric
from ..io.run_file import stored_scene
from ..scene.tables import Geometry, Shape

WRINKLING_STATES = ("taut", "wrinkled", "slack")


def branch_discretisation(branch: dict) -> Discretisation:
    """The Discretisation of a stored branch (a read_run() branch dict) from its attrs degree, symmetric,
    pin_translation, quadrature (0: automatic), the coordinate map (map_centres, map_widths; empty: none) and a
    capsule's joins (empty, or absent in files before its piecewise basis: the Legendre basis) and its graded
    element degrees (absent: shared), and the surface whose area centroid a held general basis holds (held_shape,
    held_size: a spheroid's aspect, a capsule's length; absent: the sphere's hold, b_0 = 0): it evaluates the
    unknowns."""
    attrs = branch["attrs"]
    centres = tuple(float(c) for c in attrs.get("map_centres", ()))
    mapping = WireMap(centres, tuple(float(w) for w in attrs["map_widths"])) if centres else None
    return Discretisation(int(attrs["degree"]), bool(attrs["symmetric"]), bool(attrs["pin_translation"]),
                          int(attrs.get("quadrature", 0)), mapping, tuple(float(x) for x in attrs.get("joins", ())),
                          tuple(int(d) for d in attrs.get("element_degrees", ())),
                          held_geometry(attrs))


def held_geometry(attrs) -> Geometry | None:
    """``Discretisation.held`` from a stored branch's held_shape and held_size (absent: None)."""
    if "held_shape" not in attrs:
        return None
    shape, size = Shape(str(attrs["held_shape"])), float(attrs["held_size"])
    return Geometry(shape, size) if shape == Shape.SPHEROID else Geometry(shape, length=size)


def _legendre_derivatives(coefficients, c, s, mapping):
    """(f, f', f'', df/dx) in θ of f = Σ c_k P_k(s), s = h(cos θ) (f_x = f_s h', f_xx = f_ss h'² + f_s h'')."""
    arg = c if mapping is None else np.clip(mapping.s(c), -1.0, 1.0)
    ds = 1.0 if mapping is None else mapping.ds_dx(c)
    d2s = 0.0 if mapping is None else mapping.d2s_dx2(c)
    f, fs, fss = (legendre.legval(arg, legendre.legder(coefficients, m)) for m in range(3))
    fx, fxx = fs * ds, fss * ds * ds + fs * d2s
    return f, -s * fx, s * s * fxx - c * fx, fx


def _element_derivatives(coefficients, c, s, joins: tuple, degrees: tuple = ()):
    """(f, f', f'', df/dx) in θ of f = Σ c_k φ_k (rows of ``coefficients``) on a capsule's elements
    (galerkin/elements.py: ``element_series``): on cylinder element e, t linear in θ, f' = f_t t', f'' = f_tt t'²,
    f_x = −f'/sin θ; on the caps ξ = (2|x| − 1 − c)/(1 − c), f_x = f_ξ ξ_x, f_xx = f_ξξ ξ_x², then θ by the chain
    rule as on Legendre's. The caps' joins belong to the cylinder, an inner boundary to its northern element
    (one-sided derivatives)."""
    shape = layout(joins)
    join = shape.join
    cylinder, north = np.abs(c) <= join, c > join
    rows = [element_series(row, joins, degrees) for row in np.atleast_2d(coefficients)]

    def derivatives(series, at):
        """f, f_t, f_tt of the rows' ``series`` (rows, top) at ``at``."""
        return (legendre.legval(at, legendre.legder(series.T, m)) for m in range(3))

    element, t, _ = cylinder_coordinates(np.where(cylinder, c, 0.0), shape)
    bounds = np.array(shape.bounds)
    out = [np.zeros((len(rows), c.size)) for _ in range(4)]
    for e in range(shape.count):
        on = cylinder & (element == e)
        f, ft, ftt = derivatives(np.array([row[1][e] for row in rows]), t)
        rate = -2.0 / ((bounds[e + 1] - bounds[e]) * shape.half_span)  # dt/dθ
        for target, part in zip(out, (f, ft * rate, ftt * rate**2, -ft * rate / np.where(cylinder, s, 1.0))):
            target[..., on] = part[..., on]
    xi_cap = (2.0 * np.abs(c) - 1.0 - join) / (1.0 - join)
    for element_index, on, sign in ((0, north, 1.0), (2, ~(north | cylinder), -1.0)):
        f, fxi, fxixi = derivatives(np.array([row[element_index] for row in rows]), xi_cap)
        rate = 2.0 * sign / (1.0 - join)
        fx, fxx = fxi * rate, fxixi * rate**2
        for target, part in zip(out, (f, -s * fx, s * s * fxx - c * fx, fx)):
            target[..., on] = part[..., on]
    return tuple(out)


def surface(disc: Discretisation, X, theta, geometry: Geometry = Geometry()) -> dict:
    """Shape, stretches and principal curvatures (module docstring) for the rows X = (u, P) on ``theta`` of a
    scene of reference ``geometry`` (a sphere, a spheroid, a capsule on its piecewise basis).

    Keys lam1, lam2, rho, eta, drho, deta (θ-derivatives), speed (s'), k_meridian, k_parallel,
    gaussian_curvature (κ), radius (the reference R); each array has shape (n_points, len(theta)).
    """
    a, b = (np.array(c).T for c in zip(*(disc.split(row) for row in np.atleast_2d(X)[:, : disc.size])))
    c, s = np.cos(theta), np.sin(theta)
    if disc.joins:
        lam2, dlam2, d2lam2, _ = _element_derivatives(a.T, c, s, disc.joins, disc.element_degrees)
        eta, deta, d2eta, deta_dx = _element_derivatives(b.T, c, s, disc.joins, disc.element_degrees)
    else:
        lam2, dlam2, d2lam2, _ = _legendre_derivatives(a, c, s, disc.mapping)
        eta, deta, d2eta, deta_dx = _legendre_derivatives(b, c, s, disc.mapping)
    radius, radius_rate = hoop(geometry, c, s), hoop_rate(geometry, c, s)
    rho = lam2 * radius
    drho = dlam2 * radius + lam2 * radius_rate
    d2rho = d2lam2 * radius + 2 * dlam2 * radius_rate + lam2 * hoop_acceleration(geometry, c, s)
    speed = np.hypot(drho, deta)
    k_meridian = -(drho * d2eta - d2rho * deta) / speed**3
    # sin θ/R, its limit 1/|R'| at a pole (R = 0): −η'/ρ = (dη/dx)(sin θ/R)/λ2 without 0/0
    ratio = np.divide(s, radius, out=1.0 / np.maximum(np.abs(radius_rate), 1e-300), where=radius > 0)
    k_parallel = deta_dx * ratio / (lam2 * speed)
    return {
        "lam1": speed / metric(geometry, c, s), "lam2": lam2, "rho": rho, "eta": eta, "drho": drho, "deta": deta,
        "speed": speed,
        "k_meridian": k_meridian, "k_parallel": k_parallel,
        "gaussian_curvature": k_meridian * k_parallel,
        "radius": np.broadcast_to(radius, lam2.shape),
    }


def surface_field(coils, geometry: dict) -> dict:
    """Applied field on the deformed surface (units of I/(4π R0)); coils are rows (radius, height, current).

    h_rho, h_z: h at (ρ, η); H_theta = h·t, H_zeta = h·n (meridional tangent, outward normal, so that
    H_θ² + H_ζ² = H²); H2 = H²; dH2_drho = ∂(H²)/∂ρ at fixed η. Raises FieldError where the surface reaches
    a wire.
    """
    table = coil_table(np.reshape(coils, (-1, 3)))
    rho, eta = geometry["rho"], geometry["eta"]
    h_rho, h_z = field_components(rho, eta, table)
    derivatives = np.empty((6, rho.size))
    field_squared_nodes(np.ascontiguousarray(rho.ravel()), np.ascontiguousarray(eta.ravel()), table, derivatives)
    t_rho, t_z = geometry["drho"] / geometry["speed"], geometry["deta"] / geometry["speed"]
    return {
        "h_rho": h_rho, "h_z": h_z,
        "H_theta": h_rho * t_rho + h_z * t_z,
        "H_zeta": -h_rho * t_z + h_z * t_rho,
        "H2": h_rho**2 + h_z**2,
        "dH2_drho": derivatives[1].reshape(rho.shape),
    }


def paper_magnetic_stresses(M: float, chi: float, radius, lam2, field: dict):
    """The paper's magnetic additions to (σ_θ, σ_φ) (its Cauchy stress section), taken as written:

    Δσ_θ = (1 + χ) M H_θ² − ½ M H²,    Δσ_φ = ½ λ2 χ M ∂(H²)/∂λ2 − ½ M H²,    ∂(H²)/∂λ2 = R ∂(H²)/∂ρ
    (at fixed θ, ρ = λ2 R, R the reference hoop radius ``radius``: sin θ on a sphere). Its factors are not consistent with the energy of MODEL.md §2 (the paper
    switches between ½ χ M H² and χ M H², and calls these stresses nondimensional "with shear modulus μ" while
    its moduli are in units of μ/2), so the terms are reported on their own, next to the elastic stresses,
    never added to them.
    """
    half = 0.5 * M * field["H2"]
    return (
        (1.0 + chi) * M * field["H_theta"] ** 2 - half,
        0.5 * lam2 * chi * M * radius * field["dH2_drho"] - half,
    )


def wrinkling(sigma_theta, sigma_phi) -> np.ndarray:
    """Tension-field state per entry: 'taut' (both principal stresses > 0), 'wrinkled' (one ≤ 0), 'slack'
    (both ≤ 0)."""
    compressed = (np.asarray(sigma_theta) <= 0).astype(int) + (np.asarray(sigma_phi) <= 0)
    return np.array(WRINKLING_STATES)[compressed]


def quantities(scene, disc: Discretisation, X, theta, M: float | None = None, chi: float | None = None) -> dict:
    """Everything of MODEL.md §6 for the rows X = (u, P) of a branch of ``scene`` on ``theta``.

    The keys of surface() and surface_field(), plus (arrays of shape (n_points, len(theta))):
    sigma_theta, sigma_phi: elastic stresses; sigma_theta_paper, sigma_phi_paper: the paper's magnetic additions
    alone (paper_magnetic_stresses); wrinkling: state from the elastic stresses; wrinkling_paper: from elastic
    plus the paper's additions; lam1_below_one: the paper's wrinkling sign λ1 < 1. Also theta and pressure.
    M and χ default to the scene's.
    """
    theta = np.asarray(theta, dtype=float)
    X = np.atleast_2d(X)
    M = scene.field.M if M is None else M
    chi = scene.field.chi if chi is None else chi
    geometry = surface(disc, X, theta, scene.geometry)
    field = surface_field(coaxial_table(scene.field.coils), geometry)
    sigma_theta, sigma_phi = elastic_stresses(scene.material, geometry["lam1"], geometry["lam2"])
    extra_theta, extra_phi = paper_magnetic_stresses(M, chi, geometry["radius"], geometry["lam2"], field)
    return {
        "theta": theta,
        "pressure": X[:, -1],
        **geometry,
        **field,
        "sigma_theta": sigma_theta,
        "sigma_phi": sigma_phi,
        "sigma_theta_paper": extra_theta,
        "sigma_phi_paper": extra_phi,
        "wrinkling": wrinkling(sigma_theta, sigma_phi),
        "wrinkling_paper": wrinkling(sigma_theta + extra_theta, sigma_phi + extra_phi),
        "lam1_below_one": geometry["lam1"] < 1.0,
    }


def postprocess(run: dict, branch: str = "primary", points=None, theta=None) -> dict:
    """quantities() for stored points of a run (read_run() output): all points, or the indices ``points``.

    θ defaults to the branch's stored grid; M and χ come from the branch attrs. Adds 'points' (the indices);
    'pressure' (and 'voltage' where the dielectric term is present) are the stored columns (the last unknown is
    Φ̄ on a voltage branch).
    """
    data = run["branches"][branch]
    index = np.arange(len(data["pressure"])) if points is None else np.asarray(points, dtype=int)
    result = quantities(
        stored_scene(run), branch_discretisation(data), data["unknowns"][index],
        data["theta"] if theta is None else theta, float(data["attrs"]["M"]), float(data["attrs"]["chi"]),
    )
    stored = {name: data[name][index] for name in ("pressure", "voltage") if name in data}
    return result | stored | {"points": index}
