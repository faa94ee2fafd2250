#include "twincal/core/gaussian.hpp"

#include <cmath>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(Gaussian, HoldsMeanAndCovariance) {
  const Gaussian<2> g(Eigen::Vector2d(1.0, -1.0), Eigen::Matrix2d::Identity() * 0.5);
  EXPECT_EQ(g.dimension(), 2);
  EXPECT_EQ(g.mean(), Eigen::Vector2d(1.0, -1.0));
  EXPECT_EQ(g.covariance(), Eigen::Matrix2d::Identity() * 0.5);
  EXPECT_EQ(g, Gaussian<2>(g.mean(), g.covariance()));
}

TEST(Gaussian, DynamicSizeAndSemidefiniteCovarianceAreAccepted) {
  const Eigen::VectorXd mean = Eigen::VectorXd::Zero(3);
  const Eigen::MatrixXd singular = Eigen::VectorXd::Ones(3) * Eigen::RowVectorXd::Ones(3);
  const Gaussian<Dynamic> g(mean, singular);
  EXPECT_EQ(g.dimension(), 3);
}

TEST(Gaussian, RejectsBadInputWithTypedErrors) {
  EXPECT_THAT(
      [] { Gaussian<Dynamic>(Eigen::VectorXd::Zero(2), Eigen::MatrixXd::Identity(3, 3)); },
      ::testing::ThrowsMessage<DimensionMismatchError>("covariance: is 3x3; rule: must be 2x2"));
  EXPECT_THAT([] { Gaussian<2>(Eigen::Vector2d(0.0, std::nan("")), Eigen::Matrix2d::Identity()); },
              ::testing::ThrowsMessage<NonFiniteError>(
                  "mean: entry 1 is nan; rule: every entry must be finite"));
  EXPECT_THAT(
      [] { Gaussian<2>(Eigen::Vector2d::Zero(), Eigen::Matrix2d(-Eigen::Matrix2d::Identity())); },
      ::testing::ThrowsMessage<NotPositiveDefiniteError>(
          "covariance: smallest eigenvalue is -1; rule: must be positive semi-definite (all "
          "eigenvalues >= 0)"));
}

TEST(Gaussian, LogDensityMatchesTheClosedForm) {
  Eigen::Matrix2d p;
  p << 2.0, 0.3, 0.3, 1.0;
  const Gaussian<2> g(Eigen::Vector2d(0.5, -0.2), p);
  const Eigen::Vector2d x(1.0, 0.4);
  const Eigen::Vector2d r = x - g.mean();
  const double expected = -0.5 * (r.dot(p.inverse() * r) + std::log(p.determinant()) +
                                  2.0 * std::log(2.0 * std::numbers::pi));
  EXPECT_NEAR(g.log_density(x), expected, 1e-13);
  const Gaussian<Dynamic> dynamic(g.mean(), g.covariance());
  EXPECT_THAT([&] { (void)dynamic.log_density(Eigen::VectorXd::Zero(3)); },
              ::testing::ThrowsMessage<DimensionMismatchError>("x: size is 3; rule: must equal 2"));
}

TEST(Gaussian, LogDensityOfASingularGaussianIsAnError) {
  const Gaussian<2> g(Eigen::Vector2d::Zero(), Eigen::Matrix2d::Zero());
  EXPECT_THAT([&] { (void)g.log_density(Eigen::Vector2d::Zero()); },
              ::testing::ThrowsMessage<NotPositiveDefiniteError>(::testing::HasSubstr(
                  "covariance: Cholesky factorization failed (repair policy: none): smallest "
                  "eigenvalue is 0")));
}

TEST(Gaussian, FormatsWithAnElementSpec) {
  const Gaussian<2> g(Eigen::Vector2d(1.0, 2.0), Eigen::Matrix2d::Identity());
  EXPECT_EQ(fmt::format("{:.1f}", g), "N(mean=[1.0, 2.0], covariance=[[1.0, 0.0], [0.0, 1.0]])");
}

}  // namespace
}  // namespace twincal
