"""A tube under volume and gas control (tube/control.py, tube/stability.py) and ``continuation.stop_volume`` on every
shape (analysis/branches/control.py, tube/control.VolumeStop), against the uniform closed tube derived here.

The uniform closed tube (sliding ends) of hoop stretch λθ and axial stretch λz, Ogden membrane
Φ = Σ μ_i/α_i (λ1^α_i + λ2^α_i + (λ1λ2)^−α_i − 3): the energy per 2π of the cell of length L is
L (Φ(λz, λθ) − ½ P λθ² λz), stationary in λθ where P = Φ_2/(λθλz) and in λz (the closed ends: no axial force
beyond the pressure's on the plugs) where N = Φ_1 − λθΦ_2/(2λz) = 0: the closed-end path λz(λθ). Its enclosed
volume is V = πL λθ²λz (V0 = πL) and the gas amount n = P V = πL λθ Φ_2. Under gas control a fold of the branch in
n (LN) is where dn/dλθ = 0 along the path; under volume control a fold in V (LV) where dV/dλθ = 0, none on the
uniform path (V grows along it).
"""
import numpy as np
import pytest
from scipy import linalg, optimize

from balloon_cg.analysis.branches.control import control_value
from balloon_cg.analysis.branches.primary import trace_primary
from balloon_cg.analysis.results import Kind, StopCode
from balloon_cg.app.api import analyse
from balloon_cg.app.cli import main
from balloon_cg.galerkin.equilibrium import Equilibrium
from balloon_cg.galerkin.interval import Mirror
from balloon_cg.io.tube_file import read_tube_run, stored_branch, write_tube_run
from balloon_cg.scene import Control, SceneError, parse_scene
from balloon_cg.tube.bulge import bulge_branch
from balloon_cg.tube.primary import primary_branch
from balloon_cg.tube.stability import unstable_counts

from shared_pictures import first_bulge_picture

# SPOM1's exponents (the committed tube kernels) with a stronger α = −2 term: the closed tube's n = πL λθΦ_2 then
# has a maximum (at λθ ≈ 3.55), which no preset's has
SOFT = "[material]\nmu = [3.0, 0.0145, 0.06]\nalpha = [1.3, 4.0, -2.0]\n"


def tube(material: str, length: float, extra: str = ""):
    return parse_scene(f'{material}[geometry]\nshape = "tube"\nlength = {length}\n{extra}', "tube")


def derivatives(material, l1, l2):
    """(Φ_1, Φ_2) of the Ogden Φ written in the module docstring."""
    terms = list(zip(material.mu, material.alpha))
    return (sum(m * (l1 ** (a - 1) - l1 ** (-a - 1) * l2 ** -a) for m, a in terms),
            sum(m * (l2 ** (a - 1) - l2 ** (-a - 1) * l1 ** -a) for m, a in terms))


def closed_path(material, hoop: float) -> tuple[float, float]:
    """(λz, P) of the uniform closed tube at λθ = ``hoop``: N(λz) = 0 by Brent, P = Φ_2/(λθλz)."""
    axial = optimize.brentq(lambda z: derivatives(material, z, hoop)[0]
                            - hoop * derivatives(material, z, hoop)[1] / (2 * z), 0.2, 50.0, xtol=1e-15, rtol=1e-15)
    return axial, derivatives(material, axial, hoop)[1] / (hoop * axial)


def amount(material, hoop: float, length: float) -> float:
    """n = P V = πL λθΦ_2 on the closed-end path."""
    axial, P = closed_path(material, hoop)
    return P * np.pi * length * hoop**2 * axial


