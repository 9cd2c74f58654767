"""Issue 37's "unchanged": the whole picture of every shipped scene and of the off-equator scene against the tables
main made at 94ce54e (tests/stability_reference.py), and issue 38's: those and a Gent scene (tests/data/gent.toml)
against the tables of main before the reference meridian became data: the same special points (kind, block, m, status,
classification, interval), every located point and stored eigenvalue within max(1e-9 relative, its own error
estimate) of the table's, the unsettled points the same, and every stability flag identical except at points whose
deciding eigenvalue is within its own error estimate of zero (the test lists them). The scenes with coils are
studies (one to two minutes each): ``-m slow``.

The tables hold the m = 0 eigenvalues in 94ce54e's only norm, ∫(δλ2² + δη²) d(cos θ); the default norm is now
|δx|² (stability.norm = "displacement", docs/numerics.md §4), in which the same blocks have other eigenvalues with
the same inertia. Those blocks are compared by their signs: the number of negative ones among the stored lowest
at every point (``M0_BLOCKS``), as the flags are; their values are checked against an independent basis by
tests/test_stability_basis.py. The m ≥ 1 blocks and the surface branches' readings were |δx|² already and compare
by value.

Re-recorded with the default norm, after checking them against 94ce54e's (docs/numerics.md §4): tpom1 between the
two coils at M = 0.001 and 0.002, whose free pear branch is now traced through other points on another wire map
(its switch reads the critical mode of the mapped basis): every label and flag identical, every special point's P
within 2e-12 relative; the raw coefficients and the eigenvalues at a point index compare other points. The paper
coil: every label and flag identical; its m1_free point next to the wire at P 1.80595332 (main's 1.80595334 carried
its x-basis gap: the crossing eigenvalue there is −1.4e-8 in x at 400 and on the map); the m1_free eigenvalues of
the primary's last points moved by up to 7.8e-8 (main's at x-degree 320, unconverged there; now the map's at 67);
pear_0_mirror's rejoin point is the reflected state on the mirrored map (issue 39: 94ce54e stored the pear's
coefficients there, another state on that map). The off-equator scene (session 23): its broken pear's legs start on
the wire map of the continued point at the scene's degree instead of the seed's plain degree 320, so the branch is
traced through other points (54 instead of 76, stored at degree 90): its four special points the same (kinds,
labels, status), their P within 8.6e-10 (the fold 2.2e-13), the unstable count of every block the same sequence
along the branch; the other branches unchanged. The paper coil (session 23), when `stability.banded_from = 225`
became the default (its points at degree ≥ 225 read on the banded sibling blocks): every label, flag and special
point identical, every eigenvalue within its error estimate of the table's (largest change 5.8e-6, where the
estimates reach 8e-5) but one: pear_free_2's point 36 (and its mirror), second m1_free eigenvalue, 1.46e-9 from the
table's −0.044649472758, where the rule allows 1.1e-9. The elements are right there: 40 to 120 elements of order
12 and 16 give −0.0446494742213 within 1.3e-12 of each other, while the dense Legendre blocks at degrees 213, 320,
400, 480 and 560 scatter by 2e-9 with no trend in the degree (the dense eigensolver's rounding ε‖H‖ at these
sizes; docs/numerics.md §4).

Re-recorded in session 26, when ``Tracer._refine`` came to keep the current wire map at a degree step unless the
re-centred one's tail estimate is below half the current's (``Resolution.clearly_lower``): before, the smaller of two
estimates both at their rounding floor won, and the BLAS kernels chose. Session 25 found spom1_single_coil and
tpom1_two_coils_M0.002 failing on its machine (numpy 2.4.6, scipy 1.17.1, OpenBLAS 0.3.31 picking its Haswell kernels
on an AMD EPYC) at the commits that recorded them; benchmarks/results/refine_choice.txt shows both pictures' decisions
the same under the Haswell, Sandybridge and Nehalem kernels now, different ones before. tpom1_two_coils_M0.002 passes
again unchanged: at pear_free_1's point 27 (P 2.245873, degree 135 -> 202) the current map (widths 0.16903, 0.23597;
T 2.804e-11 here) is kept over the re-centred one (0.18979, 0.24705; 2.789e-11 here, 2.504e-11 with Sandybridge's
kernels, 2.542e-11 with Nehalem's), the choice of the machine that recorded its table. tpom1_two_coils_M0.001
passes unchanged: at its pear_free_1's point 27 (P 2.255091, 135 -> 202) the current map (T 2.224e-11) is kept now
over the re-centred one (2.088e-11), so the branch is stored on another map, but every sample agrees to 1e-12 and
every stored number within the rule. Moved, re-recorded:
spom1_single_coil: at the primary's point 67 (P 0.876362, degree 40 -> 60) the current map (width 0.06672,
T 1.087e-13) is kept over the re-centred one (0.05710, 1.123e-13; with Sandybridge's kernels 1.439e-13 and
0.910e-13, which kept the re-centred map and made the old table: main under OPENBLAS_CORETYPE=Sandybridge reproduces
it). The primary's samples agree to point 67, then follow the other map and reach wire_gap after 75 points instead
of 74, stored on the map of width 0.02339 (was 0.02725); every other branch has the same samples; against main under
Sandybridge every special point's λ2 and η on a 2001-point θ grid are within 7.8e-12 and its P within 3.3e-12 but
two: the TP at point 71 (P 3.5e-10 apart, λ2 1.6e-9, η 2.9e-10) and the wire-gap end point (the first sample inside
the gap: P 0.84200 against 0.84084, where the samples fall). Neither map is the better one (both estimates at the
floor, four orders below max_error); the new one is the one every kernel keeps. off_equator: on its broken pear at
P 1.681873 (degree 60 -> 90) the current map (width 0.03280, T 1.630e-13) is kept over the re-centred one (0.03213,
1.219e-13; ratio 1.34, both at the floor); the samples agree to point 49 of 54, the branch is stored on the map of
width 0.03280 (was 0.03213), and its eigenvalues compared by point index differ from point 50 on (other samples, up
to 0.0147); its four special points (labels the same) have λ2 and η within 4.6e-13 and P within 5.6e-14 but the end
point (EP, point 53): P 1.3e-11, λ2 7.5e-11, η 3.6e-11 apart; the primary is identical. spom1_two_coils_M0.003: at the
primary's point 48 (P 2.068692, degree 60 -> 90) the current map (width 0.09438, T 1.553e-13) is kept over the
re-centred one (0.08478, 1.519e-13; ratio 1.02, both at the floor); the samples agree to 4.4e-16 up to point 48 (the
start point's P to 1.9e-12), then follow the other map and reach wire_gap after 55 points instead of 56 (the end
point, the first sample inside the gap, at P 1.80413 against 1.77212); against main every special point's λ2 and η on
a 2001-point θ grid are within 1.9e-10 and its P within 8.9e-11 (the pear branches' m1_free BPs; the primary's within
2.9e-11 and 2e-12) but the primary's TP at point 51 (P 3.5e-10, λ2 1.4e-10, η 7e-11 apart) and that end point; the
m1_bp0 surface branch's four special points keep their labels and P within 9.3e-13, one coefficient of each 4.7e-5
apart (its basis follows the primary's storage map); every other stored number within the rule. The three
re-recorded tables pass under OPENBLAS_CORETYPE=Sandybridge as under the default kernels.

Session 30: a surface branch's special points compare by their state sampled off the poles (``x``,
stability_reference.SAMPLES) and their P, no longer by their coefficients, which are of the branch's final basis, whose
wire map the trace's chain of refinements chooses. A trace that carries the point its resolution stop rejects to the
finer basis (``surface.branches.follow``) ends the paper coil's m1_bp0 on another map than main's (centres ±0.003325,
width 0.037484 against ±0.003226, 0.037478): the same 12 points (P within 1.8e-13, eigenvalues within the rule), its
three special points' coefficients 1.3e-5 apart. Their states agree to 1.4e-12 on SAMPLES, 2.2e-12 on a 2001 × 3
(θ, φ) grid but at the north pole, 2.6e-8 apart, which is not the states': main's map evaluates s(1) = 1 − 2.2e-16, one ulp short, where the
m ≥ 1 polar functions (∝ √(1 − s²)) are 2.1e-8 instead of 0; with s(±1) = ±1 exactly the two agree to 5.8e-13 there
too. An independent finer solve (degree 72, order 58; the LP on the hyperplane normal to its tangent, the EP at fixed P)
moves P by 1e-14 and the state off the poles by 1.8e-11 (LP) and 1.7e-9 (EP, whose basis' tail stopped the branch at
6e-9), and keeps at the pole the value of the map it is solved on. The ``x`` of the stored tables are main 33619c6's
(whose pictures pass every stored table), added beside the stored numbers, none of which changed.
"""
import numpy as np
import pytest

