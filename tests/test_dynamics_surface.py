"""Natural frequencies of a surface branch (dynamics.surface): its sectors' Ω² against the axisymmetric blocks at
its birth point, zero at its located special points, stored and read back.

Units (docs/dynamics.md). The whole-sphere stability solves H c = μ G c in each symmetry sector, H the Hessian of
the energy per 2π with moduli over μ/2 and G = (1/2π)∫∫|δu|² dA the displacement norm; the axisymmetric blocks solve
K q = ν M q with the same units for K and M the kinetic energy per 2π over ½ρT0R0⁴, (1/2π)∫∫|δx|² dA: both are
the same quadratic forms of the same displacement, so μ and ν are the same numbers and Ω² = μ/2 = ν/2. The test
below checks that claim: the sectors' Ω² (μ/2) at an axisymmetric state against the axisymmetric blocks' (ν/2).

Which modes are in which sector. At an axisymmetric state a perturbation δx = R cos mφ e_ρ + T sin mφ e_φ +
Z cos mφ e_z (the cos family of order m: the axisymmetric block m, m = 0 its (δρ, δz) alone) keeps the mirror
y → −y; the sin family (δρ, δz ∝ sin mφ, δφ ∝ cos mφ) is odd under it and has the same spectrum for m ≥ 1, with
the torsion δφ(θ) (m = 0) that no axisymmetric block holds. So the sectors even under the mirror together hold
exactly the modes of the blocks even, odd_held and m<m>_held, m ≥ 1 (held: the translations and, at M = 0, the
rigid rotations removed in both).
"""
import json
from dataclasses import replace
from pathlib import Path

import h5py
import numpy as np
import pytest

import balloon_cg as bc
from balloon_cg.analysis.picture import analyse
from balloon_cg.analysis.results import Block, Kind, Status
from balloon_cg.analysis.surface.branches import rotated, trace_surface
from balloon_cg.app.cli import main
from balloon_cg.dynamics.frequencies import attach
from balloon_cg.dynamics.surface import sector_block, surface_matching_block
from balloon_cg.io.run_file import write_run
from balloon_cg.scene import load_scene
from balloon_cg.surface.basis import MIRROR_Y
from netcdf_groups import uncoordinated

ROOT = Path(__file__).resolve().parent.parent
COUNT, M_MAX = 4, 3


@pytest.fixture(scope="module")
def m1_run(tmp_path_factory):
    """SPOM1 at M = 0 with [dynamics] frequencies (count 4, m_max 3): the primary branch to a pole stretch of 3 (its
    LP and pear BP), the branch born at the m = 1 copy of the pear point traced 6 points on the whole sphere and its
    image under the rotation by π, frequencies attached, written to a run file."""
    scene = load_scene(ROOT / "scenes" / "spom1.toml").with_overrides(
        {"continuation.stop_stretch": 3.0, "surface.branches": "none", "dynamics.frequencies": True,
         "dynamics.count": COUNT, "dynamics.m_max": M_MAX})
    primary = analyse(scene, pear=False).primary
    k, bp = next((k, s) for k, s in enumerate(primary.branch_points()) if s.block == Block.ODD_HELD)
    branch = trace_surface(primary, k, replace(bp, m=1, block=Block.M1_HELD), 1.0, "m1", 6)
    image = rotated(branch, "m1_rotated")
    branches = [primary, branch, image]
    attach(branches, COUNT, M_MAX)
    path = write_run(tmp_path_factory.mktemp("surface_dynamics") / "m1.h5", scene, branches)
    return primary, branch, image, bp, path


def test_sectors_at_the_birth_point_hold_the_axisymmetric_blocks(m1_run):
    """At point 0 (the pear point's state solved on the whole sphere at its P*) the sectors even under the mirror
    y → −y, held under pressure control, together hold the modes of the primary's held blocks at that point (module
    docstring): each of their stored Ω² is an Ω² of a block, and the lowest COUNT of all of them, with
    multiplicity, are the lowest COUNT of the blocks (m = 0..M_MAX: the sphere's degree-n modes are in m ≤ n, and
    block m_max + 1 = 4 starts at degree 4, above them). Tolerance: both are spectra of the sphere of radius λ(P*),
    whose modes are spherical harmonics of degree ≤ 3, exact in the surface basis (L = 16) and in the axisymmetric
    one (N ≥ 20); the two states are the same sphere to the solver's tolerance 1e-11 (point 0's residual, the BP's
    location), and an Ω² moves with the state by an O(1) factor (|dΩ²/dλ| ~ 10 here): 1e-9 is that, with room
    (observed ~1e-12)."""
    primary, branch, _, bp, _ = m1_run
    n = next(n for n, s in enumerate(primary.special) if s is bp)
    blocks = ["even", "odd_held"] + [f"m{m}_held" for m in range(1, M_MAX + 1)]
    axisymmetric = np.sort(np.concatenate([primary.frequencies.special[b][n] for b in blocks]))
    mirror = branch.basis.symmetry.index(MIRROR_Y)
    sectors = [key for key in branch.sectors["held"] if key[mirror] == 1]
    assert len(sectors) == 2  # (mirror, equator): the equator-even and -odd halves
    whole = np.concatenate([branch.frequencies.omega2[sector_block("held", key)][0] for key in sectors])
    assert abs(branch.values[0] - bp.X[-1]) < 1e-12 and np.isfinite(whole).all()
    assert np.abs(whole[:, None] - axisymmetric[None, :]).min(axis=1).max() <= 1e-9
    np.testing.assert_allclose(np.sort(whole)[:COUNT], axisymmetric[:COUNT], rtol=0, atol=1e-9)
    # the same at the special point's own state (solved again on the branch's basis)
    np.testing.assert_allclose(branch.frequencies.special["held_++"][0], branch.frequencies.omega2["held_++"][0],
                               rtol=0, atol=1e-10)


