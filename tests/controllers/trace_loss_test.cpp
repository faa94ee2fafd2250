#include "twincal/controllers/trace_loss.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(TraceLoss, IsEquationTwelve) {
  Eigen::Matrix3d p;
  p << 0.04, 0.01, 0.0, 0.01, 0.09, 0.0, 0.0, 0.0, 0.16;
  EXPECT_DOUBLE_EQ(TraceLoss{}(p), std::sqrt(0.29) / 3.0);
  EXPECT_DOUBLE_EQ(TraceLoss{}(Eigen::MatrixXd::Identity(4, 4)), 2.0 / 4.0);
}

TEST(TraceLoss, SmallerPosteriorMeansSmallerLoss) {
  const Eigen::Matrix2d wide = Eigen::Matrix2d::Identity();
  const Eigen::Matrix2d narrow = 0.5 * Eigen::Matrix2d::Identity();
  EXPECT_LT(TraceLoss{}(narrow), TraceLoss{}(wide));
}

TEST(TraceLoss, RejectsWhatIsNotACovariance) {
  EXPECT_THAT([] { (void)TraceLoss{}(Eigen::MatrixXd::Zero(2, 3)); },
              ::testing::ThrowsMessage<DimensionMismatchError>(
                  "posterior_covariance: is 2x3; rule: must be square"));
  EXPECT_THAT([] { (void)TraceLoss{}(Eigen::MatrixXd(0, 0)); },
              ::testing::ThrowsMessage<DimensionMismatchError>(
                  "posterior_covariance: is 0x0; rule: must be at least 1x1"));
  EXPECT_THAT([] { (void)TraceLoss{}(Eigen::Matrix2d(-Eigen::Matrix2d::Identity())); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "trace(posterior_covariance): value is -2; rule: must be >= 0"));
  Eigen::Matrix2d p = Eigen::Matrix2d::Identity();
  p(0, 1) = std::nan("");
  EXPECT_THAT([&] { (void)TraceLoss{}(p); },
              ::testing::ThrowsMessage<NonFiniteError>(
                  "posterior_covariance: entry (0, 1) is nan; rule: every entry must be finite"));
}

}  // namespace
}  // namespace twincal
