#include "twincal/filters/sigma_points.hpp"

#include <gtest/gtest.h>

namespace twincal {
namespace {

// The symmetric 2n-point set x ± sqrt(n)·col_k(L) with equal weights reproduces N(x, L Lᵀ).
template <int N>
SigmaPoints<N, size_product(2, N)> cubature_set(const Vector<N>& mean,
                                                const SquareMatrix<N>& lower) {
  const Index n = mean.size();
  SigmaPoints<N, size_product(2, N)> set;
  set.points.resize(n, 2 * n);
  set.mean_weights.setConstant(2 * n, 1.0 / static_cast<double>(2 * n));
  set.covariance_weights = set.mean_weights;
  const double scale = std::sqrt(static_cast<double>(n));
  for (Index k = 0; k < n; ++k) {
    set.points.col(k) = mean + scale * lower.col(k);
    set.points.col(n + k) = mean - scale * lower.col(k);
  }
  return set;
}

template <typename Sizes>
class SigmaPointsTest : public ::testing::Test {};
using Dimensions = ::testing::Types<std::integral_constant<int, 3>,
                                    std::integral_constant<int, Dynamic>>;
TYPED_TEST_SUITE(SigmaPointsTest, Dimensions);

TYPED_TEST(SigmaPointsTest, WeightedMomentsReproduceTheGaussian) {
  constexpr int N = TypeParam::value;
  Vector<N> mean(3);
  mean << 0.5, -1.0, 2.0;
  SquareMatrix<N> lower(3, 3);
  lower << 1.0, 0.0, 0.0, 0.2, 0.5, 0.0, -0.1, 0.3, 0.7;
  const SigmaPoints<N, size_product(2, N)> set = cubature_set<N>(mean, lower);
  EXPECT_EQ(set.dimension(), 3);
  EXPECT_EQ(set.size(), 6);
  EXPECT_TRUE(set.mean().isApprox(mean, 1e-14));
  const SquareMatrix<N> expected = lower * lower.transpose();
  EXPECT_TRUE(set.covariance(set.mean()).isApprox(expected, 1e-14));
}

TEST(SigmaPoints, CovarianceCentreMustMatchTheDimension) {
  SigmaPoints<Dynamic, Dynamic> set{Eigen::MatrixXd::Zero(2, 4), Eigen::VectorXd::Constant(4, 0.25),
                                    Eigen::VectorXd::Constant(4, 0.25)};
  EXPECT_THROW((void)set.covariance(Eigen::VectorXd::Zero(3)), DimensionMismatchError);
}

}  // namespace
}  // namespace twincal
