#include "twincal/samplers/gaussian_transform.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/samplers/normal_quantile.hpp"
#include "twincal/samplers/sobol.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

template <typename T>
class GaussianTransformTest : public ::testing::Test {
 public:
  static constexpr int N = T::value;
  using TransformType = GaussianTransform<N>;

  static Vector<N> mean() {
    Vector<N> m(3);
    m << 1.0, -2.0, 0.5;
    return m;
  }
  static SquareMatrix<N> covariance() {
    SquareMatrix<N> p(3, 3);
    p << 4.0, 1.0, 0.5,  //
        1.0, 2.0, 0.3,   //
        0.5, 0.3, 1.0;
    return p;
  }
  // Rank 1: every sample lies on the line mean + t·(1, 2, −1).
  static SquareMatrix<N> rank_one() {
    Vector<N> v(3);
    v << 1.0, 2.0, -1.0;
    return v * v.transpose();
  }
};

using Sizes =
    ::testing::Types<std::integral_constant<int, 3>, std::integral_constant<int, Dynamic>>;
TYPED_TEST_SUITE(GaussianTransformTest, Sizes);

MatrixX sobol_points(Index d, Index n) {
  Sobol sobol(d, {.randomization = SobolRandomization::linear_matrix_scramble,
                  .seed = 2,
                  .balance = BalanceCheck::refuse});
  MatrixX u(d, n);
  sobol.fill(u);
  return u;
}

TYPED_TEST(GaussianTransformTest, FactorReproducesTheCovariance) {
  using Transform = typename TestFixture::TransformType;
  for (const auto f : {GaussianFactorization::cholesky, GaussianFactorization::eigen}) {
    const Transform t(TestFixture::mean(), TestFixture::covariance(), {.factorization = f});
    EXPECT_EQ(t.factorization(), f);
    EXPECT_LT((t.factor() * t.factor().transpose() - TestFixture::covariance()).norm(), 1e-13);
    if (f == GaussianFactorization::cholesky) {
      EXPECT_EQ(t.factor()(0, 1), 0.0);
      EXPECT_EQ(t.factor()(0, 2), 0.0);
      EXPECT_EQ(t.factor()(1, 2), 0.0);
    } else {  // principal components first: column norms are √λ, decreasing
      EXPECT_GT(t.factor().col(0).norm(), t.factor().col(1).norm());
      EXPECT_GT(t.factor().col(1).norm(), t.factor().col(2).norm());
    }
  }
}

TYPED_TEST(GaussianTransformTest, MapsEachColumnThroughTheClippedQuantile) {
  using Transform = typename TestFixture::TransformType;
  const Transform t(TestFixture::mean(), TestFixture::covariance(), {.clip = 1e-8});
  MatrixX u(3, 3);
  u << 0.0, 0.5, 1.0,  //
      0.25, 0.5, 0.9,  //
      0.7, 0.5, 1e-12;
  const auto x = t(u);
  for (Index c = 0; c < 3; ++c) {
    Vector<TestFixture::N> z(3);
    for (Index r = 0; r < 3; ++r) z(r) = normal_quantile(std::clamp(u(r, c), 1e-8, 1.0 - 1e-8));
    const Vector<TestFixture::N> expected = TestFixture::mean() + t.factor() * z;
    EXPECT_LT((x.col(c) - expected).norm(), 1e-13) << "column " << c;
  }
  EXPECT_TRUE(x.allFinite());  // the zero point and the coordinate at 1 stay finite
  EXPECT_LT((x.col(1) - TestFixture::mean()).norm(), 1e-15);  // the centre maps to the mean
}

TYPED_TEST(GaussianTransformTest, SobolSampleMomentsMatchTheTarget) {
  using Transform = typename TestFixture::TransformType;
  for (const auto f : {GaussianFactorization::cholesky, GaussianFactorization::eigen}) {
    const Transform t(TestFixture::mean(), TestFixture::covariance(), {.factorization = f});
    const MatrixX x = t(sobol_points(3, 1 << 14));
    const Eigen::Vector3d sample_mean = x.rowwise().mean();
    const MatrixX centred = x.colwise() - sample_mean;
    const Eigen::Matrix3d sample_cov =
        centred * centred.transpose() / static_cast<double>(x.cols());
    // Randomized QMC errors at n = 2^14 are far below Monte Carlo's 1/√n ≈ 0.008 (relative).
    EXPECT_LT((sample_mean - TestFixture::mean()).cwiseAbs().maxCoeff(), 1e-3);
    EXPECT_LT((sample_cov - TestFixture::covariance()).cwiseAbs().maxCoeff(), 5e-3);
  }
}