from stability_reference import SCENES, reference_path, scene_table

from balloon_cg.analysis.stability.axisymmetric import FLAGS

RELATIVE = 1e-9
M0_BLOCKS = {"even", "even_volume", "even_gas", "odd_held", "odd_free", "all_held", "all_volume_held", "all_gas_held",
             "all_free", "all_volume_free", "all_gas_free"}  # stored in the norm "unknowns" (module docstring)
QUICK = {"spom1", "spom2", "fpom1", "fpom2", "tpom1", "tpom2", "gent"}  # no coils: a second or a few each


def within(found, expected, error) -> np.ndarray:
    """Where |found − expected| ≤ max(1e-9·max(1, |expected|), error), elementwise."""
    return np.abs(found - expected) <= np.maximum(RELATIVE * np.maximum(1.0, np.abs(expected)), error)


def compare(found: dict, expected: dict) -> list[str]:
    """What differs between a fresh table and the stored one beyond the rule of the module docstring (flag
    changes allowed there are listed with a leading "allowed")."""
    problems = []
    names = lambda table: {k for k in table if not k.split("/")[-1].startswith(("error_", "degrees"))}
    if names(found) != names(expected):
        return [f"entries differ: only stored {sorted(names(expected) - names(found))}, "
                f"only found {sorted(names(found) - names(expected))}"]
    for key, values in expected.items():
        branch, entry = key.rsplit("/", 1)
        if entry.startswith(("error_", "degrees")):
            continue
        if values.dtype.kind in "US":
            if str(found[key]) != str(values):
                problems.append(f"{key}: {found[key]} != {values}")
        elif entry == "unsettled":
            if not np.array_equal(found[key], values):
                problems.append(f"{key}: {found[key].tolist()} != {values.tolist()}")
        elif entry == "X":
            moved = found[key]
            if f"{branch}/x" in expected:  # a surface branch's point: its state sampled, and its P (module docstring)
                moved, values = (np.append(table[f"{branch}/x"], table[key][-1]) for table in (found, expected))
            error = max(float(expected[f"{branch}/uncertainty"]), RELATIVE * max(1.0, np.abs(values).max()))
            if np.abs(moved - values).max() > error:
                problems.append(f"{key}: moved by {np.abs(moved - values).max():.3g} (allowed {error:.3g})")
        elif entry.removeprefix("lowest_") in M0_BLOCKS:
            changed = np.flatnonzero((found[key] < 0).sum(axis=1) != (values < 0).sum(axis=1))
            problems += [f"{'allowed' if _near_zero(expected, branch, n) else 'changed'}: {key} point {n}: "
                         f"{int((found[key][n] < 0).sum())} negative, stored {int((values[n] < 0).sum())}"
                         for n in changed]
        elif entry.startswith("lowest_"):
            error = expected.get(f"{branch}/error_{entry.removeprefix('lowest_')}", 0.0)
            bad = ~within(found[key], values, error)
            if bad.any():
                problems.append(f"{key}: {bad.sum()} eigenvalues moved beyond their error, the largest by "
                                f"{np.abs(found[key] - values)[bad].max():.3g}")
        elif entry == "flags":
            problems += _flag_changes(found, expected, branch)
    return problems


