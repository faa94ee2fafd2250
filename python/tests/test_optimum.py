"""twincal.BudgetedOptimum: u0 of a twin written in Python searched within a budget, on the
deviations (least squares) or on Q (trust region); what it finds, what it spends, and what it
refuses."""

import numpy as np
import pytest

import twincal
from twincal.reference_twins import KeyPointRmsTwin, QuadraticRmsTwin


class Searchable:
    """A reference twin without its optimum (which the tests keep), counting its calls and the
    controls it is asked for; with `deviations` it answers them."""

    def __init__(self, twin, deviations):
        self.reference = twin
        self.lower_bounds = twin.lower_bounds
        self.upper_bounds = twin.upper_bounds
        self.calls = 0
        self.controls = 0
        if deviations:
            self.key_point_count = twin.key_point_count
            self.deviations_batch = self._deviations_batch

    def quality_batch(self, assembly, controls):
        self.calls += 1
        self.controls += controls.shape[1]
        return self.reference.quality_batch(assembly, controls)

    def _deviations_batch(self, assembly, controls):
        self.calls += 1
        self.controls += controls.shape[1]
        return self.reference.deviations_batch(assembly, controls)


def test_least_squares_finds_the_optimum_of_an_affine_twin_within_its_budget():
    reference = KeyPointRmsTwin(4)
    twin = Searchable(reference, deviations=True)
    searched = twincal.BudgetedOptimum(twin)
    assert (searched.method, searched.budget, searched.seed) == ("least_squares", 50, 2023)
    for x in range(5):
        np.testing.assert_allclose(searched.optimum(x), reference.optimum(x), atol=1e-8)
        assert searched.optimal_quality(x) == pytest.approx(reference.optimal_quality(x),
                                                            rel=1e-12)
    assert searched.searches == 5  # optimum, then optimal_quality: one search
    assert twin.controls == searched.evaluations <= 5 * searched.budget
    assert twin.calls == searched.requests
    last = searched.last_search
    assert last["evaluations"] <= 50 and last["status"] in ("converged", "budget_spent")
    np.testing.assert_array_equal(last["control"], searched.optimum(4))


def test_speculative_least_squares_finds_the_same_optima_in_fewer_requests():
    reference = KeyPointRmsTwin(4)
    plain_twin = Searchable(reference, deviations=True)
    speculative_twin = Searchable(reference, deviations=True)
    plain = twincal.BudgetedOptimum(plain_twin)
    speculative = twincal.BudgetedOptimum(speculative_twin, method="least_squares_speculative")
    for x in range(5):
        np.testing.assert_allclose(speculative.optimum(x), plain.optimum(x), atol=1e-8)
    assert speculative_twin.calls == speculative.requests < plain.requests
    assert speculative_twin.controls == speculative.evaluations <= 5 * speculative.budget


def test_the_trust_region_finds_the_optimum_of_a_twin_that_answers_only_q():
    reference = QuadraticRmsTwin(3)
    twin = Searchable(reference, deviations=False)
    searched = twincal.BudgetedOptimum(twin, budget=40)
    assert searched.method == "trust_region"
    for x in range(5):
        np.testing.assert_allclose(searched.optimum(x), reference.optimum(x), atol=1e-3)
        assert searched.optimal_quality(x) == pytest.approx(reference.optimal_quality(x),
                                                            rel=1e-6)
    assert twin.controls == searched.evaluations <= 5 * 40
    assert twin.calls == searched.requests < twin.controls  # in batches


def test_a_controller_searches_u0_within_the_budget_instead_of_by_nlopt():
    reference = KeyPointRmsTwin(3)
    twin = Searchable(reference, deviations=True)
    searched = twincal.BudgetedOptimum(twin, budget=20)
    controller = twincal.DefaultController(searched)
    for x in range(3):
        before = twin.controls
        controller.propose(x)
        u0 = controller.last_proposal["individual_control"]
        np.testing.assert_array_equal(u0, searched.optimum(x))
        np.testing.assert_allclose(u0, reference.optimum(x), atol=1e-8)
        assert controller.last_proposal["optimal_quality"] == searched.optimal_quality(x)
        assert twin.controls - before <= 20  # NLopt's search takes 100 to 3000
    active = twincal.ActiveController(searched, seed=3)
    u = active.propose(1)
    active.observe(1, u, float(reference.quality_batch(1, u[:, None])[0]))
    assert np.all(np.isfinite(active.offset_estimate))


