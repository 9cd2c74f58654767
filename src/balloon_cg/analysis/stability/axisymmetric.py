"""Stability of equilibria from the second variation (MODEL.md §5), axisymmetric modes.

Perturbations δλ2 = Σ a_k P_k(cos θ), δη = Σ b_k P_k(cos θ), k = 0..N (the paper's basis drops a_0, which
carries the limit-point instability, and b_0, the rigid axial translation: both are kept here). The Hessian
H = Σ_q W_q Bᵀ ∂²π̂ B is assembled at the equilibrium state, and eigenvalues are taken relative to the L2 Gram
matrix G = ∫(δλ2² + δη²) d(cos θ), so that they do not depend on the basis normalisation.

Blocks of an equator-symmetric state: 'even' (a_even, b_odd: shape-symmetric modes, carries the volume change)
and 'odd' (a_odd, b_even: pear-shaped modes). b_0 is the rigid translation: a zero mode without a field
(always left out); with a field it is kept for a *free* balloon and left out for one *held* at its centre.

Control modes: under pressure control the test is H > 0; under volume control H restricted to the
perturbations that keep the volume, gᵀδ = 0 with g = ∂Ṽ/∂(a, b) = −∂²(E/2π)/∂P∂(a, b) (Ṽ = V/2π); under gas
control (isothermal ideal gas, P V = n fixed: energy E − n ln V in place of E − P V) the Hessian of
E/2π − (n/2π) ln V, H + (n/2π)(2π)² g gᵀ/V² = H + (P/Ṽ) g gᵀ > 0. As H ≤ H_gas and H_gas = H on gᵀδ = 0,
stable under pressure ⇒ stable under gas ⇒ stable under volume control.

Resolution: along a branch each point is assessed at the degree N = max(stability.degree, the Legendre degree
in x that holds the equilibrium) (``point_degrees``: raised near a wire, where the equilibrium lives on a mapped
basis), and checked at ``check_degree`` (2N, at solver.max_degree against N/1.5) where a sign could change. The
bracketing points of a crossing (a sign change a branch-point search reads) are raised until the crossing
eigenvalue is resolved there (``crossings.follow_modes``): the degree follows the mode, not only the
equilibrium.

Non-axisymmetric modes m = 1..m_max (``azimuthal``, docs/second_variation.md) form blocks 'm<m>_held' and
'm<m>_free' with the symmetry zero modes removed; they enter every flag.
"""
from dataclasses import dataclass, replace

import numpy as np

from .azimuthal import lowest_readings, merged_lowest, perturbation_map, restricted_blocks
from .banded import banded_variation
from .banded_azimuthal import BandedAzimuthal
from .flags import (EVERY_FLAG, FLAGS, FREE, FREE_FLAGS, FREE_GAS, FREE_VOLUME, HELD, HELD_FLAGS,  # noqa: F401
                    HELD_GAS, HELD_VOLUME, LOWEST)
from .crossings import branch_point_crossings, follow_modes, resolved
from ...galerkin.legendre import gauss_rule
from ...galerkin.discretisation import (Discretisation, assemble_gradient, assemble_hessian, even_half, piece_nodes,
                                       read_only)
from ...galerkin.equilibrium import NodeKernels, Parameters
from ...model.meridian import area_density, mass_density, reference_area
from ...scene.tables import Geometry, Shape
from ...numerics import eigen, interrupt, workers
from ..branches.problem import equilibrium_of
from ..branches.resolution import Resolution, transfer_error
from ...numerics.threads import limited_blas

CHECK_FACTOR = 2.0  # N-convergence is checked at CHECK_FACTOR·N
# a point's flags are checked at the check degree where a block's lowest eigenvalue is below this in magnitude
# (``near_zero``): 0.1 where eigenvalues are O(1) but the m = 0 blocks' are not converged in the degree (the
# unknowns' norm: docs/numerics.md §4, or a plain basis on a mapped branch); on the defaults (|δx|², the wire map)
# every block's lowest eigenvalue at a point's degree N was within 2.2e-8 of its value at the check degree (4.3e-9
# where below 0.1) at every point the old rule checked, no sign changed (2128 blocks of the two-coil, paper-coil and
# off-equator pictures: benchmarks/results/near_zero.txt), so 1e-4 keeps a margin of 4500 over that error
NEAR_ZERO = {True: 1e-4, False: 0.1}


@dataclass
class Assessment:
    """Lowest eigenvalues per block and the stability flags of one equilibrium."""

    blocks: dict  # name -> lowest eigenvalues (ascending); names: even, odd_held, odd_free, all_held, all_free,
    #                even_volume, all_volume_held, all_volume_free, even_gas, all_gas_held, all_gas_free
    stable_pressure: bool  # held at the centre (the translation excluded), pressure control
    stable_volume: bool  # held, volume control
    stable_pressure_free: bool  # free balloon (translation included; equal to held without a field)
    stable_volume_free: bool
    stable_gas: bool  # held, gas control (fixed amount of isothermal ideal gas)
    stable_gas_free: bool
    degree: int  # the perturbation degree N it was computed at

    def flags(self) -> dict:
        """The six stability flags by name (FLAGS)."""
        return {name: getattr(self, name) for name in FLAGS}