def test_uniform_tube_under_volume_control_is_stable_at_its_pressure_maximum():
    """Neo-Hookean, L = 10, volume control: the branch is the closed-end path (V = πL λθ²λz at every point, 1e-10),
    V grows at every step and no LV is located on it; at its pressure maximum (an LP, at the closed form's, 1e-10)
    the Hessian ∂R/∂u has a zero eigenvalue (|μ| < 1e-8: the LP's marginal mode, the uniform one) while on δV = 0 its
    smallest is positive (> 1e-2, Q an orthonormal basis of gᵀδ = 0 here): stable under volume control, and so
    counted (tube/stability.unstable_counts: no unstable direction under volume or gas control)."""
    scene = tube('[material]\npreset = "neo-Hookean"\n', 10.0,
                 '[solver]\ndegree = 12\n[continuation]\nstop_stretch = 1.75\n[loading]\ncontrol = "volume"\n')
    branch = primary_branch(scene)
    hoop = branch.states[:, 0]
    volume = np.array([h**2 * closed_path(scene.material, h)[0] for h in hoop])
    assert np.abs(branch.volume - volume).max() < 1e-10 and np.all(np.diff(branch.volume) > 0)
    assert not [s for s in branch.special if s.kind == Kind.LV]
    (fold,) = [s for s in branch.special if s.kind == Kind.LP]
    peak = optimize.minimize_scalar(lambda h: -closed_path(scene.material, h)[1], bounds=(1.3, 1.9),
                                    method="bounded", options={"xatol": 1e-12})
    assert abs(fold.pressure + peak.fun) < 1e-10 * fold.pressure
    eq, free = Equilibrium(scene, branch.disc), branch.disc.free
    params = branch.params.with_value("P", fold.pressure)
    H = eq.jacobian(fold.u, params)[np.ix_(free, free)]
    Q = linalg.null_space(eq.parameter_derivative(fold.u, params, "P")[free][None, :])
    assert abs(np.linalg.eigvalsh(H)).min() < 1e-8 and np.linalg.eigvalsh(Q.T @ H @ Q)[0] > 1e-2
    counts = unstable_counts(eq, [np.append(fold.u, fold.pressure)], branch.params)
    assert counts[Control.VOLUME][0] == counts[Control.GAS][0] == 0


def test_gas_control_locates_the_fold_in_the_amount():
    """SOFT, L = 2, gas control: the LN located on the uniform branch is the maximum of n = πL λθΦ_2 on the
    closed-end path (P·V within 1e-8 of it, its λθ within 1e-6); there the gas Hessian H + (P/Ṽ) g gᵀ on the uniform
    unknowns (λ2's mean, λ̄) is singular (its determinant relative to its neighbours' below 1e-6). Neo-Hookean has
    no LN: its n grows along the whole path (checked on the closed form to λθ = 4)."""
    scene = tube(SOFT, 2.0, '[solver]\ndegree = 12\n[continuation]\nstop_stretch = 3.8\nstep_max = 0.5\n'
                            '[loading]\ncontrol = "gas"\n')
    branch = primary_branch(scene)
    (fold,) = [s for s in branch.special if s.kind == Kind.LN]
    best = optimize.minimize_scalar(lambda h: -amount(scene.material, h, 2.0), bounds=(3.0, 3.8), method="bounded",
                                    options={"xatol": 1e-10})
    eq = Equilibrium(scene, branch.disc)
    n = control_value(branch.disc, np.append(fold.u, fold.pressure), Control.GAS)
    assert fold.status == "located" and abs(n + best.fun) < 1e-8 * n and abs(fold.u[0] - best.x) < 1e-6

    uniform = [0, branch.disc.axial_index]

    def gas_determinant(u, P):
        params = branch.params.with_value("P", P)
        g = -eq.parameter_derivative(u, params, "P")[uniform]
        H = eq.jacobian(u, params)[np.ix_(uniform, uniform)] + P / eq.volume(u) * np.outer(g, g)
        return np.linalg.det(H)

    neighbours = [abs(gas_determinant(branch.states[i], branch.pressure[i])) for i in (fold.index, fold.index + 1)]
    assert abs(gas_determinant(fold.u, fold.pressure)) < 1e-6 * min(neighbours)

    neo = tube('[material]\npreset = "neo-Hookean"\n', 2.0)
    hoops = np.linspace(1.01, 4.0, 400)
    assert np.all(np.diff([amount(neo.material, h, 2.0) for h in hoops]) > 0)
    neo_branch = primary_branch(neo.with_overrides({"loading.control": "gas", "solver.degree": 12,
                                                    "continuation.stop_stretch": 4.0, "continuation.step_max": 0.5}))
    assert not [s for s in neo_branch.special if s.kind == Kind.LN]


@pytest.fixture(scope="module")
def volume_run():
    """SPOM1, L = 10, degree 20, volume control, continuation.stop_volume = 5 V0: ``run``'s primary and bulge
    branches (shared_pictures.first_bulge_picture: the later branch points not switched)."""
    scene = tube('[material]\npreset = "SPOM1"\n', 10.0,
                 f'[solver]\ndegree = 20\n[continuation]\nstop_volume = {5 * np.pi * 10.0!r}\nstep_max = 0.5\n'
                 '[loading]\ncontrol = "volume"\n')
    return scene, first_bulge_picture(scene)


