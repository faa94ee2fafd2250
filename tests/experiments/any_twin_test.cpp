#include "twincal/experiments/any_twin.hpp"

#include <gtest/gtest.h>

#include "twincal/core/random_stream.hpp"
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

TEST(AnyTwin, CopiesShareTheTwin) {
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate({}, RandomStream(5));
  const AnyTwin any(twin, twin.assemblies(), {0});
  const AnyTwin copy = any;  // NOLINT(performance-unnecessary-copy-initialization)
  EXPECT_EQ(&copy.locator_names(), &any.locator_names());
}

}  // namespace
}  // namespace twincal