def _flag_changes(found: dict, expected: dict, branch: str) -> list[str]:
    """The flags that changed: allowed at a point where some stored lowest eigenvalue is within its error (and
    1e-9) of zero (``_near_zero``), a problem elsewhere."""
    old, new = expected[f"{branch}/flags"], found[f"{branch}/flags"]
    return [f"{'allowed' if _near_zero(expected, branch, n) else 'changed'}: {branch} point {n} {FLAGS[flag]}"
            for n, flag in zip(*np.nonzero(old != new))]


def _near_zero(expected: dict, branch: str, n: int) -> list[str]:
    """The blocks of ``branch`` whose stored lowest eigenvalue at point n is within max(1e-9, its error) of 0."""
    out = []
    for key, values in expected.items():
        if key.startswith(f"{branch}/lowest_"):
            block = key.removeprefix(f"{branch}/lowest_")
            error = expected.get(f"{branch}/error_{block}")
            if abs(values[n, 0]) <= max(RELATIVE, 0.0 if error is None else float(error[n, 0])):
                out.append(block)
    return out


def _scenes():
    return [name if name in QUICK else pytest.param(name, marks=pytest.mark.slow) for name in SCENES]


@pytest.mark.parametrize("scene", _scenes())
def test_picture_is_unchanged(scene):
    with np.load(reference_path(scene)) as stored:
        expected = {key: stored[key] for key in stored.files}
    problems = compare(scene_table(scene), expected)
    allowed = [p for p in problems if p.startswith("allowed")]
    if allowed:
        print("\n".join(allowed))
    assert not [p for p in problems if not p.startswith("allowed")], problems


