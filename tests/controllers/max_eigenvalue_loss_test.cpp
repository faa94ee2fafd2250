#include "twincal/controllers/max_eigenvalue_loss.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/controllers/exploration_loss.hpp"
#include "twincal/controllers/trace_loss.hpp"

namespace twincal {
namespace {

static_assert(ExplorationLoss<MaxEigenvalueLoss, Dynamic>);

TEST(MaxEigenvalueLoss, IsTheLongestAxisOnTheCommonScale) {
  const Eigen::Matrix2d isotropic = 0.09 * Eigen::Matrix2d::Identity();
  EXPECT_NEAR(MaxEigenvalueLoss{}(isotropic), TraceLoss{}(isotropic), 1e-15);
  Eigen::Matrix2d p;
  p << 2.0, 1.0, 1.0, 2.0;  // eigenvalues 1 and 3
  EXPECT_NEAR(MaxEigenvalueLoss{}(p), std::sqrt(3.0) / std::sqrt(2.0), 1e-14);
}

TEST(MaxEigenvalueLoss, RejectsAnIndefiniteMatrix) {
  Eigen::Matrix2d p;
  p << 1.0, 2.0, 2.0, 1.0;
  EXPECT_THAT([&] { (void)MaxEigenvalueLoss{}(p); },
              ::testing::ThrowsMessage<NotPositiveDefiniteError>(
                  "posterior_covariance: smallest eigenvalue is -1; rule: must be positive "
                  "semi-definite (all eigenvalues >= 0)"));
}

}  // namespace
}  // namespace twincal
