#include "twincal/controllers/lookahead_controller.hpp"

#include <cmath>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "controller_fixture.hpp"
#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/log_det_loss.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/sobol.hpp"

namespace twincal {
namespace {

using test_support::AnalyticTwin;
using test_support::CountingTwin;
using test_support::make_filter;
using test_support::make_twin;

SobolOptions scrambled(std::uint64_t seed) {
  return {.randomization = SobolRandomization::owen, .seed = seed};
}

template <typename F>
using SobolController = LookaheadController<F, Sobol>;

static_assert(Controller<SobolController<test_support::Ukf<2>>>);
static_assert(EstimatingController<SobolController<test_support::Ukf<2>>>);

// The candidates the controller scored after a propose, drawn again with an identical sampler.
template <typename C, typename F>
Matrix<F::dimension_at_compile_time, Dynamic> redraw_candidates(const C& controller,
                                                                Sobol sampler) {
  constexpr int N = F::dimension_at_compile_time;
  const ProposalReport& report = controller.last_proposal();
  const Vector<N> center = report.default_control;
  const GaussianTransform<N> transform(center, controller.filter().covariance(),
                                       controller.options().transform);
  const BoxSet<N> box = BoxSet<N>::cube(center, controller.options().box_half_width);
  const CandidateSet<N> set =
      draw_candidates(sampler, transform, box, {.count = report.candidates_requested});
  Matrix<N, Dynamic> scored = set.points().leftCols(report.candidates_scored);
  return scored;
}

TEST(LookaheadController, WithWZeroAndATinyCovarianceItPicksTheCandidateClosestToTheDefault) {
  const AnalyticTwin twin = make_twin(2);
  const CountingTwin counting(twin);
  const Eigen::Vector2d offset_estimate(0.05, -0.03);
  using F = test_support::Ukf<2>;
  SobolController<F> controller(make_filter<F>(counting, offset_estimate, 1e-10, 1e-12),
                                Sobol(2, scrambled(3)), {.w = 0.0});
  const AssemblyId x{2, 7};
  const Eigen::Vector2d u = controller.propose(x);
  const ProposalReport& report = controller.last_proposal();
  ASSERT_FALSE(report.fell_back()) << report.fallback;
  EXPECT_EQ(report.candidates_requested, 16);  // 2^(2+d)
  EXPECT_EQ(report.default_control, twin.optimum(x) + offset_estimate);

  // Brute force: with P ≈ 0 every sigma point is δû, so E[Q] ranks the candidates by their
  // H-distance to u0 + δû, where Q(x, u − δû) is smallest.
  const Matrix<2, Dynamic> candidates =
      redraw_candidates<SobolController<F>, F>(controller, Sobol(2, scrambled(3)));
  ASSERT_GT(candidates.cols(), 1);
  const Eigen::MatrixXd& h = twin.curvature();
  double best = std::numeric_limits<double>::infinity();
  Index closest = -1;
  for (Index c = 0; c < candidates.cols(); ++c) {
    const Eigen::Vector2d e = candidates.col(c) - report.default_control;
    const double distance = e.dot(h * e);
    if (distance < best) {
      best = distance;
      closest = c;
    }
  }
  EXPECT_EQ(report.chosen, closest);
  EXPECT_EQ(u, candidates.col(closest));
}

TEST(LookaheadController, WithWOneTheChoiceMinimizesTheExplorationLossOverTheSet) {
  const AnalyticTwin twin = make_twin(2);
  const CountingTwin counting(twin);
  using F = test_support::Ukf<2>;
  SobolController<F> controller(make_filter<F>(counting, Eigen::Vector2d(0.1, 0.0), 0.02),
                                Sobol(2, scrambled(11)), {.w = 1.0});
  const AssemblyId x{4, 1};
  const Eigen::Vector2d u = controller.propose(x);
  const ProposalReport& report = controller.last_proposal();
  ASSERT_FALSE(report.fell_back()) << report.fallback;

  const F predicted = controller.filter();  // a copy: previews below must not touch the original
  const Matrix<2, Dynamic> candidates =
      redraw_candidates<SobolController<F>, F>(controller, Sobol(2, scrambled(11)));
  double best = std::numeric_limits<double>::infinity();
  Index argmin = -1;
  for (Index c = 0; c < candidates.cols(); ++c) {
    const Eigen::Vector2d candidate = candidates.col(c);
    const double loss = TraceLoss{}(predicted.preview({x, candidate}).posterior_covariance);
    if (loss < best) {
      best = loss;
      argmin = c;
    }
  }
  EXPECT_EQ(report.chosen, argmin);
  EXPECT_EQ(u, candidates.col(argmin));
  EXPECT_DOUBLE_EQ(report.loss, best);
  EXPECT_DOUBLE_EQ(report.exploration, best);
}

TEST(LookaheadController, QualityEvaluationsPerAssemblyAreCandidatesTimesSigmaPoints) {
  const AnalyticTwin twin = make_twin(3);
  const CountingTwin counting(twin);
  using F = test_support::Ukf<3>;
  SobolController<F> controller(make_filter<F>(counting, Eigen::Vector3d::Zero(), 1e-3),
                                Sobol(3, scrambled(2)), {.w = 0.5});
  const AssemblyId x{0, 0};
  const EvaluationStats before = counting.stats();
  const Eigen::Vector3d u = controller.propose(x);
  controller.observe(x, u, twin.quality(x, u) + 0.01);
  const EvaluationStats step = counting.stats() - before;
  const ProposalReport& report = controller.last_proposal();
  ASSERT_FALSE(report.fell_back()) << report.fallback;
  constexpr Index sigma_points = 2 * 3 + 1;
  EXPECT_EQ(step.evaluations, static_cast<std::uint64_t>(report.candidates_scored * sigma_points));
  EXPECT_EQ(step.calls, 1U);  // one batch for scoring; the update reused the chosen preview
  EXPECT_EQ(report.quality_evaluations, step.evaluations);
  EXPECT_EQ(report.optimizer_evaluations, 0U);  // the analytic twin knows u0 exactly
  EXPECT_EQ(controller.filter().update_count(), 1U);
}

TEST(LookaheadController, ObservingAnotherControlRunsAnOrdinaryUpdate) {
  const AnalyticTwin twin = make_twin(1);
  const CountingTwin counting(twin);
  using F = test_support::Ukf<1>;
  SobolController<F> controller(make_filter<F>(counting, Vector<1>(0.0), 1e-3),
                                Sobol(1, scrambled(2)), {.w = 0.5});
  const AssemblyId x{1, 1};
  const Vector<1> proposed = controller.propose(x);
  F reference = controller.filter();
  const Vector<1> applied = proposed + Vector<1>(0.01);
  const EvaluationStats before = counting.stats();
  controller.observe(x, applied, 0.7);
  EXPECT_EQ((counting.stats() - before).evaluations, 3U);  // the update's own 2n+1 points
  reference.update(0.7, {x, applied});
  EXPECT_EQ(controller.filter().state(), reference.state());
  EXPECT_EQ(controller.filter().covariance(), reference.covariance());
}

TEST(LookaheadController, ATwinFailureFallsBackToTheDefaultControlWithoutTouchingTheFilter) {
  // Scoring needs 16 candidates × 5 sigma points in one batch; the filter's update needs 5.
  const test_support::FailingTwinSetup setup(5);
  const AnalyticTwin& inner = setup.inner;
  using F = test_support::FailingTwinSetup::Filter;
  F reference = setup.filter();
  LookaheadController<F, Sobol> controller(setup.filter(), Sobol(2, scrambled(1)));
  const AssemblyId x{3, 3};
  const Eigen::Vector2d u = controller.propose(x);
  const ProposalReport& report = controller.last_proposal();
  EXPECT_TRUE(report.fell_back());
  EXPECT_THAT(report.fallback, ::testing::HasSubstr("FEM solver crashed"));
  EXPECT_EQ(report.chosen, -1);
  EXPECT_EQ(u, report.default_control);
  reference.predict();  // the controller's filter was predicted, and nothing else
  EXPECT_EQ(controller.filter().state(), reference.state());
  EXPECT_EQ(controller.filter().covariance(), reference.covariance());
  EXPECT_EQ(controller.filter().update_count(), 0U);
  controller.observe(x, u, inner.quality(x, u));  // an ordinary update still works
  EXPECT_EQ(controller.filter().update_count(), 1U);
}

// A twin that fails everywhere: the proposal falls back, and its observation, an ordinary update
// at the default control, is dropped (update_or_drop); the filter stays as predicted.
TEST(LookaheadController, DropsTheMeasurementWhenTheTwinAlsoFailsInTheUpdate) {
  const test_support::FailingTwinSetup setup(0);  // every batch fails
  using F = test_support::FailingTwinSetup::Filter;
  F reference = setup.filter();
  LookaheadController<F, Sobol> controller(setup.filter(), Sobol(2, scrambled(1)));
  const AssemblyId x{3, 3};
  const Eigen::Vector2d u = controller.propose(x);
  EXPECT_TRUE(controller.last_proposal().fell_back());
  controller.observe(x, u, 0.5);
  EXPECT_TRUE(controller.last_proposal().dropped());
  EXPECT_THAT(controller.last_proposal().dropped_measurement,
              ::testing::HasSubstr("FEM solver crashed"));
  reference.predict();
  EXPECT_EQ(controller.filter().state(), reference.state());
  EXPECT_EQ(controller.filter().covariance(), reference.covariance());
  EXPECT_EQ(controller.filter().update_count(), 0U);
}

TEST(LookaheadController, RejectsBadOptionsAndAMismatchedSampler) {
  const AnalyticTwin twin = make_twin(2);
  const CountingTwin counting(twin);
  using F = test_support::Ukf<2>;
  const F filter = make_filter<F>(counting, Eigen::Vector2d::Zero(), 1e-3);
  using C = SobolController<F>;
  EXPECT_THAT([&] { C(filter, Sobol(2), {.w = 1.5}); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "LookaheadOptions: w: value is 1.5; rule: must lie in [0, 1]"));
  EXPECT_THAT([&] { C(filter, Sobol(2), {.box_half_width = 0.0}); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "LookaheadOptions: box_half_width: value is 0; rule: must be finite and > 0"));
  EXPECT_THAT([&] { C(filter, Sobol(2), {.candidates = 0}); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "LookaheadOptions: candidates: value is 0; rule: must be >= 1 (unset: 2^(2+d))"));
  EXPECT_THAT([&] { C(filter, Sobol(3)); },
              ::testing::ThrowsMessage<DimensionMismatchError>(
                  "sampler.dimension(): size is 3; rule: must equal 2"));
}

struct TrackingErrors {
  double mean = 0.0;   // mean ‖δû_t − δu*_t‖ after the burn-in
  double worst = 0.0;  // largest after the burn-in
};

// Tracks the paper's bouncing drift (eq. 15) with the plant Q(x, u − δu*) + noise over the 100
// assemblies, and fails on divergence (the paper's rule: an error above 10).
template <typename C>
TrackingErrors track_drift(C& controller, const AnalyticTwin& twin, std::uint64_t seed,
                           int burn_in = 10) {
  RandomStream root(seed);
  RandomStream drift_stream = root.substream("drift");
  RandomStream noise = root.substream("noise");
  const Index d = twin.control_dimension();
  BouncingDrift<Dynamic> drift = BouncingDrift<Dynamic>::random(d, drift_stream);
  const std::vector<AssemblyId> assemblies = twin.assemblies();
  TrackingErrors errors;
  for (int t = 0; t < 100; ++t) {
    drift.advance();
    const AssemblyId& x = assemblies[static_cast<std::size_t>(t)];
    const typename C::ControlVector u = controller.propose(x);
    EXPECT_FALSE(controller.last_proposal().fell_back()) << controller.last_proposal().fallback;
    const VectorX shifted = VectorX(u) - drift.offset();
    const double z =
        twin.quality(x, shifted) + std::sqrt(test_support::measurement_variance) * noise.normal();
    controller.observe(x, u, z);
    const double error = (VectorX(controller.offset_estimate()) - drift.offset()).norm();
    EXPECT_LT(error, 10.0) << "diverged at assembly " << t;
    if (t < burn_in) continue;
    errors.mean += error / (100.0 - burn_in);
    errors.worst = std::max(errors.worst, error);
  }
  return errors;
}

// A zero estimate of the drift (amplitude 0.5) would have a mean error of about 0.25: these
// bounds demand real tracking, far from divergence.
void expect_tracking(const TrackingErrors& errors) {
  EXPECT_LT(errors.mean, 0.15);
  EXPECT_LT(errors.worst, 0.4);
  ::testing::Test::RecordProperty("mean_error", std::to_string(errors.mean));
  ::testing::Test::RecordProperty("worst_error", std::to_string(errors.worst));
}

template <typename F>
class LookaheadControllerFilters : public ::testing::Test {};
using Filters = ::testing::Types<test_support::Ukf<1>, test_support::Ckf<1>,
                                 test_support::SquareRootUkf<1>, test_support::Ukf<Dynamic>>;
TYPED_TEST_SUITE(LookaheadControllerFilters, Filters);

TYPED_TEST(LookaheadControllerFilters, TracksASlowDriftWithoutDivergingForOneLocator) {
  using F = TypeParam;
  const AnalyticTwin twin = make_twin(1);
  const CountingTwin counting(twin);
  LookaheadController<F, Sobol> controller(
      make_filter<F>(counting, Vector<F::dimension_at_compile_time>::Zero(1), 1e-3),
      Sobol(1, scrambled(9)), {.w = 0.5});
  expect_tracking(track_drift(controller, twin, 2023));
}

static_assert(SnapshotController<SobolController<test_support::Ukf<2>>>);
static_assert(SnapshotController<LookaheadController<test_support::SquareRootUkf<3>, Halton>>);

// Assembly t of a drifting offset; the whole state after the observation (save()) as text.
template <typename C>
std::string lookahead_snapshot_step(C& controller, const AnalyticTwin& twin, int t, bool propose,
                                    VectorX& u) {
  const AssemblyId x = twin.assemblies()[static_cast<std::size_t>(t)];
  if (propose) u = controller.propose(x);
  const double offset = 0.1 * std::sin(0.1 * static_cast<double>(t));
  controller.observe(x, typename C::ControlVector(u), twin.quality(x, VectorX(u.array() - offset)));
  return controller.save().dump();
}

// A snapshot that went through text restores a controller built alike bit for bit, taken after
// an observation or between a proposal and its observation (the chosen candidate's preview,
// which observe commits), with every kind of filter.
TYPED_TEST(LookaheadControllerFilters, ASnapshotRestoresItBitForBit) {
  using F = TypeParam;
  const AnalyticTwin twin = make_twin(1);
  const CountingTwin counting(twin);
  const auto make = [&counting] {
    return LookaheadController<F, Sobol>(
        make_filter<F>(counting, Vector<F::dimension_at_compile_time>::Zero(1), 1e-3),
        Sobol(1, scrambled(9)), {.w = 0.5});
  };
  for (const bool between : {false, true}) {
    auto original = make();
    VectorX u;
    for (int t = 0; t < 30; ++t) (void)lookahead_snapshot_step(original, twin, t, true, u);
    if (between) u = original.propose(twin.assemblies()[30]);
    const nlohmann::json snapshot = nlohmann::json::parse(original.save().dump());
    EXPECT_EQ(snapshot["pending"], between);
    auto restored = make();
    restored.restore(snapshot);
    EXPECT_EQ(restored.save(), snapshot);
    VectorX v = u;
    for (int t = 30; t < 60; ++t) {
      const bool propose = !(between && t == 30);
      const std::string expected = lookahead_snapshot_step(original, twin, t, propose, u);
      const auto evaluations = counting.stats().evaluations;
      EXPECT_EQ(lookahead_snapshot_step(restored, twin, t, propose, v), expected)
          << "assembly " << t;
      if (!propose) {
        // The pending proposal's preview is committed, not evaluated afresh.
        EXPECT_EQ(counting.stats().evaluations, evaluations);
      }
    }
  }
}

TEST(LookaheadController, RefusesABadSnapshotAndKeepsItsState) {
  const AnalyticTwin twin = make_twin(2);
  const CountingTwin counting(twin);
  const auto make = [&counting] {
    return SobolController<test_support::Ukf<2>>(
        make_filter<test_support::Ukf<2>>(counting, Eigen::Vector2d::Zero(), 1e-3),
        Sobol(2, scrambled(4)), {.w = 0.3});
  };
  auto tried = make();
  auto untouched = make();
  VectorX u;
  VectorX v;
  for (int t = 0; t < 10; ++t) {
    (void)lookahead_snapshot_step(tried, twin, t, true, u);
    (void)lookahead_snapshot_step(untouched, twin, t, true, v);
  }
  auto other = make();
  (void)lookahead_snapshot_step(other, twin, 0, true, u);
  const nlohmann::json good = other.save();
  const std::string state = tried.save().dump();
  nlohmann::json bad = good;
  bad["filter"]["covariance"][0][0] = -1.0;  // the filter's part is restored last
  EXPECT_THROW(tried.restore(bad), NotPositiveDefiniteError);
  bad = good;
  bad["sampler"]["format"] = "twincal.halton";
  EXPECT_THAT([&] { tried.restore(bad); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  ::testing::StartsWith("sampler.format: is \"twincal.halton\"")));
  bad = good;
  bad["report"].erase("chosen");
  EXPECT_THROW(tried.restore(bad), InvalidArgumentError);
  EXPECT_EQ(tried.save().dump(), state);
  for (int t = 10; t < 20; ++t) {
    EXPECT_EQ(lookahead_snapshot_step(tried, twin, t, true, u),
              lookahead_snapshot_step(untouched, twin, t, true, v));
  }
}

TEST(LookaheadController, AblationsAreTypeChanges) {
  // Halton for Sobol, log-det for trace, CKF for UKF: the same code and guarantees.
  const AnalyticTwin twin = make_twin(1);
  const CountingTwin counting(twin);
  using F = test_support::Ckf<1>;
  LookaheadController<F, Halton, ExpectedQuality, LogDetLoss> controller(
      make_filter<F>(counting, Vector<1>::Zero(), 1e-3), Halton(1), {.w = 0.7});
  expect_tracking(track_drift(controller, twin, 7));
}

}  // namespace
}  // namespace twincal
