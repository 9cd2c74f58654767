"""Real spherical harmonics for the Cartesian displacement of the whole sphere (MODEL.md §8), at Gauss–Legendre ×
uniform nodes: the node values the surface kernels take, and the residual and Hessian assembled from theirs.

    u_c(θ, φ) = Σ c_{c,l,m,t} Y_{l,m,t}(θ, φ),   Y_{l,m,t} = P̄_l^m(cos θ) τ_{m,t}(φ),
    τ_{0,cos} = 1/√(2π),  τ_{m,cos} = cos mφ/√π,  τ_{m,sin} = sin mφ/√π,

c = x, y, z, l ≤ L (orthonormal on the unit sphere, dA = d(cos θ) dφ). A smooth vector field has smooth Cartesian
components, so every coefficient vector is a smooth surface: no pole condition to impose. At a node the kernels
take x = X + u, a_θ = ∂x/∂θ and a_φ = ∂x/∂φ / sin θ (rows ``SURFACE_STATE``), and E = (1/2π) ∫∫ π dA becomes
Σ_j Σ_k (w_j / N_φ) π(θ_j, φ_k).

The unknowns come in *blocks* (component c, order m, type t; degrees l): inside a block every unknown has the same
φ-dependence, so the Hessian is assembled by sum factorisation, not nodes × unknowns²:

    H[(b, l), (b', l')] = Σ_{d, d'} Σ_j Θ^d_b[j, l] T^{dd'}_j[b, b'] Θ^{d'}_{b'}[j, l'],
    T^{dd'}_j[b, b'] = Σ_k W_j D_{(c,d),(c',d')}(θ_j, φ_k) p^d_b(φ_k) p^{d'}_{b'}(φ_k),

d ∈ (value, ∂θ, ∂φ/sin θ), Θ^d_b the θ-tables (P̄, dP̄/dθ, m P̄/sin θ) and p^d_b the φ-functions (τ, or ∂φτ/m).
T comes from one FFT in φ per ring of each of the 45 node-Hessian entries D and the product-to-sum identities
(cos a cos b = ½[cos(a − b) + cos(a + b)], …), exact for the discrete sums at any N_φ (frequencies alias mod N_φ).

Symmetry subspaces: ``symmetry`` is a tuple of diagonal reflections S = diag(s_x, s_y, s_z) and ``characters``
one sign χ_S each (default +1); the basis keeps the fields with u(S X) = χ_S S u(X), i.e. the e_c Y_{l,m,t} with
s_c σ_S(l, m, t) = χ_S, σ the sign of Y under S: y → −y flips sin mφ, x → −x multiplies cos mφ by (−1)^m and
sin mφ by −(−1)^m, z → −z multiplies by (−1)^(l+m) (the rotation by π about the axis, diag(−1, −1, 1), is
diagonal too: it multiplies Y_{l,m,t} by (−1)^m). The states of a branch lie in the invariant subspace (every
χ = +1); the Hessian at such a state maps each sector (a choice of the χ) to itself, so its spectrum is the union
of the sectors' (``sectors``).
"""
import functools
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
from numba import njit
from scipy.linalg import lapack

from ..galerkin.discretisation import read_only
from ..galerkin.legendre import gauss_rule, legendre_values, theta_derivative

COS, SIN = 0, 1
MIRROR_Y = (1, -1, 1)  # the plane y = 0 through the axis (MODEL.md §8: x, z keep cos kφ, y keeps sin kφ)
EQUATOR = (1, 1, -1)  # the equatorial plane z = 0
INVERSION = (-1, -1, -1)  # the centre: x(−X) = −x(X)
HALF_TURN = (-1, -1, 1)  # the rotation by π about the axis: C_2 ⊂ C_m, kept by the branches of an even-m mode
STATE_ROWS = 9  # x (3), a_θ (3), a_φ (3): row 3 d + c for derivative d and component c
SHARED_TABLE = 4096  # up to this many points the Legendre tables of an order are cached (the blocks share them)
POLE_ZONE = 1e-10  # sin²θ below which a mapped basis' dθ_s/dθ takes its pole limit (relative error ~ POLE_ZONE)