def test_compare_sees_a_moved_eigenvalue_and_a_changed_label():
    """The comparison fails where it should: an m ≥ 1 eigenvalue moved beyond 1e-9, an m = 0 one that changed
    sign, a label changed, a flag flipped away from zero, a surface branch's special point whose state or P moved;
    and lets an m ≥ 1 eigenvalue move within its stored error estimate, the m = 0 ones change their values (another
    norm) with their signs, and a surface branch's special point change its coefficients (another basis) with its
    state."""
    with np.load(reference_path("spom1")) as stored:
        expected = {key: stored[key] for key in stored.files}
    assert compare(dict(expected), expected) == []
    key = "primary/lowest_even"
    scaled = dict(expected, **{key: 3.0 * expected[key]})  # another norm: the same signs
    assert compare(scaled, expected) == []
    n = int(np.argmax(np.abs(expected[key][:, 0])))
    flipped = expected[key].copy()
    flipped[n, 0] = -flipped[n, 0]
    assert any(p.startswith("changed") and key in p for p in compare(dict(expected, **{key: flipped}), expected))
    with np.load(reference_path("spom1_two_coils_M0.002")) as stored:
        coils = {key: stored[key] for key in stored.files}
    key = "primary/lowest_m1_held"
    moved = dict(coils, **{key: coils[key] + 1e-7})
    assert any(p.startswith(key) for p in compare(moved, coils))
    assert compare(moved, dict(coils, **{"primary/error_m1_held": np.full_like(coils[key], 2e-7)})) == []
    special = next(k.removesuffix("/x") for k in coils if k.endswith("/x"))  # a surface branch's point
    X, x = coils[f"{special}/X"], coils[f"{special}/x"]
    other_basis = np.append(X[:-1] + 1e-5, X[-1])  # coefficients of another basis, the same state
    assert compare(dict(coils, **{f"{special}/X": other_basis}), coils) == []
    assert any(p.startswith(f"{special}/X") for p in compare(dict(coils, **{f"{special}/x": x + 1e-7}), coils))
    assert any(p.startswith(f"{special}/X") for p in compare(dict(coils, **{f"{special}/X": X + 1e-7}), coils))
    label = next(k for k in expected if k.endswith("/label"))
    assert compare(dict(expected, **{label: np.array("LP even m=0 located fold index=0")}), expected)
    flags = expected["primary/flags"].copy()
    flags[n, 0] = not flags[n, 0]
    assert any(p.startswith("changed") for p in compare(dict(expected, **{"primary/flags": flags}), expected))
