"""Sobol and Halton against scipy.stats.qmc's points (tests/data/qmc.json), and SciPy's API."""

import warnings

import numpy as np
import pytest

import twincal


def test_sobol_is_scipys_unscrambled_sequence(qmc_reference):
    for case in qmc_reference["sobol"]:
        sobol = twincal.Sobol(case["d"], scramble=False)
        points = sobol.random(case["n"])
        assert points.shape == (case["n"], case["d"])
        np.testing.assert_array_equal(points, np.array(case["points"]), err_msg=f"d={case['d']}")


def test_halton_is_scipys_unscrambled_sequence(qmc_reference):
    for case in qmc_reference["halton"]:
        halton = twincal.Halton(case["d"], scramble=False)
        np.testing.assert_allclose(halton.random(case["n"]), np.array(case["points"]),
                                   rtol=0, atol=1e-15, err_msg=f"d={case['d']}")


def test_random_base2_reset_and_fast_forward_follow_scipy():
    sobol = twincal.Sobol(3, scramble=False)
    first = sobol.random_base2(3)
    assert first.shape == (8, 3) and sobol.num_generated == 8
    second = sobol.random_base2(3)
    sobol.reset()
    np.testing.assert_array_equal(sobol.random(8), first)
    sobol.reset()
    sobol.fast_forward(8)
    np.testing.assert_array_equal(sobol.random_base2(3), second)
    with pytest.raises(ValueError, match="multiple of 2"):
        sobol.random_base2(5)  # 16 generated, then 32: unbalanced, as SciPy refuses


def test_unbalanced_draws_warn_like_scipy():
    sobol = twincal.Sobol(2, scramble=False)
    with pytest.warns(UserWarning, match="power"):
        sobol.random(3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning):
            twincal.Sobol(2, scramble=False).random(5)


@pytest.mark.parametrize("scramble", [True, "owen"])
def test_scrambled_sobol_is_seeded_and_reproducible(scramble):
    a = twincal.Sobol(4, scramble=scramble, seed=11).random(64)
    b = twincal.Sobol(4, scramble=scramble, seed=11).random(64)
    c = twincal.Sobol(4, scramble=scramble, seed=12).random(64)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    # Scrambling keeps the net: every coordinate has one point in each of the 64 strata.
    for j in range(4):
        assert sorted(np.floor(a[:, j] * 64).astype(int)) == list(range(64))


def test_scrambled_halton_is_seeded():
    a = twincal.Halton(3, seed=5).random(10)
    np.testing.assert_array_equal(a, twincal.Halton(3, seed=5).random(10))
    assert np.all((a >= 0) & (a < 1))


def test_invalid_arguments_raise_value_errors():
    with pytest.raises(ValueError, match="dimension"):
        twincal.Sobol(0)
    with pytest.raises(twincal.InvalidArgumentError, match="dimension"):
        twincal.Sobol(21202)
    with pytest.raises(twincal.InvalidArgumentError, match="scramble"):
        twincal.Sobol(2, scramble="digital")
    with pytest.raises(ValueError, match="n"):
        twincal.Halton(2).random(-1)
    with pytest.raises(ValueError, match="m"):
        twincal.Sobol(2).random_base2(64)