TYPED_TEST(GaussianTransformTest, InPlaceEqualsOutOfPlace) {
  using Transform = typename TestFixture::TransformType;
  const Transform t(TestFixture::mean(), TestFixture::covariance());
  const MatrixX u = sobol_points(3, 64);
  Matrix<TestFixture::N, Dynamic> in_place = u;
  t.transform(in_place, in_place);
  EXPECT_LT((in_place - t(u)).cwiseAbs().maxCoeff(), 1e-14);
}

TYPED_TEST(GaussianTransformTest, SemiDefiniteCovarianceFallsBackToEigen) {
  using Transform = typename TestFixture::TransformType;
  const Transform t(TestFixture::mean(), TestFixture::rank_one());
  EXPECT_EQ(t.factorization(), GaussianFactorization::eigen);
  EXPECT_LT((t.factor() * t.factor().transpose() - TestFixture::rank_one()).norm(), 1e-13);
  const MatrixX x = t(sobol_points(3, 256));
  Eigen::Vector3d direction(1.0, 2.0, -1.0);
  direction.normalize();
  for (Index c = 0; c < x.cols(); ++c) {
    const Eigen::Vector3d offset = x.col(c) - TestFixture::mean();
    EXPECT_LT((offset - offset.dot(direction) * direction).norm(), 1e-12) << c;
  }
}

TYPED_TEST(GaussianTransformTest, RejectsBadArgumentsWithTheirValues) {
  using Transform = typename TestFixture::TransformType;
  SquareMatrix<TestFixture::N> indefinite = TestFixture::covariance();
  indefinite(2, 2) = -1.0;
  try {
    const Transform t(TestFixture::mean(), indefinite);
    FAIL();
  } catch (const NotPositiveDefiniteError& e) {
    EXPECT_EQ(e.argument(), "covariance");
    EXPECT_THAT(e.what(), HasSubstr("rule: must be positive semi-definite"));
  }
  SquareMatrix<TestFixture::N> asymmetric = TestFixture::covariance();
  asymmetric(0, 1) = 3.0;
  EXPECT_THROW(Transform(TestFixture::mean(), asymmetric), InvalidArgumentError);
  Vector<TestFixture::N> bad_mean = TestFixture::mean();
  bad_mean(1) = std::numeric_limits<double>::infinity();
  try {
    const Transform t(bad_mean, TestFixture::covariance());
    FAIL();
  } catch (const NonFiniteError& e) {
    EXPECT_EQ(std::string(e.what()), "mean: entry 1 is inf; rule: every entry must be finite");
  }
  try {
    const Transform t(TestFixture::mean(), TestFixture::covariance(), {.clip = 0.5});
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()), "options: clip: value is 0.5; rule: must lie in (0, 0.5)");
  }

  const Transform t(TestFixture::mean(), TestFixture::covariance());
  MatrixX u = MatrixX::Constant(3, 2, 0.5);
  u(2, 1) = -0.25;
  Matrix<TestFixture::N, Dynamic> out = Matrix<TestFixture::N, Dynamic>::Zero(3, 2);
  try {
    t.transform(u, out);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()), "uniform: entry (2, 1) is -0.25; rule: must lie in [0, 1]");
  }
  EXPECT_TRUE(out.isZero());  // untouched
  Matrix<TestFixture::N, Dynamic> narrow(3, 1);
  EXPECT_THROW(t.transform(MatrixX::Constant(3, 2, 0.5), narrow), DimensionMismatchError);
}

TEST(GaussianTransform, RejectsAMismatchedDynamicCovariance) {
  try {
    const GaussianTransform<Dynamic> t(VectorX::Zero(3), MatrixX::Identity(2, 2));
    FAIL();
  } catch (const DimensionMismatchError& e) {
    EXPECT_EQ(std::string(e.what()), "covariance: rows is 2; rule: must equal 3");
  }
}

}  // namespace
}  // namespace twincal
