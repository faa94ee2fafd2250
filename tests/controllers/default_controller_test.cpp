#include "twincal/controllers/default_controller.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "controller_fixture.hpp"

namespace twincal {
namespace {

using test_support::AnalyticTwin;
using test_support::CountingTwin;
using test_support::make_filter;
using test_support::make_twin;

static_assert(EstimatingController<DefaultController<test_support::Ukf<3>>>);
static_assert(EstimatingController<DefaultController<test_support::Ckf<Dynamic>>>);

TEST(DefaultController, WithZeroOffsetEstimateItAppliesTheIndividualOptimum) {
  const AnalyticTwin twin = make_twin(3);
  const CountingTwin counting(twin);
  using F = test_support::Ukf<3>;
  DefaultController<F> controller(make_filter<F>(counting, Eigen::Vector3d::Zero(), 1e-3));
  const AssemblyId x{5, 2};
  const Eigen::Vector3d u = controller.propose(x);
  EXPECT_EQ(u, twin.optimum(x));  // eq. (9) with δû = 0
  EXPECT_EQ(controller.last_proposal().optimal_quality, twin.optimal_quality(x));
  EXPECT_EQ(controller.last_proposal().optimizer_evaluations, 0U);
  EXPECT_FALSE(controller.last_proposal().fell_back());
}

TEST(DefaultController, AppliesTheOptimumCorrectedByTheFilterEstimateAndLearns) {
  const AnalyticTwin twin = make_twin(2);
  const CountingTwin counting(twin);
  using F = test_support::Ukf<Dynamic>;
  DefaultController<F> controller(make_filter<F>(counting, Eigen::Vector2d(0.1, -0.2), 1e-3));
  F reference = controller.filter();
  const AssemblyId x{0, 9};
  const Eigen::VectorXd u = controller.propose(x);
  reference.predict();
  EXPECT_EQ(u, twin.optimum(x) + reference.state());
  const EvaluationStats before = counting.stats();
  controller.observe(x, u, 0.9);
  EXPECT_EQ((counting.stats() - before).evaluations, 5U);  // one update, 2n+1 sigma points
  reference.update(0.9, {x, u});
  EXPECT_EQ(controller.offset_estimate(), reference.state());
  EXPECT_EQ(controller.offset_covariance(), reference.covariance());
}

// The twin fails at the update's sigma points (TwinError: behind an Evaluator): the measurement
// is dropped, the filter stays as predicted, the report says why, and the next proposal goes on.
TEST(DefaultController, DropsAMeasurementItsTwinCannotBeAskedAboutAndGoesOn) {
  const test_support::FailingTwinSetup setup(0);  // every batch fails
  using F = test_support::FailingTwinSetup::Filter;
  F reference = setup.filter();
  DefaultController<F> controller(setup.filter());
  const AssemblyId x{3, 3};
  const Eigen::Vector2d u = controller.propose(x);  // u0 is the twin's own: no evaluation
  controller.observe(x, u, 0.5);
  reference.predict();
  EXPECT_EQ(controller.offset_estimate(), reference.state());
  EXPECT_EQ(controller.offset_covariance(), reference.covariance());
  EXPECT_TRUE(controller.last_proposal().dropped());
  EXPECT_THAT(controller.last_proposal().dropped_measurement,
              ::testing::HasSubstr("FEM solver crashed"));
  (void)controller.propose(x);
  EXPECT_FALSE(controller.last_proposal().dropped());
}

}  // namespace
}  // namespace twincal
