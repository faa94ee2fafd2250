#include "twincal/experiments/any_exploration_loss.hpp"

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(AnyExplorationLoss, EvaluatesTheChosenLoss) {
  Eigen::Matrix3d p;
  p << 0.04, 0.01, 0.0, 0.01, 0.09, 0.02, 0.0, 0.02, 0.01;
  EXPECT_EQ(AnyExplorationLoss()(p), TraceLoss{}(p));
  EXPECT_EQ(AnyExplorationLoss(LogDetLoss{})(p), LogDetLoss{}(p));
  EXPECT_EQ(AnyExplorationLoss(MaxEigenvalueLoss{})(p), MaxEigenvalueLoss{}(p));
  const WeightedTraceLoss weighted(Eigen::Vector3d(2.0, 0.5, 0.5));
  EXPECT_EQ(AnyExplorationLoss(weighted)(p), weighted(p));
  EXPECT_NE(AnyExplorationLoss(weighted)(p), TraceLoss{}(p));
}

}  // namespace
}  // namespace twincal
