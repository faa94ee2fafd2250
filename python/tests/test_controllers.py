"""The controllers over a twin written in Python: they run the paper's loop, call the twin in
batches, are reproducible from their seed, and report the twin's errors as themselves."""

import numpy as np
import pytest

import twincal
from twincal.reference_twins import KeyPointRmsTwin, QuadraticRmsTwin


class QuadraticTwin(QuadraticRmsTwin):
    """The reference twin, recording the shape of every batch it is asked for."""

    def __init__(self, d, seed=3):
        super().__init__(d, seed)
        self.batches = []

    def quality_batch(self, assembly, controls):
        self.batches.append(controls.shape)
        return super().quality_batch(assembly, controls)


def episode(controller, twin, steps=60):
    """The paper's loop against a plant whose offset drifts (eq. 15); mean relative residual."""
    d = len(twin.lower_bounds)
    rng = np.random.default_rng(11)
    step = rng.normal(size=d)
    step *= 0.01 / np.linalg.norm(step)
    offset = np.zeros(d)
    residuals, controls = [], []
    for t in range(steps):
        x = int(rng.integers(10))
        u = controller.propose(x)
        z = float(twin.quality_batch(x, (u - offset)[:, None])[0])
        z_star = twin.optimal_quality(x)
        controller.observe(x, u, z)
        residuals.append((z - z_star) / z_star)
        controls.append(u)
        offset = offset + step
        if np.any(np.abs(offset) > 0.5):
            step = -step
    return float(np.mean(residuals)), np.array(controls)


@pytest.mark.parametrize("d", [1, 3])
def test_exploring_controllers_halve_the_baselines_residual(d):
    # The default controller is left out: measuring at its own optimum estimate, it learns
    # almost nothing about the offset (the paper's finding; docs/reproduction.md).
    twin = QuadraticTwin(d)
    baseline, _ = episode(twincal.IndividualizedController(twin), twin)
    for make in (lambda t: twincal.PaperController(t, w=1.0), twincal.ActiveController):
        score, _ = episode(make(twin), twin)
        assert score < 0.5 * baseline, (d, score, baseline)


def test_the_default_controller_runs_the_loop():
    twin = QuadraticTwin(2)
    controller = twincal.DefaultController(twin)
    u = controller.propose(3)
    np.testing.assert_allclose(u, twin.optima[3] + controller.offset_estimate, atol=1e-12)
    report = controller.last_proposal
    np.testing.assert_allclose(report["individual_control"], twin.optima[3])
    controller.observe(3, u, 0.9)
    assert controller.offset_covariance.shape == (2, 2)


def test_the_paper_controller_evaluates_candidates_in_batches():
    twin = QuadraticTwin(3)
    controller = twincal.PaperController(twin, w=1.0, candidates=16)
    twin.batches.clear()
    controller.propose(0)
    report = controller.last_proposal
    assert report["candidates_requested"] == 16
    assert 1 <= report["candidates_scored"] <= 16  # those inside the box around u0 + δû
    assert report["quality_evaluations"] == report["candidates_scored"] * 7  # × sigma points
    assert max(columns for _, columns in twin.batches) >= 16  # not one call per point
    assert controller.offset_estimate.shape == (3,)
    assert controller.offset_covariance.shape == (3, 3)


def test_controllers_are_reproducible_from_their_seed():
    twin = QuadraticTwin(3)
    _, first = episode(twincal.PaperController(twin, w=0.5, seed=5), twin, steps=15)
    _, again = episode(twincal.PaperController(twin, w=0.5, seed=5), twin, steps=15)
    _, other = episode(twincal.PaperController(twin, w=0.5, seed=6), twin, steps=15)
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first, other)