def test_stop_volume_ends_the_primary_and_the_bulge_branch(volume_run):
    """Both branches of ``run`` end landed on continuation.stop_volume = 5πL (V/R0³), 1e-9 relative, stop code
    stop_volume: the primary's end is the closed-end path's state with λθ²λz = 5 (λθ and P within 1e-9, solved
    here), the bulge's the first of its points past its volume fold with V = 5 V0."""
    scene, picture = volume_run
    target = 5 * np.pi * 10.0
    primary, bulge = picture.branches["primary"], picture.branches["bulge"]
    for branch in (primary, bulge):
        eq = Equilibrium(scene, branch.disc)
        assert branch.stop.code == StopCode.STOP_VOLUME
        assert abs(2 * np.pi * eq.volume(branch.states[-1]) - target) < 1e-9 * target
        assert np.all(branch.volume[:-1] < 5)
    hoop = optimize.brentq(lambda h: h**2 * closed_path(scene.material, h)[0] - 5.0, 1.5, 3.0, xtol=1e-15)
    assert abs(primary.states[-1, 0] - hoop) < 1e-9 and abs(primary.pressure[-1] - closed_path(scene.material,
                                                                                                  hoop)[1]) < 1e-9


def test_the_bulge_branch_under_volume_control_has_its_volume_fold(volume_run):
    """The bulge's LV (located): V is smallest there among its neighbours, the bordered Jacobian of the volume
    problem [[H, −g], [gᵀ, 0]] (unknowns u, P at fixed V) is singular there (smallest singular value below 1e-8,
    its neighbours' above 1e-4), and the volume reading loses its one unstable direction across it (1 → 0), the
    pressure reading keeping it."""
    scene, picture = volume_run
    bulge = picture.branches["bulge"]
    (fold,) = [s for s in bulge.special if s.kind == Kind.LV]
    assert fold.status == "located"
    eq = Equilibrium(scene, bulge.disc)
    V = 2 * np.pi * eq.volume(fold.u)
    i = fold.index
    assert V <= 2 * np.pi * min(eq.volume(bulge.states[i]), eq.volume(bulge.states[i + 1]))
    free = bulge.disc.free

    def smallest(u, P):
        params = bulge.params.with_value("P", P)
        g = -eq.parameter_derivative(u, params, "P")[free]
        J = np.block([[eq.jacobian(u, params)[np.ix_(free, free)], -g[:, None]], [g[None, :], np.zeros((1, 1))]])
        return np.linalg.svd(J, compute_uv=False)[-1]

    assert smallest(fold.u, fold.pressure) < 1e-8 < 1e-4 < min(smallest(bulge.states[j], bulge.pressure[j])
                                                               for j in (i, i + 1))
    assert bulge.unstable[Control.VOLUME][i] == 1 and bulge.unstable[Control.VOLUME][i + 1] == 0
    assert bulge.unstable[Control.PRESSURE][i] == bulge.unstable[Control.PRESSURE][i + 1] == 1


def test_tube_file_stores_every_reading_and_the_control(volume_run, tmp_path, capsys):
    """The tube run file holds unstable_gas beside the other readings and the scene's control; read back equal;
    inspect names the control, plot draws it by default and refuses an unknown reading."""
    scene, picture = volume_run
    path = write_tube_run(tmp_path / "t.h5", scene, picture)
    run = read_tube_run(path)
    assert run["attrs"]["control"] == "volume"
    for name, branch in picture.branches.items():
        back = stored_branch(run, name, branch.params)
        for control in Control:
            assert np.array_equal(back.unstable[control], branch.unstable[control])
    assert main(["inspect", str(path)]) == 0
    out = capsys.readouterr().out
    assert "control        volume" in out and "stable under volume control" in out
    image = tmp_path / "pv.png"
    assert main(["plot", str(path), "--what", "pressure-volume", "-o", str(image)]) == 0 and image.exists()


@pytest.mark.parametrize("control", ["pressure", "gas"])
def test_stop_volume_ends_a_sphere_branch(control):
    """SPOM1 sphere, continuation.stop_volume = 20 under pressure and gas control: the primary branch lands on
    V = 20 (1e-9 relative; stop code stop_volume), where λ = (3V/4π)^(1/3) and P = 2Σμ(λ^(α−3) − λ^(−2α−3))."""
    scene = parse_scene(f'[material]\npreset = "SPOM1"\n[continuation]\nstop_volume = 20.0\n[stability]\nm_max = 0\n'
                        f'[loading]\ncontrol = "{control}"\n', "sphere")
    branch = trace_primary(scene, down=False)
    assert branch.legs[0].stop.code == StopCode.STOP_VOLUME
    assert abs(control_value(branch.disc, branch.X[-1], Control.VOLUME) - 20.0) < 1e-9 * 20.0
    lam = (3 * 20.0 / (4 * np.pi)) ** (1 / 3)
    m = scene.material
    pressure = 2 * sum(mu * (lam ** (a - 3) - lam ** (-2 * a - 3)) for mu, a in zip(m.mu, m.alpha))
    assert abs(branch.X[-1, -1] - pressure) < 1e-9