def test_a_search_depends_only_on_the_twin_the_assembly_the_start_and_the_seed():
    def run(seed, order):
        searched = twincal.BudgetedOptimum(Searchable(KeyPointRmsTwin(3), True), seed=seed)
        return {x: searched.search(x)["control"] for x in order}

    first, reordered = run(7, [0, 1, 2]), run(7, [2, 0, 1])
    for x in range(3):
        np.testing.assert_array_equal(first[x], reordered[x])
    twin = Searchable(KeyPointRmsTwin(3), True)
    searched = twincal.BudgetedOptimum(twin, budget=30)
    found = searched.search(2, start=[0.5, -0.5, 0.0])
    assert set(found) == {"control", "quality", "evaluations", "requests", "status"}
    assert found["evaluations"] <= 30 and found["requests"] >= 1
    np.testing.assert_allclose(found["control"], twin.reference.optimum(2), atol=1e-8)


def test_every_other_attribute_is_the_twins_own():
    twin = Searchable(KeyPointRmsTwin(3), True)
    searched = twincal.BudgetedOptimum(twin)
    assert searched.twin is twin
    assert searched.key_point_count == twin.key_point_count
    np.testing.assert_array_equal(searched.lower_bounds, twin.lower_bounds)
    controls = np.zeros((3, 2))
    np.testing.assert_array_equal(searched.quality_batch(0, controls),
                                  twin.quality_batch(0, controls))
    with pytest.raises(AttributeError):
        searched.no_such_attribute
    assert not hasattr(twincal.BudgetedOptimum(Searchable(QuadraticRmsTwin(3), False)),
                       "deviations_batch")
    assert "method=least_squares, budget=32, seed=2023" in repr(searched)


def test_the_compiled_twins_optima_are_found_from_their_deviations():
    body = twincal.Twin("body", locators="ABC")
    searched = twincal.BudgetedOptimum(body, budget=16)
    for x in body.assemblies[:5]:
        assert searched.optimal_quality(x) == pytest.approx(body.optimal_quality(x), rel=1e-9)


@pytest.mark.parametrize("keywords, message", [
    ({"method": "powell"}, "method: value is powell; rule: must be least_squares, "
                           "least_squares_speculative or trust_region"),
    ({"method": "least_squares"}, "method: value is least_squares; rule: least_squares needs a "
                                  "twin that answers its deviations"),
    ({"budget": 0}, "budget: value is 0; rule: must be >= 1"),
])
def test_bad_settings_raise_the_rule_they_break(keywords, message):
    with pytest.raises(twincal.InvalidArgumentError, match=message):
        twincal.BudgetedOptimum(Searchable(QuadraticRmsTwin(3), False), **keywords)


def test_a_bad_start_or_twin_error_leaves_the_counts_and_the_last_search_unchanged():
    twin = Searchable(QuadraticRmsTwin(3), False)
    searched = twincal.BudgetedOptimum(twin, budget=20)
    searched.optimum(0)
    last, evaluations = searched.last_search, searched.evaluations
    with pytest.raises(twincal.DimensionMismatchError, match="start"):
        searched.search(1, start=[0.0, 0.0])
    with pytest.raises(twincal.InvalidArgumentError, match="start"):
        searched.search(1, start=[0.0, 0.0, 5.0])

    def broken(assembly, controls):
        raise RuntimeError("solver diverged")

    twin.quality_batch = broken
    with pytest.raises(RuntimeError, match="solver diverged"):
        searched.optimum(1)
    assert searched.evaluations == evaluations and searched.searches == 1
    np.testing.assert_array_equal(searched.last_search["control"], last["control"])


def test_a_twins_own_optimal_quality_is_taken_without_another_call():
    class Counted(QuadraticRmsTwin):
        calls = 0

        def quality_batch(self, assembly, controls):
            self.calls += 1
            return super().quality_batch(assembly, controls)

    twin = Counted(3)
    controller = twincal.DefaultController(twin)
    controller.propose(2)
    assert twin.calls == 0
    assert controller.last_proposal["optimal_quality"] == twin.optimal_quality(2)