def test_a_twin_error_propagates_as_itself():
    class Broken(QuadraticTwin):
        def quality_batch(self, assembly, controls):
            raise KeyError(f"no part scan for assembly {assembly}")

    twin = Broken(2)
    controller = twincal.DefaultController(twin)
    before = controller.offset_estimate.copy()
    with pytest.raises(KeyError, match="no part scan"):
        controller.observe(4, np.zeros(2), 0.9)
    np.testing.assert_array_equal(controller.offset_estimate, before)


class FailingOnAssembly3(QuadraticTwin):
    """The reference twin whose solver does not converge on assembly 3."""

    def quality_batch(self, assembly, controls):
        if assembly == 3:
            raise twincal.TwinError("the solver did not converge on assembly 3")
        return super().quality_batch(assembly, controls)


@pytest.mark.parametrize("make", [twincal.DefaultController, twincal.PaperController,
                                  twincal.ActiveController])
def test_a_twin_error_a_python_twin_raises_is_a_twin_failure_the_controller_goes_on_after(make):
    twin = FailingOnAssembly3(2)
    plant = QuadraticTwin(2)
    controller = make(twin)
    for x in (0, 1, 3, 2):
        u = controller.propose(x)
        if x == 3 and make is not twincal.DefaultController:
            # The default controller's proposal is u0 + δû: it asks the twin nothing.
            assert "the solver did not converge on assembly 3" in (
                controller.last_proposal["fallback"])
        before = controller.offset_estimate.copy()
        controller.observe(x, u, float(plant.quality_batch(x, u[:, None])[0]))
        dropped = controller.last_proposal["dropped_measurement"]
        if x == 3:
            assert "twin.quality_batch raised" in dropped and "assembly 3" in dropped, dropped
            if make is twincal.DefaultController:  # its prediction is a random walk's: δû stays
                np.testing.assert_array_equal(controller.offset_estimate, before)
        else:
            assert dropped == "", dropped
    assert controller.last_proposal["fallback"] == ""


def test_bad_twins_and_measurements_raise_typed_errors():
    class NoQuality:
        lower_bounds = [-1.0]
        upper_bounds = [1.0]

        def optimum(self, assembly):
            return np.zeros(1)

    with pytest.raises(twincal.InvalidArgumentError, match="quality_batch"):
        twincal.IndividualizedController(NoQuality())
    twin = QuadraticTwin(2)
    twin.upper_bounds = np.array([1.0, -2.0])
    with pytest.raises(twincal.InvalidArgumentError, match="lower < upper"):
        twincal.ActiveController(twin)

    class WrongSize(QuadraticTwin):
        def quality_batch(self, assembly, controls):
            return np.ones(controls.shape[1] + 1)

    # The candidates' batch falls back to the default control and says why; z* asked of the
    # twin (no optimal_quality of its own: Q at u0) raises.
    controller = twincal.PaperController(WrongSize(2))
    controller.propose(0)
    assert "twin.quality_batch: returned 76 values for 75 controls" in (
        controller.last_proposal["fallback"])
    WrongSize.optimal_quality = None
    with pytest.raises(twincal.DimensionMismatchError, match="quality_batch"):
        twincal.PaperController(WrongSize(2)).propose(0)
    controller = twincal.ActiveController(QuadraticTwin(2))
    u = controller.propose(1)
    with pytest.raises(twincal.NonFiniteError):
        controller.observe(1, u, float("inf"))


def test_active_controller_takes_its_settings_by_name_and_refuses_unknown_ones():
    twin = QuadraticTwin(2)
    defaults = twincal.ActiveController(twin, seed=5)
    same = twincal.ActiveController(twin, seed=5, options={})
    np.testing.assert_array_equal(defaults.propose(0), same.propose(0))
    # Settings of the controller and of its estimator, by name.
    wider = twincal.ActiveController(
        twin, seed=5, options={"max_probe_fraction": 0.5, "trajectory": {"change_gate": 3}})
    assert wider.propose(0).shape == (2,)
    with pytest.raises(twincal.InvalidArgumentError, match=r"options\.regret: key \"regret\" is unknown"):
        twincal.ActiveController(twin, options={"regret": 0.1})
    with pytest.raises(twincal.InvalidArgumentError, match=r"options\.trajectory\.change_lag: value is 1"):
        twincal.ActiveController(twin, options={"trajectory": {"change_lag": 1}})
    with pytest.raises(twincal.InvalidArgumentError, match="beside it"):
        twincal.ActiveController(twin, options={"measurement_variance": 1e-4})
    with pytest.raises(twincal.InvalidArgumentError, match="an integer"):
        twincal.ActiveController(twin, options={"audit_period": 2.5})
    with pytest.raises(ValueError):
        twincal.ActiveController(twin, options={"regret_probe": float("nan")})