def test_stop_volume_ends_a_capsule_branch_and_the_old_key_reads():
    """A SPOM1 capsule of length 2 under pressure control, continuation.stop_volume = 2 V0 (V0 = 2π + 4π/3): the
    branch lands on it (1e-9 relative); an old scene's loading.stop_volume (volume control) is the same key: the
    same branch, point for point."""
    V0 = 2 * np.pi + 4 * np.pi / 3
    capsule = ('[material]\npreset = "SPOM1"\n[geometry]\nshape = "capsule"\nlength = 2.0\n[solver]\ndegree = 32\n'
               '[stability]\nm_max = 0\n')
    scene = parse_scene(capsule + f"[continuation]\nstop_volume = {2 * V0!r}\n", "capsule")
    branch = trace_primary(scene, down=False)
    assert branch.legs[0].stop.code == StopCode.STOP_VOLUME
    assert abs(control_value(branch.disc, branch.X[-1], Control.VOLUME, scene.geometry) - 2 * V0) < 1e-9 * 2 * V0
    new = parse_scene(capsule + f'[continuation]\nstop_volume = {2 * V0!r}\n[loading]\ncontrol = "volume"\n', "c")
    old = parse_scene(capsule + f'[loading]\ncontrol = "volume"\nstop_volume = {2 * V0!r}\n', "c")
    assert old.continuation.stop_volume == new.continuation.stop_volume == 2 * V0 and old.loading == new.loading
    assert np.array_equal(trace_primary(old, down=False).X, trace_primary(new, down=False).X)


