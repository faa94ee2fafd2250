#include "twincal/controllers/update_or_drop.hpp"

#include <limits>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "controller_fixture.hpp"

namespace twincal {
namespace {

using test_support::FailingOnLargeBatches;

// The filter over a twin that fails on batches of more than `max_batch` controls (behind an
// Evaluator its failures are TwinErrors, bare they are std::runtime_errors), predicted once.
template <typename F>
F predicted_filter_over(const typename MeasurementModelOf<F>::TwinType& twin) {
  constexpr int N = F::dimension_at_compile_time;
  using Model = MeasurementModelOf<F>;
  const Vector<N> start = Vector<N>::Constant(2, 0.02);
  const SquareMatrix<N> covariance = SquareMatrix<N>::Identity(2, 2) * 1e-3;
  if constexpr (requires {
                  F(RandomWalk<N>::isotropic(2, 1e-3), Model(twin, 1e-4),
                    SphericalRadialSigmaPoints{}, start, covariance);
                }) {
    F filter(RandomWalk<N>::isotropic(2, 1e-3), Model(twin, 1e-4), SphericalRadialSigmaPoints{},
             start, covariance);
    filter.predict();
    return filter;
  } else {
    F filter(RandomWalk<N>::isotropic(2, 1e-3), Model(twin, 1e-4), test_support::merwe(), start,
             covariance);
    filter.predict();
    return filter;
  }
}

template <typename F>
class UpdateOrDropTest : public ::testing::Test {};
using CheckedTwin = test_support::FailingTwinSetup::Checked;
using EveryFilter = ::testing::Types<
    UnscentedKalmanFilter<RandomWalk<2>, QualityFeedback<CheckedTwin, 2>>,
    CubatureKalmanFilter<RandomWalk<Dynamic>, QualityFeedback<CheckedTwin, Dynamic>>,
    SquareRootSigmaPointFilter<RandomWalk<2>, QualityFeedback<CheckedTwin, 2>,
                               MerweScaledSigmaPoints>>;
TYPED_TEST_SUITE(UpdateOrDropTest, EveryFilter);

TYPED_TEST(UpdateOrDropTest, UpdatesAsTheFilterDoesWhileTheTwinAnswers) {
  using F = TypeParam;
  const test_support::FailingTwinSetup setup(100);  // no batch fails
  F filter = predicted_filter_over<F>(setup.twin);
  F reference = filter;
  ProposalReport report;
  const AssemblyId x{1, 2};
  const typename F::StateVector control = setup.inner.optimum(x);
  update_or_drop(filter, 0.4, {x, control}, report);
  reference.update(0.4, {x, control});
  EXPECT_EQ(filter.state(), reference.state());
  EXPECT_EQ(filter.covariance(), reference.covariance());
  EXPECT_FALSE(report.dropped());
}

TYPED_TEST(UpdateOrDropTest, DropsTheMeasurementWhenTheTwinFailsAndLeavesTheFilterAsPredicted) {
  using F = TypeParam;
  const test_support::FailingTwinSetup setup(0);  // every batch fails
  F filter = predicted_filter_over<F>(setup.twin);
  const F predicted = filter;
  ProposalReport report;
  const AssemblyId x{1, 2};
  const typename F::StateVector control = setup.inner.optimum(x);
  update_or_drop(filter, 0.4, {x, control}, report);
  EXPECT_EQ(filter.state(), predicted.state());
  EXPECT_EQ(filter.covariance(), predicted.covariance());
  EXPECT_EQ(filter.update_count(), predicted.update_count());
  EXPECT_TRUE(report.dropped());
  EXPECT_THAT(report.dropped_measurement, ::testing::HasSubstr("FEM solver crashed"));
}

// Only the twin's failures are dropped: an error of the filter or of the measurement (here a
// non-finite z) stops the caller, as before.
TYPED_TEST(UpdateOrDropTest, LetsEveryOtherErrorThrough) {
  using F = TypeParam;
  const test_support::FailingTwinSetup setup(100);  // no batch fails
  F filter = predicted_filter_over<F>(setup.twin);
  ProposalReport report;
  const AssemblyId x{1, 2};
  const typename F::StateVector control = setup.inner.optimum(x);
  EXPECT_THROW(
      update_or_drop(filter, std::numeric_limits<double>::quiet_NaN(), {x, control}, report),
      NonFiniteError);
  EXPECT_FALSE(report.dropped());
}

// A twin's own exception that is not a TwinError (no Evaluator around the twin to say what it
// is) is not taken for one: it stops the caller.
TEST(UpdateOrDrop, DoesNotTakeAnUntypedExceptionForATwinFailure) {
  using F = UnscentedKalmanFilter<RandomWalk<2>, QualityFeedback<FailingOnLargeBatches, 2>>;
  const test_support::FailingTwinSetup setup(0);
  F filter = predicted_filter_over<F>(setup.failing);  // the bare twin, without its Evaluator
  const F predicted = filter;
  ProposalReport report;
  const AssemblyId x{1, 2};
  EXPECT_THROW(update_or_drop(filter, 0.4, {x, Eigen::Vector2d(setup.inner.optimum(x))}, report),
               std::runtime_error);
  EXPECT_FALSE(report.dropped());
  EXPECT_EQ(filter.state(), predicted.state());
  EXPECT_EQ(filter.covariance(), predicted.covariance());
}

}  // namespace
}  // namespace twincal
