"""Issue 28's constraint: every stored eigenvalue, flag and located point of the shipped scenes' whole picture is
today's to 1e-10 (tests/stability_reference.py made the table with main's code before the stability work)."""
import numpy as np
import pytest

from stability_reference import REFERENCE, scene_table

TOLERANCE = 1e-10


@pytest.mark.parametrize("scene", ["spom1", pytest.param("spom1_two_coils_M0.002", marks=pytest.mark.slow)])
def test_picture_is_the_reference(scene):
    with np.load(REFERENCE) as stored:
        expected = {key: stored[key] for key in stored.files if key.startswith(f"{scene}/")}
    found = scene_table(scene)
    assert sorted(found) == sorted(expected)
    for key, values in expected.items():
        if values.dtype.kind in "US":  # a special point's kind, block, m, status, classification and index
            assert str(found[key]) == str(values), key
        else:
            assert found[key].shape == values.shape, key
            np.testing.assert_allclose(found[key].astype(float), values.astype(float), rtol=0, atol=TOLERANCE,
                                       err_msg=key)