def test_located_special_points_have_a_vanishing_frequency_in_their_sector(m1_run):
    """At every located fold and branch point of the surface branches one Ω² of its sector and reading
    (``surface_matching_block``) is zero to the solver's tolerance: here the birth point (a BP, the branch's own
    sector, held_++ at M = 0), on the branch and on its rotated image (whose points' Ω² are copied, its special
    points' solved at its own states)."""
    _, branch, image, _, _ = m1_run
    checked = 0
    for b in (branch, image):
        for n, s in enumerate(b.special):
            block = surface_matching_block(s, b)
            if block is None or s.status != Status.LOCATED:
                continue
            assert np.min(np.abs(b.frequencies.special[block][n])) <= b.scene.solver.tol, (b.name, s, block)
            checked += 1
    assert checked == 2 and branch.special[0].kind == Kind.BP
    np.testing.assert_array_equal(image.frequencies.omega2["held_+-"], branch.frequencies.omega2["held_+-"])
    np.testing.assert_allclose(image.frequencies.special["held_+-"], branch.frequencies.special["held_+-"],
                               rtol=0, atol=1e-10)


def test_surface_frequencies_are_stored_and_read_back(m1_run, capsys):
    """frequencies/omega2_<reading>_<signs> (point, frequency) and special_omega2_… (special, frequency) of a surface
    branch, units "1", checksummed; bc.load, to_xarray, inspect (a table at the special points) and --json give
    them back as computed."""
    _, branch, _, _, path = m1_run
    with h5py.File(path, "r") as f:
        group = f["branches/m1/frequencies"]
        assert group.attrs["count"] == COUNT
        assert group["omega2_held_++"].attrs["units"] == "1" and group["omega2_held_++"].fletcher32
        assert group["special_omega2_free_gas_--"].shape == (len(branch.special), COUNT)
    loaded = bc.load(path)
    data = loaded.branches["m1"].data
    assert data["frequencies"].keys() == branch.frequencies.omega2.keys()
    for block, values in branch.frequencies.omega2.items():
        np.testing.assert_array_equal(data["frequencies"][block], values)
        np.testing.assert_array_equal(data["special_frequencies"][block], branch.frequencies.special[block])
    frame = loaded.to_xarray("m1")
    assert frame["omega2_held_+-"].dims == ("point", "frequency")
    np.testing.assert_array_equal(frame["omega2_held_+-"].values, branch.frequencies.omega2["held_+-"])
    assert uncoordinated(path) == []
    assert main(["inspect", str(path)]) == 0
    text = capsys.readouterr().out.split("surface branch m1 ")[1].split("\nsurface branch ")[0]
    assert "lowest Ω² = ω² R0² ρ/μ per block at the special points" in text and "held_++" in text
    assert main(["inspect", str(path), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)["branches"]["m1"]
    assert summary["frequencies"]["held_++"] == pytest.approx(branch.frequencies.omega2["held_++"][:, 0], abs=0)
    assert "translation_omega2" not in summary


def test_a_damaged_surface_frequency_group_is_exit_2(m1_run, tmp_path, capsys):
    """A surface branch's special_omega2 dataset with a row too few: one line naming it, exit 2."""
    *_, path = m1_run
    damaged = tmp_path / "damaged.h5"
    damaged.write_bytes(path.read_bytes())
    with h5py.File(damaged, "r+") as f:
        group = f["branches/m1/frequencies"]
        values = group["special_omega2_held_++"][()]
        del group["special_omega2_held_++"]
        group.create_dataset("special_omega2_held_++", data=values[:-1])
    assert main(["inspect", str(damaged)]) == 2
    assert "special_omega2_held_++" in capsys.readouterr().err
