#include "twincal/core/cholesky_factor.hpp"

#include <cmath>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/cholesky.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

Eigen::Matrix3d lower_factor() {
  Eigen::Matrix3d l;
  l << 2.0, 0.0, 0.0, 0.5, 1.5, 0.0, -0.3, 0.4, 1.2;
  return l;
}

TEST(CholeskyFactor, CovarianceAndLogDeterminant) {
  const CholeskyFactor<3> factor(lower_factor());
  EXPECT_EQ(factor.dimension(), 3);
  const Eigen::Matrix3d p = lower_factor() * lower_factor().transpose();
  EXPECT_TRUE(factor.covariance().isApprox(p, 1e-15));
  EXPECT_NEAR(factor.log_determinant(), std::log(p.determinant()), 1e-12);
}

TEST(CholeskyFactor, SolvesTheFactoredSystem) {
  const CholeskyFactor<3> factor(lower_factor());
  const Eigen::Vector3d b(1.0, -2.0, 0.5);
  const Eigen::Vector3d x = factor.solve(b);
  EXPECT_TRUE((factor.covariance() * x).isApprox(b, 1e-13));
  const CholeskyFactor<Dynamic> dynamic{Eigen::MatrixXd(lower_factor())};
  EXPECT_THAT([&] { (void)dynamic.solve(Eigen::VectorXd::Ones(2)); },
              ::testing::ThrowsMessage<DimensionMismatchError>("b: rows is 2; rule: must equal 3"));
}

TEST(CholeskyFactor, RejectsBrokenInvariants) {
  Eigen::Matrix3d upper = lower_factor();
  upper(0, 1) = 0.1;
  EXPECT_THAT([&] { CholeskyFactor<3>{upper}; },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "L: entry (0, 1) above the diagonal is 0.1; rule: a Cholesky factor is lower "
                  "triangular"));
  Eigen::Matrix3d zero_pivot = lower_factor();
  zero_pivot(1, 1) = 0.0;
  EXPECT_THAT([&] { CholeskyFactor<3>{zero_pivot}; },
              ::testing::ThrowsMessage<NotPositiveDefiniteError>(
                  "L: diagonal entry 1 is 0; rule: a Cholesky factor has a positive diagonal"));
  EXPECT_THAT([] { CholeskyFactor<Dynamic>{Eigen::MatrixXd::Identity(2, 3)}; },
              ::testing::ThrowsMessage<DimensionMismatchError>("L: is 2x3; rule: must be square"));
  Eigen::Matrix3d infinite = lower_factor();
  infinite(2, 0) = std::numeric_limits<double>::infinity();
  EXPECT_THAT([&] { CholeskyFactor<3>{infinite}; },
              ::testing::ThrowsMessage<NonFiniteError>(
                  "L: entry (2, 0) is inf; rule: every entry must be finite"));
}

TEST(CholeskyFactor, RankOneUpdateMatchesRefactorization) {
  CholeskyFactor<3> factor(lower_factor());
  const Eigen::Vector3d v(0.3, -1.0, 2.0);
  const Eigen::Matrix3d expected = factor.covariance() + 0.7 * v * v.transpose();
  factor.rank_one_update(v, 0.7);
  EXPECT_TRUE(factor.covariance().isApprox(expected, 1e-13));
  EXPECT_TRUE(factor.lower().isApprox(cholesky(expected).factor.lower(), 1e-13));
}

TEST(CholeskyFactor, RankOneDowndateMatchesRefactorization) {
  CholeskyFactor<Dynamic> factor{Eigen::MatrixXd(lower_factor())};
  const Eigen::VectorXd v = Eigen::Vector3d(0.2, 0.1, -0.3);
  const Eigen::MatrixXd expected = factor.covariance() - 0.5 * v * v.transpose();
  factor.rank_one_update(v, -0.5);
  EXPECT_TRUE(factor.covariance().isApprox(expected, 1e-13));
}

TEST(CholeskyFactor, FailedDowndateThrowsAndLeavesTheFactorUnchanged) {
  CholeskyFactor<3> factor(lower_factor());
  const Eigen::Matrix3d before = factor.lower();
  const Eigen::Vector3d v(10.0, 0.0, 0.0);  // removes far more than the variance 4 in x
  try {
    factor.rank_one_update(v, -1.0);
    FAIL() << "expected NotPositiveDefiniteError";
  } catch (const NotPositiveDefiniteError& e) {
    EXPECT_THAT(e.what(), HasSubstr("L: rank-one downdate by sigma = -1 fails at column 0"));
    EXPECT_LT(e.smallest_eigenvalue(), 0.0);
  }
  EXPECT_EQ(factor.lower(), before);
}

TEST(CholeskyFactor, RankOneUpdateValidatesItsArguments) {
  CholeskyFactor<Dynamic> factor{Eigen::MatrixXd(lower_factor())};
  // With fixed sizes a wrong-size v does not compile; at run time it is a typed error.
  EXPECT_THAT([&] { factor.rank_one_update(Eigen::VectorXd::Ones(2), 1.0); },
              ::testing::ThrowsMessage<DimensionMismatchError>("v: size is 2; rule: must equal 3"));
  EXPECT_THAT(
      [&] { factor.rank_one_update(Eigen::VectorXd::Ones(3), std::nan("")); },
      ::testing::ThrowsMessage<NonFiniteError>("sigma: value is nan; rule: must be finite"));
  const Eigen::MatrixXd before = factor.lower();
  factor.rank_one_update(Eigen::VectorXd::Ones(3), 0.0);
  EXPECT_EQ(factor.lower(), before);
}

}  // namespace
}  // namespace twincal

namespace twincal {
namespace {

// Size 2 is where GCC 12's vectorized tails once tripped -Warray-bounds; keep it compiled.
TEST(CholeskyFactor, FixedSizeTwoUpdateAndDowndate) {
  Eigen::Matrix2d l;
  l << 2.0, 0.0, 0.5, 1.0;
  CholeskyFactor<2> factor(l);
  const Eigen::Vector2d v(0.1, 0.2);
  const Eigen::Matrix2d expected = factor.covariance() - 0.5 * v * v.transpose();
  factor.rank_one_update(v, -0.5);
  EXPECT_TRUE(factor.covariance().isApprox(expected, 1e-14));
}

}  // namespace
}  // namespace twincal

namespace twincal {
namespace {

// The in-place kernel at a run-time size: the member's result, and the failing column reported
// instead of thrown.
TEST(RankOneUpdateInPlace, MatchesTheMemberAndReportsTheFailingColumn) {
  const Eigen::MatrixXd start = lower_factor();
  const Eigen::VectorXd v = Eigen::Vector3d(0.2, 0.1, -0.3);
  CholeskyFactor<Dynamic> factor{start};
  factor.rank_one_update(v, -0.5);
  Eigen::MatrixXd lower = start;
  Eigen::VectorXd x = std::sqrt(0.5) * v;
  EXPECT_EQ(rank_one_update_in_place(lower, x, -1.0), -1);
  EXPECT_EQ(lower, factor.lower());

  Eigen::MatrixXd failing = start;
  Eigen::VectorXd large = Eigen::Vector3d(0.0, 10.0, 0.0);  // column 0 survives, column 1 not
  EXPECT_EQ(rank_one_update_in_place(failing, large, -1.0), 1);
}

}  // namespace
}  // namespace twincal