class DelegatingTwin:
    """A Python twin that answers Q through another twin: through a twincal.Twin the controllers
    take the Python path (callbacks, arrays crossing both ways) for the same numbers as the
    compiled twin; through a twin that knows its deviations, they see a black box."""

    def __init__(self, native):
        self.native = native
        self.lower_bounds = native.lower_bounds
        self.upper_bounds = native.upper_bounds

    def quality_batch(self, assembly, controls):
        return self.native.quality_batch(assembly, controls)

    def optimum(self, assembly):
        return self.native.optimum(assembly)


class DelegatingTwinWithDeviations(DelegatingTwin):
    """The same, for a twincal.Twin that answers its key points' deviations."""

    def __init__(self, native):
        super().__init__(native)
        self.key_point_count = native.key_point_count

    def deviations_batch(self, assembly, controls):
        return self.native.deviations_batch(assembly, controls)


def delegating(native):
    """A delegating twin that answers what `native` answers."""
    if native.key_point_count:
        return DelegatingTwinWithDeviations(native)
    return DelegatingTwin(native)


def plant_episode(controller, twin, steps):
    """Controls and estimates of `steps` assemblies against the twin's plant, drifting."""
    rng = np.random.default_rng(4)
    offset = np.zeros(len(twin.lower_bounds))
    controls, estimates = [], []
    for _ in range(steps):
        x = twin.assemblies[int(rng.integers(len(twin.assemblies)))]
        u = controller.propose(x)
        z = float(twin.quality(x, u - offset)) + 1e-3 * rng.normal()
        controller.observe(x, u, z)
        controls.append(u)
        estimates.append(getattr(controller, "offset_estimate", np.zeros_like(u)))
        offset = offset + 0.004
    return np.array(controls), np.array(estimates)


PARITY_CONTROLLERS = {
    "paper": lambda t: twincal.PaperController(t, w=0.5, seed=3),
    "paper, halton, log-det": lambda t: twincal.PaperController(
        t, w=1.0, seed=3, sampler="halton", exploration="log_det"),
    "per-component": lambda t: twincal.PerComponentController(t, w=1.0, seed=3),
    "active": lambda t: twincal.ActiveController(t, seed=3),
}


@pytest.mark.parametrize("name", PARITY_CONTROLLERS)
@pytest.mark.parametrize("case", ["body", "analytic"])
def test_a_python_twin_drives_a_controller_to_the_compiled_twins_controls(name, case):
    native = twincal.Twin(case, locators="ABC", dimension=3)
    make = PARITY_CONTROLLERS[name]
    compiled = plant_episode(make(native), native, steps=25)
    through_python = plant_episode(make(delegating(native)), native, steps=25)
    np.testing.assert_array_equal(through_python[0], compiled[0])
    np.testing.assert_array_equal(through_python[1], compiled[1])


SAMPLERS = ["sobol", "halton", "random", "latin_hypercube"]
LOSSES = ["trace", "weighted_trace", "log_det", "max_eigenvalue"]