@pytest.mark.parametrize("text, message", [
    ("[continuation]\nstop_volume = -1.0\n", r"continuation.stop_volume = -1.0: must be > 0 \(V/R0³\)$"),
    ('[continuation]\nstop_volume = "big"\n', r'continuation.stop_volume = "big": must be a number$'),
    ("[loading]\nstop_volume = 0.0\n", r"loading.stop_volume = 0.0: must be > 0 \(V/R0³; the old name of "
                                        r"continuation.stop_volume\)$"),
    ("[loading]\nstop_volume = 3.0\n[continuation]\nstop_volume = 4.0\n",
     r"loading.stop_volume = 3.0: the old name of continuation.stop_volume, which is given too \(4.0\); give "
     r"continuation.stop_volume only$"),
])
def test_bad_stop_volume_is_one_line(text, message, tmp_path, capsys):
    """One line naming the key, the value and the range; the CLI exits 2 and writes no file."""
    with pytest.raises(SceneError, match=message) as error:
        parse_scene('[material]\npreset = "SPOM1"\n' + text, "bad")
    assert "\n" not in str(error.value)
    path = tmp_path / "bad.toml"
    path.write_text('[material]\npreset = "SPOM1"\n[geometry]\nshape = "tube"\nlength = 10.0\n' + text)
    assert main(["run", str(path), "-o", str(tmp_path / "bad.h5")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1 and not (tmp_path / "bad.h5").exists()


@pytest.mark.parametrize("geometry, volume, reference", [
    ('shape = "tube"\nlength = 20.0\n', 50.0, "62.8319 (the tube of length 20 with sliding ends"),
    ('shape = "tube"\nlength = 10.0\nends = "plugged"\naxial_stretch = 1.2\n', 31.4159,
     "31.4159 (the tube of length 10 with plugged ends held at 1.2 L"),
    ('shape = "capsule"\nlength = 2.0\n', 10.47, "10.472 (the capsule of length 2"),
    ('shape = "spheroid"\naspect = 1.5\n', 6.0, "6.28319 (the spheroid of aspect 1.5"),
    ('shape = "sphere"\n', 3.0, "4.18879 (the sphere"),
])
def test_stop_volume_at_or_below_the_reference_volume_is_one_line(geometry, volume, reference, tmp_path, capsys):
    """continuation.stop_volume is V/R0³, not V/V0: a value at or below the reference volume (πL, πL + 4π/3,
    4π/3 · aspect) would end the branch at its start, landed backwards into compression (a tube of length 20 given
    stop_volume = 60 traced P down to −0.19 and switched m = 1 branches there): one line naming the key, the
    value and the allowed range; the CLI exits 2 and keeps an existing output file."""
    text = f'[material]\npreset = "SPOM1"\n[geometry]\n{geometry}[continuation]\nstop_volume = {volume!r}\n'
    message = (f"continuation.stop_volume = {volume!r}: at or below the reference volume {reference}; V/R0³, not "
               f"V/V0); must be > {reference.split()[0]}")
    with pytest.raises(SceneError) as error:
        parse_scene(text, "small")
    assert str(error.value) == f"small: {message}"
    path, out = tmp_path / "small.toml", tmp_path / "small.h5"
    path.write_text(text)
    out.write_bytes(b"kept")
    assert main(["run", str(path), "-o", str(out), "--force"]) == 2
    assert capsys.readouterr().err.strip() == f"balloon-cg: error: {path.name}: {message}"
    assert out.read_bytes() == b"kept"


def test_bulge_branch_under_gas_control_lands_on_stop_volume():
    """SPOM1, L = 10, degree 20, gas control: the bulge switched at the onset passes its LV, then its fold in n (LN),
    across which the gas reading loses its unstable direction (1 → 0: a bulge holding a fixed amount of gas is
    stable past it), and ends landed on continuation.stop_volume = 3 V0 (1e-9 relative)."""
    scene = tube('[material]\npreset = "SPOM1"\n', 10.0,
                 '[solver]\ndegree = 20\n[continuation]\nstop_stretch = 1.75\n[loading]\ncontrol = "gas"\n')
    primary = primary_branch(scene)
    target = 3 * np.pi * 10.0
    bulge = bulge_branch(scene.with_overrides({"continuation.stop_volume": target}), primary,
                         primary.branch_points(Mirror.ODD)[0], step=0.02)
    assert bulge.stop.code == StopCode.STOP_VOLUME and abs(bulge.volume[-1] * np.pi * 10.0 - target) < 1e-9 * target
    assert [s.kind for s in bulge.special] == [Kind.LV, Kind.LN]
    i = bulge.special[1].index
    assert bulge.unstable[Control.GAS][i] == 1 and bulge.unstable[Control.GAS][i + 1] == 0


def test_stop_volume_on_held_and_plugged_ends():
    """Ends held at λz = 1.5 (sliding; volume control): the primary branch is uniform at λz = 1.5 and ends landed on
    stop_volume = 4πL at λθ = sqrt(4/1.5), P = Φ_2(1.5, λθ)/(1.5 λθ) (1e-9); plugged ends (gas control): landed too
    (1e-9), past the plugged tube's pressure fold, stable under gas control there (its LP is no fold of n)."""
    held = tube('[material]\npreset = "SPOM1"\n', 10.0, 'axial_stretch = 1.5\n[solver]\ndegree = 20\n'
                f'[continuation]\nstop_volume = {40 * np.pi!r}\n[loading]\ncontrol = "volume"\n')
    branch = primary_branch(held)
    hoop = np.sqrt(4 / 1.5)
    assert branch.stop.code == StopCode.STOP_VOLUME and abs(branch.volume[-1] - 4) < 1e-9 * 4
    assert abs(branch.states[-1, 0] - hoop) < 1e-9
    assert abs(branch.pressure[-1] - derivatives(held.material, 1.5, hoop)[1] / (1.5 * hoop)) < 1e-9
    plugged = tube('[material]\npreset = "SPOM1"\n', 10.0, 'ends = "plugged"\n[solver]\ndegree = 30\n'
                   f'[continuation]\nstop_volume = {40 * np.pi!r}\n[loading]\ncontrol = "gas"\n')
    branch = primary_branch(plugged)
    assert branch.stop.code == StopCode.STOP_VOLUME and abs(branch.volume[-1] - 4) < 1e-9 * 4
    assert [s.kind for s in branch.special] == [Kind.LP] and not branch.unstable[Control.GAS].any()
    assert branch.unstable[Control.PRESSURE][-1] > 0


def test_stop_volume_ends_the_spheres_pear_branches():
    """SPOM1 sphere under pressure control, continuation.stop_volume = 40 (the pear branches reach V = 44.8 at
    stop_stretch 5 without it): ``analyse`` ends the primary branch and both pear branches landed on V = 40 (1e-9)."""
    scene = parse_scene('[material]\npreset = "SPOM1"\n[continuation]\nstop_volume = 40.0\n[stability]\nm_max = 0\n',
                        "sphere")
    branches = analyse(scene).picture.branches
    assert [b.name for b in branches] == ["primary", "pear_0", "pear_0_mirror"]
    for branch in branches:
        assert branch.legs[0].stop.code == StopCode.STOP_VOLUME
        assert abs(control_value(branch.disc, branch.X[-1], Control.VOLUME) - 40.0) < 1e-9 * 40.0
