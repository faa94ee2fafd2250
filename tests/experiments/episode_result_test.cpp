#include "twincal/experiments/episode_result.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "twincal/core/random_stream.hpp"

namespace twincal {
namespace {

// A hand-built trace of `steps` assemblies over d = 2 locators, sized for `planned` (the columns
// beyond `steps` are NaN, as after an episode stopped early); estimate and offset zero until set.
EpisodeResult lost_trace(Index steps, Index planned) {
  EpisodeResult result;
  result.steps = steps;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  result.estimate = MatrixX::Constant(2, planned, nan);
  result.offset = MatrixX::Constant(2, planned, nan);
  result.estimate.leftCols(steps).setZero();
  result.offset.leftCols(steps).setZero();
  return result;
}

TEST(AssessLost, AnEstimateWorseThanNoneOverTheSecondHalfIsLost) {
  // Second half: t = 2, 3. ‖δu*‖ = 5 there; the estimate stands at (−3, −4), 10 away.
  EpisodeResult result = lost_trace(4, 4);
  result.offset.col(2) << 3.0, 4.0;
  result.offset.col(3) << 3.0, 4.0;
  result.estimate.col(2) << -3.0, -4.0;
  result.estimate.col(3) << -3.0, -4.0;
  assess_lost(result);
  EXPECT_DOUBLE_EQ(result.estimate_error_second_half, 10.0);
  EXPECT_DOUBLE_EQ(result.offset_norm_second_half, 5.0);
  EXPECT_TRUE(result.lost);
  EXPECT_FALSE(result.diverged());  // the rule stands beside divergence, not on it
}

TEST(AssessLost, OnlyTheSecondHalfCounts) {
  // A wild start (t = 0, 1) that has converged by the second half is not lost...
  EpisodeResult converged = lost_trace(4, 4);
  converged.estimate.col(0) << 50.0, -50.0;
  converged.estimate.col(1) << 20.0, 20.0;
  for (Index t = 0; t < 4; ++t) converged.offset.col(t) << 1.0, 0.0;
  converged.estimate.col(2) << 0.9, 0.0;
  converged.estimate.col(3) << 1.1, 0.0;
  assess_lost(converged);
  EXPECT_NEAR(converged.estimate_error_second_half, 0.1, 1e-12);
  EXPECT_FALSE(converged.lost);

  // ...and a good start that wanders off later is. With 5 steps the second half is t = 2, 3, 4.
  EpisodeResult wandered = lost_trace(5, 5);
  for (Index t = 0; t < 5; ++t) wandered.offset.col(t) << 1.0, 0.0;
  wandered.estimate.col(0) << 1.0, 0.0;
  wandered.estimate.col(1) << 1.0, 0.0;
  wandered.estimate.col(2) << 1.0, 0.0;  // exact at t = 2, off by 2 at t = 3 and 4
  wandered.estimate.col(3) << -1.0, 0.0;
  wandered.estimate.col(4) << 3.0, 0.0;
  assess_lost(wandered);
  EXPECT_DOUBLE_EQ(wandered.estimate_error_second_half, 4.0 / 3.0);
  EXPECT_DOUBLE_EQ(wandered.offset_norm_second_half, 1.0);
  EXPECT_TRUE(wandered.lost);
}

TEST(AssessLost, AnErrorEqualToTheBaselinesIsNotLostAndOneAboveIs) {
  // δû = 2 δu*: the error is ‖δu*‖ exactly (3-4-5 numbers, no rounding) — the boundary.
  EpisodeResult boundary = lost_trace(2, 2);
  boundary.offset.col(1) << 3.0, 4.0;
  boundary.estimate.col(1) << 6.0, 8.0;
  assess_lost(boundary);
  EXPECT_EQ(boundary.estimate_error_second_half, boundary.offset_norm_second_half);
  EXPECT_FALSE(boundary.lost);

  EpisodeResult above = boundary;
  above.estimate(0, 1) = 6.0 + 1e-9;  // ‖δû − δu*‖ = 5 + 6e-10
  assess_lost(above);
  EXPECT_GT(above.estimate_error_second_half, above.offset_norm_second_half);
  EXPECT_TRUE(above.lost);
}

TEST(AssessLost, TheBaselineIsNeverLost) {
  // δû = 0 against offsets with rounding in every norm, over many lengths (odd and even halves)
  // and with NaN columns past `steps`: the two means agree to the bit.
  RandomStream stream(7);
  for (Index steps = 1; steps <= 40; ++steps) {
    EpisodeResult baseline = lost_trace(steps, steps + 3);
    baseline.offset = MatrixX::Constant(3, steps + 3, std::numeric_limits<double>::quiet_NaN());
    baseline.estimate = MatrixX::Zero(3, steps + 3);
    for (Index t = 0; t < steps; ++t) {
      for (Index i = 0; i < 3; ++i) baseline.offset(i, t) = 0.37 * stream.normal();
    }
    assess_lost(baseline);
    EXPECT_EQ(baseline.estimate_error_second_half, baseline.offset_norm_second_half) << steps;
    EXPECT_FALSE(baseline.lost) << steps;
  }
}

TEST(AssessLost, AnEpisodeWithoutStepsHasNoMeansAndIsNotLost) {
  EpisodeResult result = lost_trace(0, 3);
  result.diverged_at = 0;  // a controller that failed at its first assembly
  assess_lost(result);
  EXPECT_TRUE(std::isnan(result.estimate_error_second_half));
  EXPECT_TRUE(std::isnan(result.offset_norm_second_half));
  EXPECT_FALSE(result.lost);
}

}  // namespace
}  // namespace twincal