@pytest.mark.parametrize("exploration", LOSSES)
@pytest.mark.parametrize("sampler", SAMPLERS)
def test_every_sampler_and_exploration_loss_runs_the_loop(sampler, exploration):
    twin = QuadraticTwin(2)
    weights = np.array([1.0, 3.0]) if exploration == "weighted_trace" else None
    controller = twincal.PaperController(twin, w=0.5, sampler=sampler, exploration=exploration,
                                         weights=weights, seed=8)
    residual, controls = episode(controller, twin, steps=12)
    assert np.isfinite(residual) and np.all(np.isfinite(controls))
    report = controller.last_proposal
    assert report["candidates_requested"] == 16 and np.isfinite(report["loss"])


def test_unit_weights_explore_as_the_trace_does():
    twin = QuadraticTwin(3)
    trace = twincal.PaperController(twin, w=0.7, seed=2)
    weighted = twincal.PaperController(twin, w=0.7, seed=2, exploration="weighted_trace",
                                       weights=np.ones(3))
    np.testing.assert_array_equal(episode(weighted, twin, steps=10)[1],
                                  episode(trace, twin, steps=10)[1])


def test_the_weighted_trace_infers_its_weights_from_the_twins_assemblies():
    native = twincal.Twin("body", locators="ABC")
    controller = twincal.PaperController(native, w=1.0, exploration="weighted_trace")
    assert np.all(np.isfinite(controller.propose(native.assemblies[0])))
    with pytest.raises(twincal.InvalidArgumentError, match="weights"):
        twincal.PaperController(QuadraticTwin(2), exploration="weighted_trace")
    with pytest.raises(twincal.DimensionMismatchError, match="weights"):
        twincal.PaperController(QuadraticTwin(2), exploration="weighted_trace", weights=np.ones(3))
    with pytest.raises(twincal.InvalidArgumentError, match="sobel"):
        twincal.PaperController(QuadraticTwin(2), sampler="sobel")
    with pytest.raises(twincal.InvalidArgumentError, match="trace2"):
        twincal.PaperController(QuadraticTwin(2), exploration="trace2")


class TwinWithoutOptimum(QuadraticRmsTwin):
    """The reference twin, hiding its optimum: twincal must search it."""

    optimum = None  # not callable: the protocol's optional method is absent

    def __init__(self, d):
        super().__init__(d, seed=9)
        self.calls = 0

    def quality_batch(self, assembly, controls):
        self.calls += 1
        return super().quality_batch(assembly, controls)


def test_a_twin_without_optimum_gets_it_searched():
    twin = TwinWithoutOptimum(2)
    controller = twincal.IndividualizedController(twin)
    for x in range(3):
        twin.calls = 0
        np.testing.assert_allclose(controller.propose(x), twin.optima[x], atol=1e-6)
        assert 100 < twin.calls <= 3000  # one search per assembly: DIRECT-L, then BOBYQA
    paper = twincal.PaperController(twin, w=1.0, seed=1)
    residual, _ = episode(paper, twin, steps=5)
    assert np.isfinite(residual)


def test_the_active_controller_reports_its_last_step():
    twin = QuadraticTwin(2)
    controller = twincal.ActiveController(twin, seed=5)
    episode(controller, twin, steps=20)
    step = controller.last_step
    assert step["quadratic"] is True
    assert 1 <= step["history"] <= 20
    assert step["misfit_scale"] >= 1.0 and step["prediction_scale"] >= 1.0
    # An exact quadratic twin's models never err, so the fit keeps σz² as its unit.
    assert step["fit_unit"] == 1.0
    # The change gate's reading is consulted on a history this long; above 1 only at a change.
    assert np.isfinite(step["change_ratio"])
    assert (step["change_ratio"] > 1.0) == step["velocity_change"]
    assert isinstance(step["corrected"], bool)
    # A wanted correction is applied exactly when no do-no-harm rule or audit held it back.
    holds = ("held_by_innovations", "held_by_surprises", "held_beyond_reach", "held_by_audit")
    assert step["corrected"] == (step["correction_wanted"] and not any(step[k] for k in holds))
    assert not hasattr(twincal.PaperController(twin), "last_step")


