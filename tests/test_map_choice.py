"""The tracer's choice of basis map when a leg's degree grows (``Resolution.clearly_lower``): the current map is kept
unless the re-centred one's tail estimate T is lower by the factor map_gain = 2, so that two maps both at T's
rounding floor are not told apart by the BLAS kernels' rounding. The readings are the measured ones of
benchmarks/results/refine_choice.txt under three OpenBLAS kernel sets (Haswell, Sandybridge, Nehalem): at the
first two the old rule (the smaller T) chose by the kernels; at the third the session-25 machine's kernels kept the
current map and these the re-centred one (tests/test_stability_reference.py); the fourth is decided by content."""
import pytest

from balloon_cg.analysis.branches.resolution import Resolution

POLICY = Resolution(max_error=1e-9, max_degree=320)

# (current T, re-centred T) per kernel set at one decision, and whether the re-centred map is kept
MEASURED = {
    "spom1_single_coil primary P 0.876362, 40 -> 60": (
        [(1.087e-13, 1.123e-13), (1.439e-13, 9.097e-14), (1.4e-13, 1.226e-13)], False),
    "tpom1_two_coils_M0.002 P 2.227278, 90 -> 135": (
        [(7.975e-12, 8.081e-12), (8.43e-12, 8.671e-12), (8.753e-12, 7.869e-12)], False),
    "tpom1_two_coils_M0.002 pear_free_1 P 2.245873, 135 -> 202": (
        [(2.804e-11, 2.789e-11), (2.813e-11, 2.504e-11), (2.737e-11, 2.542e-11)], False),
    "tpom1_two_coils_M0.002 P 2.232320, 90 -> 135 (x against a map)": (
        [(1.102e-11, 4.563e-12), (1.102e-11, 4.379e-12), (1.102e-11, 4.235e-12)], True),
}


@pytest.mark.parametrize("decision", MEASURED)
def test_the_choice_is_the_same_under_every_kernel_set(decision):
    readings, recentred = MEASURED[decision]
    assert [POLICY.clearly_lower(new, current) for current, new in readings] == [recentred] * len(readings)


@pytest.mark.parametrize("current, recentred, replaced", [
    (2.0e-11, 0.99e-11, True), (2.0e-11, 1.01e-11, False), (1.0e-13, 1.0e-15, True), (1.0e-11, 1.2e-11, False)])
def test_a_map_replaces_the_current_one_only_below_half_its_estimate(current, recentred, replaced):
    assert POLICY.clearly_lower(recentred, current) is replaced