def _sign_under(reflection, l, m, t) -> int:
    """σ_S(l, m, t): Y_{l,m,t}(S X) = σ Y_{l,m,t}(X) for the diagonal reflection S."""
    sx, sy, sz = reflection
    sign = 1
    if sy < 0 and t == SIN:
        sign = -sign
    if sx < 0:
        sign *= (-1) ** m * (1 if t == COS else -1)
    if sz < 0:
        sign *= (-1) ** (l + m)
    return sign


@dataclass(frozen=True)
class Block:
    """The unknowns of component ``component`` with φ-dependence τ_{m,t}: degrees ``degrees``, at ``offset``."""

    component: int
    m: int
    t: int
    degrees: tuple
    offset: int

    @property
    def slice(self) -> slice:
        return slice(self.offset, self.offset + len(self.degrees))


@dataclass(frozen=True)
class SphericalBasis:
    """Degree ``degree`` (L), the largest azimuthal order ``order`` (M ≤ L, default L: every harmonic of degree
    ≤ L), the reflections ``symmetry`` the fields keep, n_theta × n_phi nodes (default ⌈3(L + 1)/2⌉ + 2 Gauss nodes
    and 2(⌈3(M + 1)/2⌉ + 2) in φ: the products of two fields with a smooth node function are integrated with
    aliasing below the truncation error of resolved states).

    ``mapping`` (a galerkin.coordinate_map.WireMap, as the axisymmetric solver picks near a coil wire): the
    harmonics are those of the mapped polar coordinate s = h(cos θ), P̄_l^m(s) τ_{m,t}(φ), smooth on the sphere
    since (1 − s²)/(1 − cos²θ) is smooth and positive (h' > 0 at the poles); Gauss nodes in s, weights
    w_j / h'(x_j), and each block's functions orthonormalised in the quadrature's inner product (Cholesky of its
    Gram matrix), so that the coefficients stay orthonormal and the spectral tail stays the last coefficients'.

    ``aspect`` (c, default 1: the unit sphere): the reference surface is the spheroid X = (sin θ cos φ, sin θ sin φ,
    c cos θ) of equatorial semi-axis 1 (scene.Geometry), the same poles and polar coordinate, so the same harmonics
    (a smooth field on the spheroid is smooth on the sphere: X is a linear image of it); only the reference rows
    of the node state change, A_θ = (cos θ cos φ, cos θ sin φ, −c sin θ) of length S'(θ) = √(cos²θ + c² sin²θ)
    (``nodes['rate']``) and A_φ/sin θ = e_φ."""

    degree: int
    symmetry: tuple = ()
    characters: tuple = ()
    n_theta: int = 0
    n_phi: int = 0
    order: int = -1
    mapping: object = None
    aspect: float = 1.0
    blocks: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        if self.degree < 1:
            raise ValueError(f"degree = {self.degree}: must be ≥ 1")
        put = object.__setattr__
        if not self.characters:
            put(self, "characters", (1,) * len(self.symmetry))
        if len(self.characters) != len(self.symmetry):
            raise ValueError(f"{len(self.characters)} characters for {len(self.symmetry)} reflections")
        if self.order < 0:
            put(self, "order", self.degree)
        if not 0 <= self.order <= self.degree:
            raise ValueError(f"order = {self.order}: must lie in [0, degree = {self.degree}]")
        if not self.n_theta:
            put(self, "n_theta", (3 * (self.degree + 1) + 1) // 2 + 2)
        if not self.n_phi:
            put(self, "n_phi", 2 * ((3 * (self.order + 1) + 1) // 2 + 2))
        if not self.aspect > 0.0:
            raise ValueError(f"aspect = {self.aspect}: must be > 0 (the reference spheroid's polar semi-axis)")
        symmetry = tuple(map(tuple, self.symmetry))
        put(self, "blocks", _blocks(self.degree, self.order, symmetry, tuple(self.characters)))

    @property
    def size(self) -> int:
        return self.blocks[-1].offset + len(self.blocks[-1].degrees) if self.blocks else 0

    def reflection_signs(self, reflection: tuple) -> np.ndarray:
        """Per coefficient, the sign s_c σ_S(l, m, t) of its e_c Y_{l,m,t} in the image S u(S X) of a field u under
        the diagonal reflection S (exact on the coefficients where S keeps the polar coordinate's map: no map, or
        s_z = +1)."""
        return np.array([reflection[b.component] * _sign_under(reflection, l, b.m, b.t)
                         for b in self.blocks for l in b.degrees], dtype=float)

    @property
    def relabellings(self) -> tuple:
        """The axes k whose material rotations, X ↦ X + ε e_k × X, map the reference onto itself (relabellings
        of every surface: zero modes of every energy): each axis on the sphere, the axis z on a spheroid."""
        return (0, 1, 2) if self.aspect == 1.0 else (2,)

    def sectors(self) -> list:
        """The bases of every choice of characters for this basis' reflections (same degree and nodes): their
        spaces together are the whole space, and a Hessian at a state of the invariant subspace is block-diagonal
        in them; the sector of this basis' own characters is this basis (its tables and products serve both). Built
        once per basis (their tables are reused)."""
        return _sectors(self)

    @cached_property
    def nodes(self) -> dict:
        """cos θ_j, sin θ_j, the weights W_j = w_j/N_φ (with E's 1/2π), φ_k, S'(θ_j) (``rate``: the reference's
        |A_θ|), and X, a_θ(X), a_φ(X) at every node (rows of the node state of u = 0), node index j N_φ + k."""
        mapped, w = gauss_rule(self.n_theta)
        mapped, w = mapped[::-1].copy(), w[::-1].copy()  # θ increasing: north to south
        if self.mapping is None:
            x = mapped
        else:
            x = self.mapping.x(mapped)
            w = w / self.mapping.ds_dx(x)
        s = np.sqrt(1.0 - x * x)
        phi = 2.0 * np.pi * np.arange(self.n_phi) / self.n_phi
        C, S = np.meshgrid(x, np.cos(phi), indexing="ij")
        s2, sp = np.meshgrid(s, np.sin(phi), indexing="ij")
        c = self.aspect
        reference = np.stack([s2 * S, s2 * sp, c * C, C * S, C * sp, -c * s2, -sp, S, np.zeros_like(C)])
        rate = np.ones_like(x) if c == 1.0 else np.sqrt(x * x + (c * s) ** 2)  # the sphere's exactly 1
        return {"cos_theta": read_only(x), "sin_theta": read_only(s), "weights": read_only(w / self.n_phi),
                "mapped": read_only(mapped), "rate": read_only(rate),
                "phi": read_only(phi), "reference": read_only(reference.reshape(STATE_ROWS, -1))}

    @cached_property
    def tables(self) -> dict:
        """Per block: θ-tables Θ (3, n_theta, n_l) for value, ∂θ, ∂φ/(m sin θ)·m, and the φ-functions p (2, n_phi)
        for value and ∂φ/m; per component the concatenated θ-tables and each column's block."""
        nodes = self.nodes
        x, s, phi = nodes["cos_theta"], nodes["sin_theta"], nodes["phi"]
        theta, phis, transforms = [], [], []
        for b in self.blocks:
            p, dp = self._polar(nodes["mapped"], x, b)
            transform = self._orthonormaliser(p)
            transforms.append(transform)
            theta.append(np.stack([p, dp, b.m * p / s[:, None]]) @ transform)
            norm = _norm(b.m)
            if b.t == COS:
                phis.append(norm * np.stack([np.cos(b.m * phi), -np.sin(b.m * phi)]))
            else:
                phis.append(norm * np.stack([np.sin(b.m * phi), np.cos(b.m * phi)]))
        components = []
        for c in range(3):
            index = [i for i, b in enumerate(self.blocks) if b.component == c]
            if not index:
                components.append({"blocks": []})
                continue
            widths = np.array([len(self.blocks[i].degrees) for i in index])
            starts = np.concatenate([[0], np.cumsum(widths)]).astype(np.int64)
            block_of = np.repeat(np.arange(len(index)), widths)
            table = np.ascontiguousarray(np.concatenate([theta[i] for i in index], axis=2))  # (3, n_theta, n_c)
            components.append({
                "blocks": index,
                "theta": read_only(table),
                "starts": read_only(starts),
                "column_block": read_only(block_of),
                "sums": np.equal.outer(block_of, np.arange(len(index))).astype(float),
                "range": slice(self.blocks[index[0]].offset, self.blocks[index[-1]].slice.stop),
                "unknowns": np.arange(self.blocks[index[0]].offset, self.blocks[index[-1]].slice.stop),
                "row_ranges": list(zip(starts[:-1], starts[1:])),
                "left": [np.ascontiguousarray(table[:, :, lo:hi]).reshape(3 * self.n_theta, hi - lo)
                         for lo, hi in zip(starts[:-1], starts[1:])],
            })
        return {"theta": theta, "phi": np.array(phis), "components": components, "transforms": transforms}

    def _polar(self, mapped: np.ndarray, x: np.ndarray, block: Block) -> tuple:
        """(P̄_l^m(s), dP̄_l^m/dθ) of the block's degrees at s = h(x) (s = x unmapped), valid at the poles."""
        k = list(block.degrees)
        points = np.ascontiguousarray(mapped, dtype=float)
        p, dp = (_legendre_pair(points.tobytes(), self.degree, block.m) if points.size <= SHARED_TABLE else
                 (legendre_values(points, self.degree, block.m), theta_derivative(points, self.degree, block.m)))
        p, dp = p[:, k], dp[:, k]
        if self.mapping is not None:  # dθ_s/dθ = h'(x) sin θ / sin θ_s, → √h'(±1) at the poles
            # the limit within POLE_ZONE of a pole, where h(±1) = ±1 may be off by an ulp (0/ε otherwise)
            at_pole = np.minimum(1.0 - x * x, 1.0 - mapped * mapped) < POLE_ZONE
            ratio = np.sqrt(np.where(at_pole, 1.0 / self.mapping.ds_dx(x),
                                     (1.0 - x * x) / np.where(at_pole, 1.0, 1.0 - mapped * mapped)))
            dp = dp * (self.mapping.ds_dx(x) * ratio)[:, None]
        return p, dp

    def _orthonormaliser(self, p: np.ndarray) -> np.ndarray:
        """L⁻ᵀ of the block's Gram matrix Σ_j N_φ W_j p_l p_l' (identity unmapped: Gauss–Legendre is exact there)."""
        if self.mapping is None:
            return np.eye(p.shape[1])
        gram = (p.T * (self.nodes["weights"] * self.n_phi)) @ p
        inverse, info = lapack.dtrtri(np.linalg.cholesky(gram), lower=1)
        if info != 0:
            raise np.linalg.LinAlgError(f"the Gram matrix of a mapped block is singular (dtrtri info = {info})")
        return inverse.T

    @cached_property
    def _products(self) -> dict:
        """Gather plan of T from the φ-Fourier table of a node function: for component pair (c, c') the arrays
        (i1, i2, α1, α2), each (2, 2, n_b, n_b') by φ-types (e, e'), with T[j, b, b'] = α1 F[j, i1] + α2 F[j, i2],
        F = [C_0 … C_{N−1}, S_0 … S_{N−1}], C_q = Σ_k f_k cos qφ_k, S_q = Σ_k f_k sin qφ_k: for p^e_b ∝ cos aφ or
        sin aφ and p^{e'}_{b'} ∝ cos bφ or sin bφ, with s = (a + b) mod N and r = |a − b| mod N, cos cos: ½(C_r + C_s),
        sin sin: ½(C_r − C_s), cos sin: ½(S_s − sgn(a − b) S_r), sin cos: ½(S_s + sgn(a − b) S_r) (times the
        normalisations and signs of the p), every block pair at once."""
        n = self.n_phi
        m = np.array([b.m for b in self.blocks])
        t = np.array([b.t for b in self.blocks])
        amplitude = np.array([[_norm(b.m), _norm(b.m) if b.m else 0.0] for b in self.blocks]).T  # (e, block)
        kind = np.array([t, np.where(t == COS, SIN, COS)])  # COS or SIN of p^e (e = 0: τ, e = 1: ∂φτ/m), (e, block)
        sign = np.array([np.ones(t.size), np.where(t == COS, -1.0, 1.0)])
        plans = {}
        for c in range(3):
            rows = self.tables["components"][c]["blocks"]
            for c2 in range(3):
                cols = self.tables["components"][c2]["blocks"]
                plans[c, c2] = tuple(read_only(np.ascontiguousarray(part))
                                     for part in _gather_plan(m[rows], m[cols], kind[:, rows], kind[:, cols],
                                                              amplitude[:, rows], amplitude[:, cols],
                                                              sign[:, rows], sign[:, cols], n))
        return plans

    # ---- fields ------------------------------------------------------------------------------------------------

    def node_state(self, c: np.ndarray) -> np.ndarray:
        """The 9 node rows (x, a_θ, a_φ) of x = X + u for coefficients ``c``, shape (9, n_theta n_phi)."""
        return self.nodes["reference"] + self.node_displacement(c)

    def framed(self, state: np.ndarray) -> np.ndarray:
        """The node rows (x, a_θ/S', a_φ) of a node state: the images of the reference's orthonormal frame
        (A_θ/S', A_φ/sin θ), where the density and the stretches are read; the state itself on the sphere."""
        if self.aspect == 1.0:
            return state
        out = state.copy()
        out[3:6] /= np.repeat(self.nodes["rate"], self.n_phi)
        return out

    def node_displacement(self, c: np.ndarray) -> np.ndarray:
        """The 9 node rows (u, ∂θu, ∂φu) of the displacement u of coefficients ``c`` (linear in c)."""
        tables = self.tables
        out = np.zeros((STATE_ROWS, self.n_theta * self.n_phi))
        for comp in range(3):
            info = tables["components"][comp]
            if not info["blocks"]:
                continue
            coefficients = c[info["unknowns"]]
            for d in range(3):
                per_block = (info["theta"][d] * coefficients) @ info["sums"]  # (n_theta, n_b)
                phis = tables["phi"][info["blocks"], 0 if d < 2 else 1]
                out[3 * d + comp] = (per_block @ phis).ravel()
        return out

    def project(self, rows: np.ndarray) -> np.ndarray:
        """Σ_{jk} W_j Σ_{d,c} rows[3d + c](θ_j, φ_k) ∂(node row 3d + c)/∂coefficient for every coefficient: the
        residual from the node gradient (9 rows), or ⟨f, Y⟩ (with 1/2π) from the 3 value rows of a field f alone
        (its derivative rows zero: not projected)."""
        tables, nodes = self.tables, self.nodes
        out = np.zeros(self.size)
        weights = nodes["weights"][:, None]
        for comp in range(3):
            info = tables["components"][comp]
            if not info["blocks"]:
                continue
            total = np.zeros(len(info["unknowns"]))
            for d in range(rows.shape[0] // 3):
                phis = tables["phi"][info["blocks"], 0 if d < 2 else 1]  # (n_b, n_phi)
                rings = (rows[3 * d + comp].reshape(self.n_theta, self.n_phi) * weights) @ phis.T  # (n_theta, n_b)
                total += np.einsum("jn,jn->n", info["theta"][d], rings[:, info["column_block"]])
            out[info["unknowns"]] = total
        return out

    def fourier_table(self, pointwise: np.ndarray) -> np.ndarray:
        """F = [C_0 … C_{N−1}, S_0 … S_{N−1}] per node row of ``pointwise`` and θ-node j: C_q = Σ_k W_j f_jk cos qφ_k,
        S_q = Σ_k W_j f_jk sin qφ_k (what ``hessian`` contracts; the same for every basis on these nodes)."""
        spectra = np.fft.fft(pointwise.reshape(-1, self.n_theta, self.n_phi) * self.nodes["weights"][None, :, None],
                             axis=2)
        return np.ascontiguousarray(np.concatenate([spectra.real, -spectra.imag], axis=2))

    def hessian(self, fourier: np.ndarray, pairs_rows: np.ndarray) -> np.ndarray:
        """Σ_{jk} W_j D(θ_j, φ_k) contracted with the node rows' derivatives on both sides (module docstring), D the
        45 node-Hessian rows laid out by ``pairs_rows`` (galerkin.discretisation.symmetric_rows of the kernels'
        pairs), given as their ``fourier_table``. Per component pair (c, c') and row block b: the column weights
        Y_b = Σ_d' T^{dd'}[·, b, ·] Θ^{d'} (jitted, ``_weighted_columns``), then the product Θ_bᵀ Y_b (BLAS) while
        Y_b is in cache."""
        components = self.tables["components"]
        H = np.empty((self.size, self.size))
        for c in range(3):
            if not components[c]["blocks"]:
                continue
            rows = components[c]["range"]
            for c2 in range(c, 3):
                if not components[c2]["blocks"]:
                    continue
                cols = components[c2]["range"]
                channels = np.array([[pairs_rows[3 * d + c, 3 * d2 + c2] for d2 in range(3)] for d in range(3)])
                theta = components[c2]["theta"]
                Y = np.empty(theta.shape)
                left = components[c]["left"]
                starts = components[c2]["starts"]
                for r, (start, stop) in enumerate(components[c]["row_ranges"]):
                    first = r if c2 == c else 0  # a diagonal pair's block b' < b is the transpose of (b', b)
                    _weighted_columns(fourier, channels, *self._products[c, c2], theta, starts, r, first, Y)
                    H[rows.start + start:rows.start + stop, cols.start + starts[first]:cols.stop] = (
                        left[r].T @ Y.reshape(3 * self.n_theta, -1)[:, starts[first]:])
                if c2 != c:
                    H[cols, rows] = H[rows, cols].T
                    continue
                for start, stop in components[c]["row_ranges"]:
                    H[rows.start + start:rows.start + stop, rows.start:rows.start + start] = (
                        H[rows.start:rows.start + start, rows.start + start:rows.start + stop].T)
        return H

    def point_values(self, c: np.ndarray, theta: np.ndarray, phi: np.ndarray) -> tuple:
        """(x, a_θ) of x = X + u at points (θ, φ) anywhere on the sphere, the poles included (each (3, n))."""
        theta, phi = np.atleast_1d(np.asarray(theta, float)), np.atleast_1d(np.asarray(phi, float))
        z = np.cos(theta)
        mapped = z if self.mapping is None else self.mapping.s(z)
        x = np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), self.aspect * z])
        a_theta = np.array([z * np.cos(phi), z * np.sin(phi), -self.aspect * np.sin(theta)])
        for b, transform in zip(self.blocks, self.tables["transforms"]):
            p, dp = self._polar(mapped, z, b)
            trig = _norm(b.m) * (np.cos(b.m * phi) if b.t == COS else np.sin(b.m * phi))
            coefficients = transform @ c[b.slice]
            x[b.component] += trig * (p @ coefficients)
            a_theta[b.component] += trig * (dp @ coefficients)
        return x, a_theta

    def grid_values(self, c: np.ndarray, cos_theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """x = X + u on the grid of rings cos θ_j × angles φ_k, shape (3, n_rings, n_φ): each block's θ-series once
        per ring (``point_values`` evaluates it per point)."""
        x = np.asarray(cos_theta, dtype=float)
        s = np.sqrt(np.clip(1.0 - x * x, 0.0, None))
        mapped = x if self.mapping is None else self.mapping.s(x)
        out = np.array([np.outer(s, np.cos(phi)), np.outer(s, np.sin(phi)),
                        np.outer(self.aspect * x, np.ones_like(phi))])
        for b, transform in zip(self.blocks, self.tables["transforms"]):
            p, _ = self._polar(mapped, x, b)
            trig = _norm(b.m) * (np.cos(b.m * phi) if b.t == COS else np.sin(b.m * phi))
            out[b.component] += np.outer(p @ (transform @ c[b.slice]), trig)
        return out

    def gram(self) -> float:
        """The sphere's displacement norm (1/2π)∫∫|δu|² d(cos θ) dφ in these coefficients: c·c/(2π) (the basis is
        orthonormal); on a spheroid the norm over its reference area is ``mass``."""
        return 1.0 / (2.0 * np.pi)

    def mass(self) -> np.ndarray:
        """M with cᵀMc = (1/2π)∫∫|δu|² dA over the reference, dA = S' d(cos θ) dφ (the kinetic energy per 2π over
        ½ρT0R0⁴: dynamics/pencil.py), by the Hessian's quadrature: Σ_k τ_{m,t}(φ_k) τ_{m',t'}(φ_k) = N_φ/(2π) δ
        exactly on N_φ > 2M uniform nodes, so M is block-diagonal, per block

            M_b[l, l'] = (1/2π) Σ_j w_j S'(θ_j) P̃_l(θ_j) P̃_l'(θ_j)    (w_j the θ-weights, P̃ the block's θ-functions);

        gram()·I on the sphere (S' = 1: the basis is orthonormal in that quadrature)."""
        M = np.zeros((self.size, self.size))
        if self.aspect == 1.0:
            M[np.diag_indices(self.size)] = self.gram()
            return M
        nodes = self.nodes
        root = np.sqrt(nodes["weights"] * self.n_phi * nodes["rate"] * self.gram())[:, None]
        for b, theta in zip(self.blocks, self.tables["theta"]):
            scaled = root * theta[0]
            M[b.slice, b.slice] = scaled.T @ scaled  # exactly symmetric (BLAS syrk)
        return M


@functools.lru_cache(maxsize=16)
def _sectors(basis: SphericalBasis) -> list:
    if not basis.symmetry:
        return [basis]
    signs = np.array(np.meshgrid(*[(1, -1)] * len(basis.symmetry), indexing="ij")).reshape(len(basis.symmetry), -1)
    characters = [tuple(int(s) for s in column) for column in signs.T]
    return [basis if chi == basis.characters else replace(basis, characters=chi) for chi in characters]


@functools.lru_cache(maxsize=64)
def _blocks(degree: int, order: int, symmetry: tuple, characters: tuple) -> tuple:
    """The Blocks of every (component, order m ≤ ``order``, φ-type) whose degrees l ≤ ``degree`` keep the reflections
    with their characters, s_c σ_S(l, m, t) = χ_S, in order (shared by the bases of every map and node count)."""
    blocks, offset = [], 0
    for c in range(3):
        for m in range(order + 1):
            for t in (COS,) if m == 0 else (COS, SIN):
                # l enters σ_S only through (−1)^(l+m): the degrees kept are all, none, or those of one parity
                kept = [all(S[c] * _sign_under(S, l, m, t) == chi for S, chi in zip(symmetry, characters))
                        for l in (m, m + 1)]
                degrees = tuple(l for l in range(m, degree + 1) if kept[(l - m) % 2])
                if degrees:
                    blocks.append(Block(c, m, t, degrees, offset))
                    offset += len(degrees)
    return tuple(blocks)


@functools.lru_cache(maxsize=256)
def _legendre_pair(points: bytes, degree: int, m: int) -> tuple:
    """(P̄_l^m, dP̄_l^m/dθ), l ≤ degree, at the points (a float64 array's bytes): the blocks of one order (three
    components, two φ-types, every symmetry sector) share them."""
    x = np.frombuffer(points)
    return read_only(legendre_values(x, degree, m)), read_only(theta_derivative(x, degree, m))


def _gather_plan(a, b, kind_a, kind_b, amp_a, amp_b, sign_a, sign_b, n: int) -> tuple:
    """(i1, i2, α1, α2) of ``SphericalBasis._products`` for row blocks of orders ``a`` and column blocks of orders
    ``b``, each (2, 2, n_a, n_b) by φ-types (e, e'): ``kind``, ``amp``, ``sign`` per (e, block) the COS or SIN, the
    normalisation and the sign of p^e."""
    a, b = a[:, None], b[None, :]
    plus, minus = (a + b) % n, np.abs(a - b) % n
    rows, cols = (slice(None), None, slice(None), None), (None, slice(None), None, slice(None))  # → (e, e', a, b)
    ki, kk = kind_a[rows], kind_b[cols]
    scale = 0.5 * amp_a[rows] * amp_b[cols] * sign_a[rows] * sign_b[cols]
    same = ki == kk
    i1 = np.where(same, minus, n + plus)
    i2 = np.where(same, plus, n + minus)
    mixed = np.sign(a - b) * np.where(ki == COS, -1.0, 1.0)  # cos a sin b = ½[sin(a + b) − sin(a − b)], …
    a2 = np.where(same, np.where(ki == COS, scale, -scale), scale * mixed)
    return i1, i2, np.broadcast_to(scale, i1.shape), a2


def _norm(m: int) -> float:
    """The normalisation of τ_{m,t}: 1/√(2π) for m = 0, 1/√π otherwise."""
    return 1.0 / np.sqrt(2.0 * np.pi) if m == 0 else 1.0 / np.sqrt(np.pi)


@njit(cache=True)
def _weighted_columns(fourier, channels, i1, i2, a1, a2, theta, starts, r, first, Y):
    """Y[d, j, col] = Σ_d' T^{dd'}_j[r, b'] Θ^{d'}[j, col] for the row block r, b' ≥ ``first`` the block of column
    col (columns starts[b'] to starts[b' + 1]), T^{dd'}_j[r, b'] = α1 F_ch[j, i1] + α2 F_ch[j, i2] of the plan of
    φ-types (d // 2, d' // 2) and the Fourier table F_ch of channel ch = channels[d, d'] (Y overwritten from column
    starts[first] on: each entry written once, its three terms summed in the order d' = 0, 1, 2; a node's three
    θ-rows stay in cache over its three rows of Y; each block's columns one contiguous, vectorised run)."""
    n_b = i1.shape[3]
    n_theta = theta.shape[1]
    for j in range(n_theta):
        w0, w1, w2 = theta[0, j], theta[1, j], theta[2, j]
        for d in range(3):
            e = d // 2
            y = Y[d, j]
            ch0, ch1, ch2 = channels[d, 0], channels[d, 1], channels[d, 2]
            for b in range(first, n_b):
                p, q, alpha, beta = i1[e, 0, r, b], i2[e, 0, r, b], a1[e, 0, r, b], a2[e, 0, r, b]
                t0 = alpha * fourier[ch0, j, p] + beta * fourier[ch0, j, q]
                t1 = alpha * fourier[ch1, j, p] + beta * fourier[ch1, j, q]
                p, q, alpha, beta = i1[e, 1, r, b], i2[e, 1, r, b], a1[e, 1, r, b], a2[e, 1, r, b]
                t2 = alpha * fourier[ch2, j, p] + beta * fourier[ch2, j, q]
                for col in range(starts[b], starts[b + 1]):
                    y[col] = t0 * w0[col] + t1 * w1[col] + t2 * w2[col]