class CountingKeyPointTwin(KeyPointRmsTwin):
    """The reference key-point twin, counting the deviations it is asked for."""

    def __init__(self, d, **kwargs):
        super().__init__(d, **kwargs)
        self.deviation_calls = 0

    def deviations_batch(self, assembly, controls):
        self.deviation_calls += 1
        return super().deviations_batch(assembly, controls)


def test_the_active_controller_fits_its_models_from_a_python_twins_deviations():
    twin = CountingKeyPointTwin(3, seed=5)
    baseline, _ = episode(twincal.IndividualizedController(twin), twin)
    score, _ = episode(twincal.ActiveController(twin, seed=2), twin)
    assert twin.deviation_calls > 0
    assert score < 0.5 * baseline, (score, baseline)
    # Seen as a black box that answers only Q, the same twin is fitted from Q²: no deviations
    # are asked for, and it still halves the baseline (its Q² is a quadratic).
    hidden = CountingKeyPointTwin(3, seed=5)
    score, _ = episode(twincal.ActiveController(DelegatingTwin(hidden), seed=2), hidden)
    assert hidden.deviation_calls == 0
    assert score < 0.5 * baseline, (score, baseline)


def test_the_reference_key_point_twin_is_the_rms_of_its_deviations_and_optimal_at_u0():
    twin = KeyPointRmsTwin(3, key_points=12, seed=4)
    rng = np.random.default_rng(0)
    controls = rng.uniform(-1.0, 1.0, size=(3, 5))
    r = twin.deviations_batch(2, controls)
    assert r.shape == (12, 5)
    np.testing.assert_allclose(twin.quality_batch(2, controls),
                               np.linalg.norm(r, axis=0) / np.sqrt(12), rtol=1e-14)
    z_star = twin.optimal_quality(2)
    assert z_star == pytest.approx(float(twin.quality_batch(2, twin.optimum(2)[:, None])[0]))
    assert np.all(twin.quality_batch(2, controls) > z_star)


def test_a_python_twins_deviations_are_checked():
    class NoCount(KeyPointRmsTwin):
        def __init__(self):
            super().__init__(2)
            del self.key_point_count

    with pytest.raises(twincal.InvalidArgumentError, match="key_point_count: missing"):
        twincal.ActiveController(NoCount())
    for bad, message in ((0, "value is 0"), (-3, "value is -3"), ("12", "is not an int"),
                         (True, "is not an int")):
        twin = KeyPointRmsTwin(2)
        twin.key_point_count = bad
        with pytest.raises(twincal.InvalidArgumentError, match=message):
            twincal.ActiveController(twin)

    class Transposed(KeyPointRmsTwin):
        def deviations_batch(self, assembly, controls):
            return super().deviations_batch(assembly, controls).T

    # The model's fit fails on it, and the controller falls back (docs/controllers.md), saying why.
    controller = twincal.ActiveController(Transposed(2, key_points=6))
    assert np.all(np.isfinite(controller.propose(0)))
    assert "deviations_batch: returned a 5 × 6 array for 5 controls" in (
        controller.last_proposal["fallback"])


def test_a_compiled_twin_answers_its_deviations_where_it_has_key_points():
    body = twincal.Twin("body", locators="ABC")
    m = body.key_point_count
    assert m > 0
    x = body.assemblies[0]
    controls = np.column_stack([body.optimum(x), body.optimum(x) + 0.1])
    r = body.deviations_batch(x, controls)
    assert r.shape == (m, 2)
    np.testing.assert_allclose(np.linalg.norm(r, axis=0) / np.sqrt(m),
                               body.quality_batch(x, controls), rtol=1e-9)
    analytic = twincal.Twin("analytic", dimension=3)
    assert analytic.key_point_count == 0
    with pytest.raises(twincal.InvalidArgumentError, match="deviations"):
        analytic.deviations_batch(analytic.assemblies[0], np.zeros((3, 1)))
