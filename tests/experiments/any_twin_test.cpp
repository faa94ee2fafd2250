#include "twincal/experiments/any_twin.hpp"

#include <cstdint>
#include <optional>
#include <utility>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/controllers/searched_optimum_twin.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/kink_nonlinearity.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal {
namespace {

TEST(AnyTwin, ForwardsEveryCallToTheWrappedTwin) {
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate({}, RandomStream(5));
  const AnyTwin any(twin, twin.assemblies(), {2, 0});
  EXPECT_EQ(any.control_dimension(), twin.control_dimension());
  EXPECT_EQ(any.locator_names(), twin.locator_names());
  EXPECT_EQ(any.lower_bounds(), twin.lower_bounds());
  EXPECT_EQ(any.upper_bounds(), twin.upper_bounds());
  EXPECT_EQ(any.assemblies(), twin.assemblies());
  EXPECT_EQ(any.significant_locators(), (std::vector<Index>{2, 0}));
  const AssemblyId x{3, 8};
  const Eigen::Vector3d u(0.1, -0.05, 0.2);
  EXPECT_EQ(any.quality(x, u), twin.quality(x, u));
  EXPECT_EQ(any.optimum(x), twin.optimum(x));
  EXPECT_EQ(any.optimal_quality(x), twin.optimal_quality(x));
  const Eigen::MatrixXd controls = Eigen::MatrixXd::Constant(3, 4, 0.07);
  Eigen::VectorXd a(4);
  Eigen::VectorXd b(4);
  any.quality_batch(x, controls, a);
  twin.quality_batch(x, controls, b);
  EXPECT_EQ(a, b);
}

TEST(AnyTwin, ForwardsTheDeviationsOfATwinThatAnswersThem) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = 3;
  const KeyPointTwin<KinkNonlinearity> twin(options, RandomStream(6));
  // Through a SearchedOptimumTwin, as the experiments wrap it (it passes the deviations on).
  SearchedOptimumTwin<KeyPointTwin<KinkNonlinearity>> searched(twin, {{4, 1}});
  const AnyTwin any(std::move(searched), {{4, 1}}, {0, 1, 2});
  ASSERT_EQ(any.key_point_count(), twin.key_point_count());
  const Eigen::MatrixXd controls = Eigen::MatrixXd::Constant(3, 2, -0.3);
  Eigen::MatrixXd a(twin.key_point_count(), 2);
  Eigen::MatrixXd b(twin.key_point_count(), 2);
  any.deviations_batch({4, 1}, controls, a);
  twin.deviations_batch({4, 1}, controls, b);
  EXPECT_EQ(a, b);
}

TEST(AnyTwin, ATwinThatAnswersOnlyItsQualityHasNoKeyPoints) {
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate({}, RandomStream(5));
  const AnyTwin any(twin, twin.assemblies(), {0});
  EXPECT_EQ(any.key_point_count(), 0);
  Eigen::MatrixXd out(1, 1);
  EXPECT_THAT(
      [&] {
        any.deviations_batch({0, 0}, Eigen::MatrixXd::Zero(3, 1), out);
      },
      ::testing::ThrowsMessage<InvalidArgumentError>(
          ::testing::HasSubstr("deviations: this twin answers only its quality")));
}

TEST(AnyTwin, ReportsWhatTheOptimumSearchesOfATwinThatSearchesCost) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = 3;
  const KeyPointTwin<KinkNonlinearity> twin(options, RandomStream(6));
  SearchedOptimumTwin<KeyPointTwin<KinkNonlinearity>> searched(twin, {{4, 1}, {2, 7}});
  const std::uint64_t evaluations = searched.search_evaluations();
  ASSERT_GT(evaluations, 0U);
  const AnyTwin any(std::move(searched), {{4, 1}, {2, 7}}, {0, 1, 2});
  const std::optional<OptimumSearchCost> cost = any.optimum_search();
  ASSERT_TRUE(cost.has_value());
  EXPECT_EQ(cost->evaluations, evaluations);
  EXPECT_EQ(cost->requests, evaluations);  // NLopt asks for one control per call
  EXPECT_EQ(cost->assemblies, 2);
  // A twin that knows its optimum searched nothing.
  const RmsQuadraticTwin exact = RmsQuadraticTwin::generate({}, RandomStream(5));
  EXPECT_FALSE(AnyTwin(exact, exact.assemblies(), {0}).optimum_search().has_value());
}

TEST(AnyTwin, CopiesShareTheTwin) {
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate({}, RandomStream(5));
  const AnyTwin any(twin, twin.assemblies(), {0});
  const AnyTwin copy = any;  // NOLINT(performance-unnecessary-copy-initialization)
  EXPECT_EQ(&copy.locator_names(), &any.locator_names());
}

}  // namespace
}  // namespace twincal
