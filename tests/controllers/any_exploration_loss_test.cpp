#include "twincal/controllers/any_exploration_loss.hpp"

#include <variant>

#include <gtest/gtest.h>

#include "twincal/controllers/exploration_kind.hpp"
#include "twincal/core/error.hpp"

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

TEST(AnyExplorationLoss, MakesTheKindAndAsksForWeightsOnlyForTheWeightedTrace) {
  int asked = 0;
  const auto weights = [&asked] {
    ++asked;
    return VectorX(Eigen::Vector3d(2.0, 0.5, 0.5));
  };
  EXPECT_TRUE(std::holds_alternative<TraceLoss>(
      make_exploration_loss(ExplorationKind::trace, weights).loss()));
  EXPECT_TRUE(std::holds_alternative<LogDetLoss>(
      make_exploration_loss(ExplorationKind::log_det, weights).loss()));
  EXPECT_TRUE(std::holds_alternative<MaxEigenvalueLoss>(
      make_exploration_loss(ExplorationKind::max_eigenvalue, weights).loss()));
  EXPECT_EQ(asked, 0);
  const AnyExplorationLoss weighted =
      make_exploration_loss(ExplorationKind::weighted_trace, weights);
  EXPECT_EQ(asked, 1);
  ASSERT_TRUE(std::holds_alternative<WeightedTraceLoss>(weighted.loss()));
  EXPECT_EQ(std::get<WeightedTraceLoss>(weighted.loss()).weights(), weights());
  // The weighted trace's rules on W hold, and the weights' own errors come through.
  EXPECT_THROW((void)make_exploration_loss(ExplorationKind::weighted_trace,
                                           [] { return VectorX(VectorX::Zero(2)); }),
               InvalidArgumentError);
  EXPECT_THROW((void)make_exploration_loss(
                   ExplorationKind::weighted_trace,
                   []() -> VectorX { throw InvalidArgumentError("weights", "weights: none"); }),
               InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
