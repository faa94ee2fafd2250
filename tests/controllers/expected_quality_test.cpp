#include "twincal/controllers/expected_quality.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/controllers/exploitation_loss.hpp"

namespace twincal {
namespace {

static_assert(ExploitationLoss<ExpectedQuality>);

TEST(ExpectedQuality, IsTheWeightedSumOfEquationEleven) {
  const Eigen::Vector3d q(1.0, 2.0, 4.0);
  const Eigen::Vector3d w(0.5, 0.25, 0.25);
  EXPECT_DOUBLE_EQ(ExpectedQuality{}(q, w), 0.5 + 0.5 + 1.0);
  // Negative centre weights (scaled unscented points) are used as they are.
  EXPECT_DOUBLE_EQ(ExpectedQuality{}(q, Eigen::Vector3d(-1.0, 1.0, 1.0)), 5.0);
}

TEST(ExpectedQuality, SizesMustAgree) {
  EXPECT_THAT(
      [] { (void)ExpectedQuality{}(Eigen::Vector2d::Ones(), Eigen::Vector3d::Ones()); },
      ::testing::ThrowsMessage<DimensionMismatchError>("qualities: size is 2; rule: must equal 3"));
}

}  // namespace
}  // namespace twincal
