#include "twincal/core/bounded_least_squares.hpp"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal::bounded_least_squares_test {
namespace {

double objective(const MatrixX& b, const VectorX& y0, const VectorX& u) {
  return (y0 + b * u).squaredNorm();
}

// Brute force over the 3^d faces of the box: every variable free, at its lower or at its upper
// bound; the free ones solved by least squares, kept when inside the box. The best kept point is
// the minimum (the minimizer lies in the relative interior of some face).
VectorX brute_force(const MatrixX& b, const VectorX& y0, const VectorX& lower,
                    const VectorX& upper) {
  const Index d = b.cols();
  Index faces = 1;
  for (Index k = 0; k < d; ++k) faces *= 3;
  VectorX best = VectorX::Zero(d);
  double best_value = std::numeric_limits<double>::infinity();
  for (Index face = 0; face < faces; ++face) {
    VectorX u = VectorX::Zero(d);
    std::vector<Index> free;
    Index code = face;
    for (Index k = 0; k < d; ++k, code /= 3) {
      if (code % 3 == 0) free.push_back(k);
      u(k) = code % 3 == 1 ? lower(k) : code % 3 == 2 ? upper(k) : 0.0;
    }
    if (!free.empty()) {
      MatrixX columns(b.rows(), static_cast<Index>(free.size()));
      for (std::size_t c = 0; c < free.size(); ++c) {
        columns.col(static_cast<Index>(c)) = b.col(free[c]);
      }
      const VectorX rhs = -(y0 + b * u);
      const VectorX step = columns.completeOrthogonalDecomposition().solve(rhs);
      for (std::size_t c = 0; c < free.size(); ++c) u(free[c]) = step(static_cast<Index>(c));
    }
    if (((u - lower).array() < -1e-12).any() || ((upper - u).array() < -1e-12).any()) continue;
    const double value = objective(b, y0, u);
    if (value < best_value) {
      best_value = value;
      best = u;
    }
  }
  return best;
}

TEST(BoundedLeastSquares, MatchesBruteForceOnRandomProblems) {
  std::mt19937_64 engine(2026);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 200; ++trial) {
    const Index d = 1 + trial % 5;
    const Index m = d + trial % 4;
    MatrixX b(m, d);
    VectorX y0(m);
    for (Index i = 0; i < m; ++i) {
      y0(i) = 3.0 * normal(engine);
      for (Index k = 0; k < d; ++k) b(i, k) = normal(engine);
    }
    const VectorX lower = -VectorX::Constant(d, 0.5 + trial % 3 * 0.25);
    const VectorX upper = VectorX::Constant(d, 1.0);
    const BoundedLeastSquaresSummary summary = bounded_least_squares(b, y0, lower, upper);
    const VectorX expected = brute_force(b, y0, lower, upper);
    EXPECT_NEAR(objective(b, y0, summary.solution), objective(b, y0, expected),
                1e-9 * (1.0 + objective(b, y0, expected)))
        << "trial " << trial;
    EXPECT_TRUE(((summary.solution - lower).array() >= -1e-12).all());
    EXPECT_TRUE(((upper - summary.solution).array() >= -1e-12).all());
    EXPECT_GE(summary.passes, 1);
  }
}

TEST(BoundedLeastSquares, InteriorOptimumIsTheUnconstrainedOne) {
  const Eigen::Matrix2d b{{2.0, 0.0}, {0.0, 1.0}};
  const Eigen::Vector2d y0(-1.0, 0.5);
  const BoundedLeastSquaresSummary summary =
      bounded_least_squares(b, y0, Eigen::Vector2d::Constant(-1.0), Eigen::Vector2d::Ones());
  EXPECT_NEAR(summary.solution(0), 0.5, 1e-14);
  EXPECT_NEAR(summary.solution(1), -0.5, 1e-14);
  EXPECT_EQ(summary.passes, 1);
}

TEST(BoundedLeastSquares, RankDeficientColumnsGiveTheMinimumNorm) {
  // Two equal columns: any u0 + u1 = 1 is optimal; the minimum-norm one splits it.
  const MatrixX b = MatrixX::Ones(3, 2);
  const VectorX y0 = -VectorX::Ones(3);
  const BoundedLeastSquaresSummary summary =
      bounded_least_squares(b, y0, VectorX::Constant(2, -2.0), VectorX::Constant(2, 2.0));
  EXPECT_NEAR(summary.solution(0), 0.5, 1e-12);
  EXPECT_NEAR(summary.solution(1), 0.5, 1e-12);
}

TEST(BoundedLeastSquares, RefusesBadArgumentsNamingThem) {
  const MatrixX b = MatrixX::Identity(2, 2);
  const VectorX ones = VectorX::Ones(2);
  EXPECT_THROW((void)bounded_least_squares(b, VectorX::Ones(3), -ones, ones),
               DimensionMismatchError);
  EXPECT_THROW((void)bounded_least_squares(b, ones, -VectorX::Ones(1), ones),
               DimensionMismatchError);
  VectorX nan = ones;
  nan(1) = std::nan("");
  EXPECT_THROW((void)bounded_least_squares(b, nan, -ones, ones), NonFiniteError);
  try {
    (void)bounded_least_squares(b, ones, VectorX::Constant(2, 0.5), ones);
    FAIL() << "a box without 0 was accepted";
  } catch (const InvalidArgumentError& error) {
    EXPECT_NE(std::string(error.what()).find("entry 0 is [0.5, 1]"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace twincal::bounded_least_squares_test
