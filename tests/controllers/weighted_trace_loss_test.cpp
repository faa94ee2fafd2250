#include "twincal/controllers/weighted_trace_loss.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/controllers/exploration_loss.hpp"
#include "twincal/controllers/trace_loss.hpp"

namespace twincal {
namespace {

static_assert(ExplorationLoss<WeightedTraceLoss, 3>);
static_assert(ExplorationLoss<WeightedTraceLoss, Dynamic>);

TEST(WeightedTraceLoss, IsTheSectionFourLossAndReducesToTraceLossForIdentityWeights) {
  Eigen::Matrix3d p;
  p << 0.04, 0.01, 0.0, 0.01, 0.09, 0.0, 0.0, 0.0, 0.16;
  const WeightedTraceLoss weighted(Eigen::Vector3d(2.0, 0.0, 1.0));
  EXPECT_DOUBLE_EQ(weighted(p), std::sqrt(2.0 * 0.04 + 0.16) / 3.0);
  EXPECT_DOUBLE_EQ(WeightedTraceLoss(Eigen::VectorXd::Ones(3))(p), TraceLoss{}(p));
}

TEST(WeightedTraceLoss, RejectsBadWeightsAndShapes) {
  EXPECT_THAT([] { WeightedTraceLoss(Eigen::Vector2d(1.0, -0.5)); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "weights(1): value is -0.5; rule: must be >= 0"));
  EXPECT_THAT([] { (void)WeightedTraceLoss(Eigen::Vector2d::Zero()); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "weights: all entries are 0; rule: at least one weight must be > 0"));
  EXPECT_THAT([] { WeightedTraceLoss(Eigen::Vector2d(1.0, std::nan(""))); },
              ::testing::ThrowsMessage<NonFiniteError>(
                  "weights: entry 1 is nan; rule: every entry must be finite"));
  const WeightedTraceLoss loss(Eigen::Vector2d::Ones());
  EXPECT_THAT([&] { (void)loss(Eigen::Matrix3d::Identity()); },
              ::testing::ThrowsMessage<DimensionMismatchError>(
                  "posterior_covariance: rows is 3; rule: must equal 2"));
  EXPECT_THAT([&] { (void)loss(Eigen::Matrix2d(-Eigen::Matrix2d::Identity())); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "tr(W posterior_covariance): value is -2; rule: must be >= 0"));
}

}  // namespace
}  // namespace twincal