class SecondVariation:
    """Galerkin Hessians of the energy on a Legendre perturbation basis of degree N, at equilibria of ``eq``."""

    def __init__(self, equilibrium, degree: int, basis: str | None = None, norm: str | None = None):
        self.eq = equilibrium
        self.basis_kind = equilibrium.scene.stability.basis if basis is None else basis
        norm = equilibrium.scene.stability.norm if norm is None else norm
        # per piece of the equilibrium's rule (split at a capsule's joins, where the integrand has kinks)
        joins = equilibrium.disc.joins
        # a graded equilibrium's own element degrees at its degree (each element as resolved as its state)
        graded = equilibrium.disc.element_degrees if degree == equilibrium.disc.degree else ()
        quadrature = max(equilibrium.disc.x.size // (len(joins) + 1), piece_nodes(degree, joins, graded))
        # "legendre": P_k(x) even when the equilibrium's basis is mapped; "mapped": P_k(s) on the equilibrium's own
        # wire map (its Gauss nodes in s); on an unmapped equilibrium both are the same basis
        mapping = perturbation_map(equilibrium, self.basis_kind)
        self.basis = Discretisation(degree, symmetric=False, pin_translation=False, quadrature=quadrature,
                                    mapping=mapping, joins=joins, element_degrees=graded)
        self.theta = np.arccos(self.basis.x)
        k = np.arange(degree + 1)
        na = degree + 1
        self.index = {
            "a_even": k[k % 2 == 0], "a_odd": k[k % 2 == 1],
            "b_even": na + k[k % 2 == 0], "b_odd": na + k[k % 2 == 1],
        }
        self.translation = na  # b_0
        self.ops, self.weights = _held_ops(self.basis, equilibrium.scene.geometry), self.basis.weights
        ops, w = self.ops, self.weights
        if ops is self.basis.ops:
            self.basis_a, self.basis_b, self._gradient_ops = (self.basis.basis_a, self.basis.basis_b,
                                                              self.basis._gradient_ops)
        else:
            self.basis_a, self.basis_b = (read_only(np.ascontiguousarray(ops[0:2, :, :na])),
                                          read_only(np.ascontiguousarray(ops[2:4, :, na:])))
            self._gradient_ops = read_only(np.ascontiguousarray(ops.reshape(-1, self.basis.size).T))
        # the norm: ∫(δλ2² + δη²) dx ("unknowns"), or |δx|² = ∫(sin²θ δλ2² + δη²) dx ("displacement", δρ = sin θ δλ2):
        # the mass matrix of the membrane's kinetic energy over the reference surface (model/meridian.py: S' dx)
        self.norm = norm
        if norm == "displacement":
            mass = mass_density(equilibrium.scene.geometry, "axisymmetric", self.basis.cos_theta, self.basis.sin_theta)
            self.gram = assemble_hessian(mass, w, self.basis_a, self.basis_b)
        else:
            self.gram = ops[0].T @ (w[:, None] * ops[0]) + ops[2].T @ (w[:, None] * ops[2])
        # diagonal: "unknowns" on the Legendre basis in x only (not on a map, nor on a capsule's elements, nor with a
        # spheroid's held η functions P_k − m_k)
        self._orthogonal = ops is self.basis.ops and not joins and norm != "displacement"
        # the state at the nodes is linear in the equilibrium's unknowns: (λ2, v, η, w) = u @ state_map
        unit = self.eq.state_at(np.eye(self.eq.disc.size), self.theta)
        self.state_map = np.ascontiguousarray(np.concatenate([np.atleast_2d(v) for v in unit], axis=1))
        # an equator-symmetric state's blocks (even, odd) take only integrands even in x: the nodes x ≥ 0 serve
        self._even = self._even_tables() if self.eq.disc.symmetric else None
        self._nodes = NodeKernels(self.eq, (self.basis.cos_theta, self.basis.sin_theta))  # the kernels at the nodes

    def _even_tables(self) -> tuple:
        """(state map, the kernels at the nodes, weights, basis_a, basis_b, gradient ops) on the nodes x ≥ 0
        (``even_half``)."""
        b = self.basis
        # mirror-symmetric nodes: in x without a map, in s with one (x = g(s) is odd only to rounding, and the middle
        # node of an odd rule must count once)
        nodes = b.x if b.mapping is None else gauss_rule(b.x.size)[0]
        keep, weights = even_half(nodes, b.weights)
        n_q = b.x.size
        state_map = np.ascontiguousarray(self.state_map[:, np.concatenate([k * n_q + keep for k in range(4)])])
        ops = np.ascontiguousarray(self.ops[:, keep])
        tables = (read_only(weights), *(read_only(np.ascontiguousarray(t[:, keep])) for t in (self.basis_a, self.basis_b)),
                  read_only(np.ascontiguousarray(ops.reshape(-1, b.size).T)))
        return (state_map, NodeKernels(self.eq, (b.cos_theta[keep], b.sin_theta[keep])), *tables)

    def _even_matrices(self, u, params: Parameters):
        """``matrices`` of an equator-symmetric state, exact on the blocks even and odd only (entries between them,
        odd integrands, are not zero here and must not be read)."""
        state_map, nodes, weights, basis_a, basis_b, gradient_ops = self._even
        _hold(nodes, u, state_map, params)
        hessian = assemble_hessian(nodes("energy_hessian", params), weights, basis_a, basis_b)
        volume = -assemble_gradient(nodes("pressure_gradient", params), weights, basis_a, basis_b, gradient_ops)
        return hessian, volume

    def matrices(self, u, params: Parameters):
        """(H, g): the Hessian of E/2π and the gradient of Ṽ = V/2π on the perturbation basis."""
        _hold(self._nodes, u, self.state_map, params)
        hessian = assemble_hessian(self._nodes("energy_hessian", params), self.weights, self.basis_a, self.basis_b)
        volume = -assemble_gradient(self._nodes("pressure_gradient", params), self.weights, self.basis_a,
                                    self.basis_b, self._gradient_ops)
        return hessian, volume

    def _lowest(self, H, idx, constraint=None):
        """Lowest generalized eigenvalues of (H, G) on the block ``idx``, optionally restricted to gᵀδ = 0
        (``numerics.eigen.lowest``)."""
        return eigen.lowest_of(self._restricted(H, idx, constraint), LOWEST)

    def _restricted(self, H, idx, constraint=None):
        """The block ``idx`` of (H, G) as a standard symmetric matrix, optionally on gᵀδ = 0 (``eigen.restricted``)."""
        normals = eigen.NO_CONSTRAINT if constraint is None else constraint[idx]
        return eigen.restricted(H, self._gram_factor(idx), normals, idx)

    def _gram_factor(self, idx: np.ndarray) -> eigen.GramFactor:
        """G_block = L Lᵀ (the Gram blocks do not change along a branch: cached)."""
        cache = self.__dict__.setdefault("_cholesky", {})
        key = idx.tobytes()
        if key not in cache:
            # Legendre in x: G diagonal; in s it is not (∫ P_k(s) P_l(s) dx, dx = ds/h')
            cache[key] = eigen.GramFactor(self.gram[np.ix_(idx, idx)], orthogonal=self._orthogonal)
        return cache[key]

    def _plan(self, symmetric: bool, field_on: bool) -> tuple:
        """The m = 0 blocks (``blocks``): (name, on H_gas, index, on gᵀδ = 0, Gram factor, flags) each; cached."""
        plans = self.__dict__.setdefault("_plans", {})
        if (symmetric, field_on) in plans:
            return plans[symmetric, field_on]
        i, t = self.index, self.translation
        if symmetric:  # the odd modes keep the volume to first order (g = 0 there): one odd block for all controls
            even = np.concatenate([i["a_even"], i["b_odd"]])
            odd_held = np.concatenate([i["a_odd"], i["b_even"][1:]])
            plan = [("even", False, even, False, (HELD, FREE)),
                    ("even_volume", False, even, True, (HELD_VOLUME, FREE_VOLUME)),
                    ("even_gas", True, even, False, (HELD_GAS, FREE_GAS)), ("odd_held", False, odd_held, False, EVERY_FLAG)]
            if field_on:
                plan.append(("odd_free", False, np.append(odd_held, t), False, FREE_FLAGS))
        else:
            everything = np.arange(self.basis.size)
            held_idx = everything[everything != t]
            plan = [("all_held", False, held_idx, False, (HELD,) if field_on else (HELD, FREE)),
                    ("all_volume_held", False, held_idx, True, (HELD_VOLUME,) if field_on else (HELD_VOLUME, FREE_VOLUME)),
                    ("all_gas_held", True, held_idx, False, (HELD_GAS,) if field_on else (HELD_GAS, FREE_GAS))]
            if field_on:
                plan += [("all_free", False, everything, False, (FREE,)),
                         ("all_volume_free", False, everything, True, (FREE_VOLUME,)),
                         ("all_gas_free", True, everything, False, (FREE_GAS,))]
        plans[symmetric, field_on] = tuple((name, gas, idx, constrained, self._gram_factor(idx), flags)
                                           for name, gas, idx, constrained, flags in plan)
        return plans[symmetric, field_on]

    def blocks(self, u, params: Parameters, symmetric: bool, m_max: int = 0) -> list:
        """(name, standard matrices, flags) per block at one equilibrium: the block's pencil restricted to its
        constraints, as one matrix or the matrices of its uncoupled parts (``_plan``, ``eigen.restricted``,
        ``azimuthal.restricted_blocks``), and the flags it enters (positions in
        FLAGS). Azimuthal blocks m = 1..m_max enter every flag (their modes keep the volume to first order, so
        every control mode sees the same m ≥ 1 spectrum); a free balloon's flags take the held blocks where the
        translation is no zero mode to remove (no field)."""
        out = self._axisymmetric(u, params, symmetric)
        field_on = self.eq.coils.shape[0] > 0 and params.M > 0
        for m in range(1, m_max + 1):
            readings = restricted_blocks(self.eq, u, params, m, self.basis.degree, (True, False) if field_on else (True,),
                                         kind=self.basis_kind)
            out.append((f"m{m}_held", readings[True], HELD_FLAGS if field_on else EVERY_FLAG))
            if field_on:
                out.append((f"m{m}_free", readings[False], FREE_FLAGS))
        return out

    def _axisymmetric(self, u, params: Parameters, symmetric: bool, names=None) -> list:
        """``blocks`` of the m = 0 plan (``_plan``; only those named in ``names``, if given): each block's matrix is
        its own array (the eigensolves overwrite them), made from its index set's reduction (``_families``)."""
        return [(name, (_member_matrix(A, row, weight, gas, constrained),), flags)
                for A, row, weight, members in self._families(u, params, symmetric, names)
                for name, gas, constrained, flags in members]

    def _families(self, u, params: Parameters, symmetric: bool, names=None) -> list:
        """The m = 0 plan (``_plan``; only the blocks named in ``names``, if given) by index set: (A, row, weight,
        members) each, with A = L⁻¹HL⁻ᵀ the set's reduction (one dsygst for its blocks), row = L⁻¹g, weight = P/Ṽ and
        members (name, gas, constrained, flags) its blocks: pressure control is A, volume control A on
        (L⁻¹g)ᵀy = 0 (its reflections), gas control A + (P/Ṽ)(L⁻¹g)(L⁻¹g)ᵀ (``_member_matrix``)."""
        half = symmetric and self._even is not None  # g's odd entries are then not zero: read on even rows only
        H, g = self._even_matrices(u, params) if half else self.matrices(u, params)
        field_on = self.eq.coils.shape[0] > 0 and params.M > 0
        weight = self._gas_weight(u, params)
        families = {}  # per index set: [A, row, weight, members]
        for name, gas, idx, constrained, factor, flags in self._plan(symmetric, field_on):
            if names is not None and name not in names:
                continue
            if id(idx) not in families:
                families[id(idx)] = (eigen.restricted(H, factor, eigen.NO_CONSTRAINT, idx),
                                     factor.directions(g[idx][None, :]), weight, [])
            families[id(idx)][3].append((name, gas, constrained, flags))
        return list(families.values())

    def _axisymmetric_lowest(self, u, params: Parameters, symmetric: bool) -> list:
        """(name, LOWEST eigenvalues, flags) of every m = 0 block (``_axisymmetric``): the blocks of one index set
        are relatives of its pressure block A (``eigen.lowest_with_relatives``: large ones through one shifted
        factorisation below A's lowest eigenvalue, not a dense eigensolve each)."""
        out, families = [], self._families(u, params, symmetric)
        interrupt.check()  # a signal while the reductions were built: Interrupted before any of them is solved
        for A, row, weight, members in families:
            plain = [member for member in members if not (member[1] or member[2])]
            relatives = [member for member in members if member[1] or member[2]]
            if len(plain) != 1:  # no pressure block to be the relatives' base: each alone
                out += [(name, merged_lowest((_member_matrix(A, row, weight, gas, constrained),), LOWEST), flags)
                        for name, gas, constrained, flags in members]
                continue
            own, values = eigen.lowest_with_relatives(
                A, LOWEST, [(row if constrained else None, (row[0], weight) if gas else None,
                             lambda gas=gas, constrained=constrained: _member_matrix(A, row, weight, gas, constrained))
                            for _, gas, constrained, _ in relatives])
            found = {plain[0][0]: own} | {member[0]: v for member, v in zip(relatives, values)}
            out += [(name, found[name], flags) for name, _, _, flags in members]
        return out

    def _gas(self, H, g, u, params: Parameters) -> np.ndarray:
        """The Hessian under gas control, H + (P/Ṽ) g gᵀ (module docstring)."""
        return H + self._gas_weight(u, params) * np.outer(g, g)

    def _gas_weight(self, u, params: Parameters) -> float:
        """P/Ṽ, the weight of the gas term g gᵀ."""
        return params.P / self.eq.volume(u)

    def block_pencil(self, u, params: Parameters, symmetric: bool, name: str) -> tuple:
        """The m = 0 block ``name`` (``blocks``) as its pencil on the perturbation coefficients ``index``:
        (K, G, N, index), K q = ν G q on N q = 0 (K the Hessian, under gas control H + (P/Ṽ) g gᵀ; G the Gram
        matrix; N the volume gradient's row where the block keeps the volume, else no rows), the full assembly
        (``matrices``), for the eigenvectors (dynamics.modes)."""
        field_on = self.eq.coils.shape[0] > 0 and params.M > 0
        plan = {entry[0]: entry for entry in self._plan(symmetric, field_on)}
        if name not in plan:
            raise KeyError(f"no m = 0 block {name!r} here (blocks: {', '.join(plan)})")
        _, gas, idx, constrained, _, _ = plan[name]
        H, g = self.matrices(u, params)
        K = self._gas(H, g, u, params) if gas else H
        normals = g[idx][None, :] if constrained else np.zeros((0, idx.size))
        return K[np.ix_(idx, idx)], self.gram[np.ix_(idx, idx)], normals, idx

    def _lowest_blocks(self, u, params: Parameters, symmetric: bool, m_max: int = 0):
        """(name, LOWEST eigenvalues, flags) per block of ``blocks``, in its order; the blocks that are relatives of
        another (volume and gas of a pressure block, the held m = 1 reading of the free one) read through one
        factorisation where they are large (``_axisymmetric_lowest``, ``azimuthal.lowest_readings``); from
        stability.banded_from on the banded sibling basis instead (``banded.banded_variation``,
        ``banded_azimuthal.BandedAzimuthal``), where P ≥ 0 (its gas reading's proved shift needs the rank-one weight
        P/Ṽ ≥ 0: numerics/banded.py)."""
        sibling = self._sibling(symmetric) if params.P >= 0 else None
        if sibling is None:
            yield from self._axisymmetric_lowest(u, params, symmetric)
        else:
            yield from sibling.lowest(u, params)
        field_on = self.eq.coils.shape[0] > 0 and params.M > 0
        wanted = (True, False) if field_on else (True,)
        for m in range(1, m_max + 1):
            interrupt.check()
            if sibling is None:
                readings = lowest_readings(self.eq, u, params, m, self.basis.degree, LOWEST, wanted,
                                           kind=self.basis_kind)
            else:
                readings = self._sibling_block(symmetric, m).lowest_readings(u, params, LOWEST, wanted)
            yield f"m{m}_held", readings[True], HELD_FLAGS if field_on else EVERY_FLAG
            if field_on:
                yield f"m{m}_free", readings[False], FREE_FLAGS

    def _sibling(self, symmetric: bool, start: int | None = None):
        """The m = 0 blocks' banded sibling at this degree (``banded.banded_variation``), cached per symmetry; None
        below ``start`` (default stability.banded_from; 0: never)."""
        start = self.eq.scene.stability.banded_from if start is None else start
        if not start or self.basis.degree < start:
            return None
        siblings = self.__dict__.setdefault("_banded", {})
        if symmetric not in siblings:
            siblings[symmetric] = banded_variation(self.eq, self.basis.degree, symmetric)
        return siblings[symmetric]

    def _sibling_block(self, symmetric: bool, m: int, start: int | None = None) -> BandedAzimuthal:
        """The m-th block on the sibling's elements (``_sibling``), cached."""
        blocks = self.__dict__.setdefault("_banded_azimuthal", {})
        if (symmetric, m) not in blocks:
            blocks[symmetric, m] = BandedAzimuthal(self._sibling(symmetric, start), m)
        return blocks[symmetric, m]

    def lowest(self, u, params: Parameters, symmetric: bool, name: str) -> np.ndarray:
        """The LOWEST eigenvalues of the one m = 0 block ``name`` at one equilibrium (``blocks``)."""
        (_, parts, _), = self._axisymmetric(u, params, symmetric, (name,))
        return merged_lowest(parts, LOWEST)

    def assess(self, u, params: Parameters, symmetric: bool, m_max: int = 0) -> Assessment:
        """Blocks (their LOWEST eigenvalues) and flags (a flag holds when every block it takes is positive) at one
        equilibrium (``blocks``)."""
        blocks, lowest = {}, [np.inf] * len(FLAGS)
        for name, values, flags in self._lowest_blocks(u, params, symmetric, m_max):
            interrupt.check()  # a signal: Interrupted at the next block (assess_branch's callers catch it)
            blocks[name] = values
            for flag in flags:
                lowest[flag] = min(lowest[flag], blocks[name][0])
        return Assessment(blocks, *(value > 0 for value in lowest), self.basis.degree)

    def flags(self, u, params: Parameters, symmetric: bool, m_max: int = 0) -> tuple:
        """The flags of ``assess`` (in FLAGS order) from the inertia alone, no eigenvalues: a block is positive when
        its Cholesky factorisation exists (``eigen.positive_definite``), on the banded sibling where ``assess``
        reads it (``_positive_blocks``); a block is skipped once every flag it enters has failed."""
        stable = [True] * len(FLAGS)
        for flags, positive in self._positive_blocks(u, params, symmetric, m_max):
            interrupt.check()  # as assess
            if any(stable[flag] for flag in flags) and not positive():
                for flag in flags:
                    stable[flag] = False
        return tuple(stable)

    def _positive_blocks(self, u, params: Parameters, symmetric: bool, m_max: int):
        """(the flags a block enters, a call saying whether it is positive definite) per block, in ``blocks``'
        order: the Legendre blocks' Cholesky factorisations, or from stability.banded_flags_from where P ≥ 0 (as
        ``_lowest_blocks``) the banded sibling's inertia (``BandedVariation.positive``,
        ``BandedAzimuthal.positive_readings``: one factorisation per index set and part)."""
        start = self.eq.scene.stability.banded_flags_from
        sibling = self._sibling(symmetric, start) if params.P >= 0 else None
        if sibling is None:
            for _, parts, flags in self.blocks(u, params, symmetric, m_max):
                yield flags, lambda parts=parts: all(eigen.positive_definite(A) for A in parts)
            return
        for _, positive, flags in sibling.positive(u, params):
            yield flags, lambda positive=positive: positive
        field_on = self.eq.coils.shape[0] > 0 and params.M > 0
        for m in range(1, m_max + 1):
            readings = self._sibling_block(symmetric, m, start).positive_readings(u, params, (True, False) if field_on
                                                                                  else (True,))
            yield (HELD_FLAGS if field_on else EVERY_FLAG), lambda held=readings[True]: held
            if field_on:
                yield FREE_FLAGS, lambda free=readings[False]: free


def _held_ops(basis: Discretisation, geometry: Geometry) -> np.ndarray:
    """The node values (λ2, v, η, w) per perturbation coefficient (a_0..a_N, b_0..b_N), shape (4, n_q, 2N + 2).
    The η functions are 1 and φ_k − m_k (k ≥ 1, ``held_means``; φ_k = P_k, or a capsule's piecewise functions with
    φ_0 = 1), the span of φ_0..φ_N: dropping b_0 (a held balloon) then means ∫δη dA = 0, the centroid of the
    reference surface fixed (dA = R S' dθ dφ; on the sphere ∫δη dx = 0), also the hold of the equilibrium's held
    general basis (``Discretisation``). On the sphere in x, m_k = 0: the basis's own ops."""
    if not _weighted_hold(basis, geometry):
        return basis.ops
    na = basis.a_index.size
    ops = np.array(basis.ops)
    ops[2, :, na + 1:] -= held_means(basis, geometry)
    return read_only(ops)


def _weighted_hold(basis: Discretisation, geometry: Geometry) -> bool:
    """Whether the held η functions φ_k − m_k differ from φ_k: on a map, on a spheroid (S' ≠ 1), or on a capsule's
    piecewise basis (joins; its R ≠ sin θ)."""
    return basis.mapping is not None or geometry.shape == Shape.SPHEROID or bool(basis.joins)


def held_means(basis: Discretisation, geometry: Geometry) -> np.ndarray:
    """m_k = ∫φ_k dA / A = ∫φ_k ρ dx / ∫ρ dx, k = 1..N (ρ = R S'/sin θ, ``meridian.area_density``; ∫ρ dx = A/2π,
    ``meridian.reference_area``; φ_k = P_k of s(x) on a map, a capsule's piecewise functions on its joins),
    subtracted from the η functions of the perturbation basis (``_held_ops``); zero on the sphere in x."""
    if not _weighted_hold(basis, geometry):
        return np.zeros(basis.degree)
    density = area_density(geometry, basis.cos_theta, basis.sin_theta)
    return (basis.weights * density) @ basis.ops[2, :, basis.a_index.size + 1:] / reference_area(geometry)


def held_transform(basis: Discretisation, geometry: Geometry) -> np.ndarray | None:
    """T with ``_held_ops`` = basis.ops @ T (the column b_k of T takes −m_k into the row b_0, ``held_means``), or
    None where they are the basis's own ops."""
    if not _weighted_hold(basis, geometry):
        return None
    na = basis.a_index.size
    T = np.eye(basis.size)
    T[na, na + 1:] = -held_means(basis, geometry)
    return T


def _hold(nodes: NodeKernels, u, state_map: np.ndarray, params: Parameters):
    """The node state u @ state_map (rows λ2, v, η, w) of the unknowns u into ``nodes``, held at ``params``."""
    np.dot(np.asarray(u, dtype=float), state_map, out=nodes.state.reshape(-1))
    nodes.hold(params)


def _member_matrix(A, row, weight: float, gas: bool, constrained: bool) -> np.ndarray:
    """One m = 0 block's matrix from its index set's reduction A (``SecondVariation._families``): A itself under
    pressure control, A on rowᵀy = 0 under volume control, A + weight·row rowᵀ under gas control."""
    if constrained:  # A on (L⁻¹g)ᵀy = 0
        return eigen.restricted(A, eigen.GramFactor(np.ones(A.shape[0]), orthogonal=True), row)
    if gas:  # L⁻¹(H + (P/Ṽ) g gᵀ)L⁻ᵀ
        return A + weight * np.outer(row[0], row[0])
    return A


def block_indices(variation, block: str, field_on: bool):
    """Indices of a block on the perturbation basis (odd_held plus b_0 for a free balloon in a field)."""
    i = variation.index
    if block == "even":
        return np.concatenate([i["a_even"], i["b_odd"]])
    odd = np.concatenate([i["a_odd"], i["b_even"][1:]])
    return np.append(odd, variation.translation) if (block == "odd_free" and field_on) else odd


def point_degrees(branch, degree: int) -> np.ndarray:
    """The perturbation degree per point of ``branch``: at least ``degree`` (the scene's stability.degree) and at
    least the degree that holds the equilibrium. On a mapped branch that is, for stability.basis "legendre", the
    Legendre degree in x (``Resolution.plain_degrees`` from ``degree`` up: near a wire up to hundreds) and for
    "mapped" the branch's own degree on its map (every point is stored there); on an unmapped branch ``degree``,
    but on a capsule's piecewise basis (galerkin/elements.py) at least the branch's degree: its functions are shared
    by three elements, and at 20 of them the eigenvalue at a pear branch's first point (L = 3) is 2.6e-6 off its
    converged −1.2e-8 (degrees 40 to 135 agree to 1e-11), so its flags changed at the check degree."""
    if branch.disc.mapping is None:
        return np.full(len(branch.X), max(degree, branch.disc.degree) if branch.disc.joins else degree)
    if branch.scene.stability.basis == "mapped":
        return np.maximum(degree, mapped_degrees(branch, degree))
    return np.maximum(degree, Resolution.of(branch.scene).plain_degrees(branch.disc, branch.X, start=degree))


def mapped_degrees(branch, start: int) -> np.ndarray:
    """Per point of a mapped branch: the degree on its map that holds it, grown from ``start`` (by the resolution's
    growth) until the point truncated to it loses at most max_error (``transfer_error``) and its tail estimate is
    within max_error, at most the branch's degree (where every point is stored): a branch that ends next to a wire
    at a high mapped degree keeps its earlier points at the degree they need."""
    resolution, disc = Resolution.of(branch.scene), branch.disc
    X = np.atleast_2d(branch.X)
    degrees = np.full(len(X), disc.degree)
    open_rows, degree = np.arange(len(X)), start
    while open_rows.size and degree < disc.degree:
        lower = replace(disc, degree=degree)
        moved = np.array([lower.join(*(c[: degree + 1] for c in disc.split(row[: disc.size]))) for row in X[open_rows]])
        loss = transfer_error(disc, X[open_rows], lower, moved)
        tails = np.array([lower.tail(row) for row in moved])
        settled = np.maximum(loss, tails) <= resolution.max_error
        degrees[open_rows[settled]] = degree
        open_rows = open_rows[~settled]
        degree = resolution.grow(degree)
    return degrees


def check_degree(branch, degree: int, factor: float = CHECK_FACTOR) -> int:
    """The degree a result at perturbation degree N is checked against: ``factor``·N, at most solver.max_degree;
    at max_degree itself the coarser N/growth (then the check says whether N lies in the converged range)."""
    resolution = Resolution.of(branch.scene)
    if degree < resolution.max_degree:
        return min(int(factor * degree), resolution.max_degree)
    return int(degree / resolution.growth)


def convergence_problems(branch, index: int, eigenvalue, degrees) -> list[str]:
    """Whether a crossing eigenvalue changes sign between points index and index + 1 and is converged there: at
    each point's degree N (``degrees``: one per bracketing point) it is resolved against its ``check_degree``
    (``crossings.resolved``) ([] if so, else what is wrong). ``eigenvalue(n, N)`` is the
    eigenvalue at point n on the perturbation basis of degree N."""
    problems, signs = [], []
    for n, N in zip((index, index + 1), degrees):
        finer = check_degree(branch, int(N))
        coarse, fine = eigenvalue(n, int(N)), eigenvalue(n, finer)  # ``fine``: coarser at solver.max_degree
        signs.append(np.sign(coarse))
        if not resolved(coarse, fine):
            problems.append(f"point {n}: crossing eigenvalue not converged ({coarse:.3g} at N = {int(N)}, "
                            f"{fine:.3g} at {finer})")
    if signs[0] == signs[1]:
        problems.append(f"the crossing eigenvalue does not change sign between points {index} and {index + 1} "
                        "at the stability degree")
    return problems


class Variations(dict):
    """SecondVariation of one equilibrium by perturbation degree, built when first asked for."""

    def __init__(self, equilibrium):
        super().__init__()
        self.eq = equilibrium

    def __missing__(self, degree):
        self[degree] = SecondVariation(self.eq, int(degree))
        return self[degree]


@limited_blas
def assess_branch(branch, degree: int, symmetric: bool | None = None, check: bool = False,
                  near_zero: float | None = None, m_max: int = 0, on_point=None):
    """Assessments of every point and, with ``check``, the points whose flags change at the check degree.
    ``on_point()`` is called after each point's first assessment. A stop asked for by a signal
    (``numerics.interrupt``) raises ``interrupt.Interrupted`` at the next point: the assessment is abandoned. The
    points' first assessments and their flag checks run on every core (``numerics.workers.spread``: the numbers of
    the serial loop).

    Each point is assessed at its ``point_degrees`` (``degree`` far from wires, the degree in x that holds the
    equilibrium near one). With ``check``, the degree then follows the modes: the bracketing points of every
    crossing a branch-point search reads are raised until its eigenvalue is resolved (``crossings.follow_modes``),
    and flags are checked at ``check_degree`` of each point's degree where a sign could change: points with a
    lowest eigenvalue of magnitude below ``near_zero``, points
    next to a change of a flag, and every tenth point (``near_zero``: by default ``near_zero_of`` the scene).
    """
    symmetric = branch.disc.symmetric if symmetric is None else symmetric
    near_zero = near_zero_of(branch.scene.stability) if near_zero is None else near_zero
    variations = Variations(equilibrium_of(branch))

    def assess(n, N):
        interrupt.check()
        return variations[N].assess(branch.X[n][:-1], branch.params_at(branch.X[n]), symmetric, m_max)

    def fine_flags(n):
        interrupt.check()  # as assess: a point at the check degree costs as much (~0.3 s near a wire)
        X = branch.X[n]
        return variations[check_degree(branch, degrees[n])].flags(X[:-1], branch.params_at(X), symmetric, m_max)

    degrees = point_degrees(branch, degree)
    results = workers.spread(lambda job: assess(*job), list(enumerate(degrees)),
                             [assessment_cost(N, m_max) for N in degrees], on_point, here=first_of_each(degrees))
    unsettled = []
    if check:
        folds = branch.fold_intervals
        followed = follow_modes(results, degrees, assess, lambda N: check_degree(branch, N),
                                lambda found: branch_point_crossings(found, m_max, folds))
        results, degrees = followed.assessments, followed.degrees
        flags = [_flags(a) for a in results]
        checked = {n: _flags(a) for n, a in followed.checked.items()}
        worth = [n for n, coarse in enumerate(results) if _worth_checking(flags, coarse, n, near_zero)]
        asked = [n for n in worth if n not in checked]
        finer = [check_degree(branch, degrees[n]) for n in asked]
        checked |= zip(asked, workers.spread(fine_flags, asked, [assessment_cost(N, m_max) for N in finer],
                                             here=first_of_each(finer)))
        unsettled = [n for n in worth if checked[n] != flags[n]]
    return results, unsettled


def near_zero_of(stability) -> float:
    """The magnitude below which a lowest eigenvalue has its point's flags checked (``assess_branch``, NEAR_ZERO):
    small where every block converges spectrally (the |δx|² norm on the wire-mapped basis), else 0.1."""
    return NEAR_ZERO[stability.norm == "displacement" and stability.basis == "mapped"]


def _worth_checking(flags: list, coarse: Assessment, n: int, near_zero: float) -> bool:
    """Whether point n's flags are checked at the check degree (``assess_branch``): next to a change of a flag,
    a lowest eigenvalue of magnitude below ``near_zero``, or every tenth point."""
    changes = (n > 0 and flags[n - 1] != flags[n]) or (n + 1 < len(flags) and flags[n + 1] != flags[n])
    small = min(abs(values[0]) for values in coarse.blocks.values()) < near_zero
    return changes or small or n % 10 == 0


def first_of_each(degrees) -> list[int]:
    """The position of the first point at each degree: assessed before the others go to workers
    (``workers.spread(here=...)``), its second variation is built once and inherited."""
    first = {}
    for n, N in enumerate(degrees):
        first.setdefault(int(N), n)
    return list(first.values())


def assessment_cost(degree: int, m_max: int) -> float:
    """The relative cost of one assessment at perturbation degree N: its dense blocks, ~(1 + m_max) N³ flops."""
    return (1 + m_max) * float(degree) ** 3


def assessed_degrees(branch) -> list[int]:
    """The perturbation degree of each point's stored assessment (``Assessment.degree``: ``point_degrees``, raised
    where a crossing needed it); ``point_degrees`` at stability.degree for a branch not assessed."""
    if branch.stability is None:
        return [int(N) for N in point_degrees(branch, branch.scene.stability.degree)]
    return [a.degree for a in branch.stability]


def _flags(a: Assessment):
    return tuple(a.flags().values())
