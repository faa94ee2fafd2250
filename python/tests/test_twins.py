"""twincal.Twin: the FEM and analytic twins from Python — the protocol of a Python twin, the
same numbers one by one as in a batch, and typed errors for what it cannot do."""

import numpy as np
import pytest

import twincal


@pytest.fixture(scope="module")
def body():
    return twincal.Twin("body", locators="ABC")


def test_the_body_twin_restricted_to_its_significant_locators(body):
    assert body.control_dimension == 3
    assert len(body.locator_names) == 3
    assert body.lower_bounds.shape == (3,) and np.all(body.lower_bounds < body.upper_bounds)
    assert len(body.assemblies) == 100  # 10 upper x 10 lower parts
    assert body.assemblies[12] == (1, 2)


def test_a_batch_equals_its_columns_one_by_one(body):
    x = body.assemblies[7]
    rng = np.random.default_rng(1)
    controls = body.optimum(x)[:, None] + 0.05 * rng.normal(size=(3, 9))
    batch = body.quality_batch(x, controls)
    assert batch.shape == (9,)
    np.testing.assert_allclose(batch, [body.quality(x, c) for c in controls.T], rtol=1e-13)
    np.testing.assert_array_equal(body.quality_batch(7, controls), batch)  # index = pair


def test_the_optimum_is_a_minimum(body):
    for x in body.assemblies[::17]:
        u0 = body.optimum(x)
        assert body.optimal_quality(x) == pytest.approx(body.quality(x, u0), rel=1e-12)
        around = u0[:, None] + 0.01 * np.vstack([np.eye(3), -np.eye(3)]).T
        assert np.all(body.quality_batch(x, around) > body.optimal_quality(x))


def test_the_analytic_twin_has_its_dimension():
    twin = twincal.Twin("analytic", dimension=12, seed=5)
    assert twin.control_dimension == 12
    assert twin.locator_names[:3] == ["A", "B", "C"]
    other = twincal.Twin("analytic", dimension=12, seed=6)
    x = twin.assemblies[0]
    assert not np.array_equal(twin.optimum(x), other.optimum(x))  # the seed is the twin's


def test_what_the_twin_cannot_do_raises_typed_errors(body):
    with pytest.raises(twincal.InvalidArgumentError, match="plane"):
        twincal.Twin("plane")
    with pytest.raises(ValueError, match="locator"):
        twincal.Twin("body", locators="Z9")
    with pytest.raises(twincal.InvalidArgumentError, match=r"\(10, 0\)"):
        body.optimum((10, 0))
    with pytest.raises(twincal.InvalidArgumentError, match="index in"):
        body.quality_batch(100, np.zeros((3, 1)))
    with pytest.raises(twincal.DimensionMismatchError, match="controls"):
        body.quality_batch(0, np.zeros((2, 4)))
