#include "twincal/controllers/log_det_loss.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/controllers/exploration_loss.hpp"
#include "twincal/controllers/trace_loss.hpp"

namespace twincal {
namespace {

static_assert(ExplorationLoss<LogDetLoss, 2>);

TEST(LogDetLoss, SharesTheTraceLossScaleForIsotropicCovariances) {
  const Eigen::Matrix3d p = 0.04 * Eigen::Matrix3d::Identity();
  EXPECT_NEAR(LogDetLoss{}(p), TraceLoss{}(p), 1e-15);  // σ/√d = 0.2/√3
}

TEST(LogDetLoss, MeasuresVolumeNotSpread) {
  // Same trace, different volume: the elongated ellipse has the smaller determinant.
  const Eigen::Matrix2d round = Eigen::Vector2d(0.5, 0.5).asDiagonal();
  const Eigen::Matrix2d elongated = Eigen::Vector2d(0.9, 0.1).asDiagonal();
  EXPECT_DOUBLE_EQ(TraceLoss{}(round), TraceLoss{}(elongated));
  EXPECT_LT(LogDetLoss{}(elongated), LogDetLoss{}(round));
  EXPECT_NEAR(LogDetLoss{}(elongated), std::pow(0.09, 0.25) / std::sqrt(2.0), 1e-15);
}

TEST(LogDetLoss, ASingularPosteriorIsAnError) {
  EXPECT_THAT([] { (void)LogDetLoss{}(Eigen::Matrix2d(Eigen::Vector2d(1.0, 0.0).asDiagonal())); },
              ::testing::ThrowsMessage<NotPositiveDefiniteError>(::testing::HasSubstr(
                  "posterior_covariance: Cholesky factorization failed (repair policy: none): "
                  "smallest eigenvalue is 0")));
}

}  // namespace
}  // namespace twincal
