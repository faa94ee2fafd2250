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


def test_zero_dimensions_give_empty_samples_as_in_scipy():
    for engine in (twincal.Sobol(0), twincal.Halton(0, scramble=False)):
        assert engine.random(4).shape == (4, 0)
        assert engine.num_generated == 4
        assert engine.reset().num_generated == 0


def test_seeds_are_recorded_and_generators_accepted():
    a = twincal.Sobol(3, seed=np.random.default_rng(1))
    b = twincal.Sobol(3, seed=a.scramble_seed)
    np.testing.assert_array_equal(a.random(16), b.random(16))
    assert twincal.Sobol(3, seed=11).scramble_seed == 11
    fresh = twincal.Halton(2)  # seed None: fresh entropy, as in SciPy, and recorded
    np.testing.assert_array_equal(fresh.random(8),
                                  twincal.Halton(2, seed=fresh.scramble_seed).random(8))
    with pytest.raises(twincal.InvalidArgumentError, match="seed"):
        twincal.Sobol(2, seed=-1)


def test_integers_workers_and_optimization_follow_scipy():
    scipy_qmc = pytest.importorskip("scipy.stats.qmc")
    engine = twincal.Halton(2, seed=3)
    assert isinstance(engine, scipy_qmc.QMCEngine)
    sample = engine.integers(10, n=8)
    engine.reset()
    np.testing.assert_array_equal(engine.integers(10, n=8, workers=4), sample)
    assert sample.dtype == np.int64 and sample.min() >= 0 and sample.max() < 10
    with pytest.raises(ValueError, match="workers"):
        engine.random(2, workers=0)
    plain = twincal.Sobol(2, scramble=False).random(64)
    optimized = twincal.Sobol(2, scramble=False, optimization="random-cd", seed=1).random(64)
    assert scipy_qmc.discrepancy(optimized) < scipy_qmc.discrepancy(plain)
    normal = scipy_qmc.MultivariateNormalQMC(mean=[0.0, 1.0], engine=twincal.Sobol(2, seed=7))
    assert normal.random(8).shape == (8, 2)


def test_invalid_arguments_raise_value_errors():
    with pytest.raises(ValueError, match="non-negative"):
        twincal.Sobol(-1)
    with pytest.raises(twincal.InvalidArgumentError, match="dimensionality"):
        twincal.Sobol(21202)
    with pytest.raises(twincal.InvalidArgumentError, match="scramble"):
        twincal.Sobol(2, scramble="digital")
    with pytest.raises(ValueError, match="n"):
        twincal.Halton(2).random(-1)
    with pytest.raises(ValueError, match="m"):
        twincal.Sobol(2).random_base2(64)


def test_without_scipy_the_engines_keep_their_interface_but_optimization():
    import subprocess
    import sys
    import textwrap

    script = textwrap.dedent("""
        import sys
        sys.modules["scipy"] = None  # `import scipy.stats` now raises ImportError
        import numpy as np
        import twincal
        engine = twincal.Sobol(2, scramble=False)
        assert engine.random_base2(2).shape == (4, 2) and engine.num_generated == 4
        assert engine.integers(5, n=4).shape == (4, 2)
        assert twincal.Halton(0).random(3).shape == (3, 0)
        try:
            twincal.Halton(2, optimization="lloyd")
        except twincal.InvalidArgumentError as error:
            assert "needs SciPy" in str(error)
        else:
            raise AssertionError("optimization without SciPy was accepted")
    """)
    subprocess.run([sys.executable, "-c", script], check=True)
