#include "twincal/core/validate.hpp"

#include <cmath>
#include <cstdlib>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/QR>

namespace twincal {
namespace {

using ::testing::HasSubstr;

constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr double inf = std::numeric_limits<double>::infinity();

// Runs `f`, expects an exception of type E, and returns its message for assertions.
template <typename E, typename F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "no exception of the expected type";
  return {};
}

TEST(RequireFinite, AcceptsFiniteScalarsAndMatrices) {
  EXPECT_NO_THROW(require_finite("x", 1.5));
  EXPECT_NO_THROW(require_finite("v", Eigen::Vector3d(1, 2, 3)));
  EXPECT_NO_THROW(require_finite("m", Eigen::Matrix2d::Identity()));
}

TEST(AllFinite, FindsEveryNonFiniteEntryAndAcceptsExtremeFiniteOnes) {
  constexpr double largest = std::numeric_limits<double>::max();
  constexpr double smallest = std::numeric_limits<double>::denorm_min();
  Eigen::Matrix<double, 3, 7> fixed = Eigen::Matrix<double, 3, 7>::Constant(-largest);
  fixed(1, 3) = smallest;
  Eigen::MatrixXd dynamic = Eigen::MatrixXd::Constant(5, 13, largest);  // sums overflow to inf
  EXPECT_TRUE(all_finite(fixed));
  EXPECT_TRUE(all_finite(dynamic));
  EXPECT_TRUE(all_finite(Eigen::MatrixXd(0, 3)));
  for (const double bad : {nan, inf, -inf}) {
    for (Index i = 0; i < fixed.size(); ++i) {
      Eigen::Matrix<double, 3, 7> m = fixed;
      m(i) = bad;
      EXPECT_FALSE(all_finite(m)) << "entry " << i << " = " << bad;
    }
    for (Index i = 0; i < dynamic.size(); ++i) {
      Eigen::MatrixXd m = dynamic;
      m(i) = bad;
      EXPECT_FALSE(all_finite(m)) << "entry " << i << " = " << bad;
    }
  }
}

TEST(RequireFinite, ScalarMessageNamesArgumentValueAndRule) {
  const std::string message = message_of<NonFiniteError>([] { require_finite("sigma_z", nan); });
  EXPECT_EQ(message, "sigma_z: value is nan; rule: must be finite");
}

TEST(RequireFinite, VectorMessageNamesEntry) {
  const Eigen::Vector3d v(1.0, inf, 3.0);
  EXPECT_EQ(message_of<NonFiniteError>([&] { require_finite("u", v); }),
            "u: entry 1 is inf; rule: every entry must be finite");
}

TEST(RequireFinite, MatrixMessageNamesRowAndColumn) {
  Eigen::Matrix2d m = Eigen::Matrix2d::Identity();
  m(1, 0) = -inf;
  try {
    require_finite("P", m);
    FAIL() << "expected NonFiniteError";
  } catch (const NonFiniteError& e) {
    EXPECT_EQ(std::string(e.what()), "P: entry (1, 0) is -inf; rule: every entry must be finite");
    EXPECT_EQ(e.argument(), "P");
  }
}

TEST(RequireDimension, ReportsActualAndExpected) {
  EXPECT_NO_THROW(require_dimension("u", 3, 3));
  try {
    require_dimension("u", 2, 3);
    FAIL() << "expected DimensionMismatchError";
  } catch (const DimensionMismatchError& e) {
    EXPECT_EQ(std::string(e.what()), "u: size is 2; rule: must equal 3");
    EXPECT_EQ(e.actual(), 2);
    EXPECT_EQ(e.expected(), 3);
  }
  EXPECT_EQ(message_of<DimensionMismatchError>([] { require_dimension("H", 4, 3, "rows"); }),
            "H: rows is 4; rule: must equal 3");
}

TEST(RequireSquareAndShape, NameTheShape) {
  EXPECT_NO_THROW(require_square("P", Eigen::Matrix3d::Zero()));
  EXPECT_EQ(
      message_of<DimensionMismatchError>([] { require_square("P", Eigen::MatrixXd::Zero(2, 3)); }),
      "P: is 2x3; rule: must be square");
  EXPECT_NO_THROW(require_shape("K", Eigen::MatrixXd::Zero(3, 1), 3, 1));
  EXPECT_EQ(message_of<DimensionMismatchError>(
                [] { require_shape("K", Eigen::MatrixXd::Zero(2, 1), 3, 1); }),
            "K: is 2x1; rule: must be 3x1");
}

TEST(RequireRanges, PositiveNonNegativeAndInterval) {
  EXPECT_NO_THROW(require_positive("alpha", 1e-3));
  EXPECT_EQ(message_of<InvalidArgumentError>([] { require_positive("alpha", 0.0); }),
            "alpha: value is 0; rule: must be > 0");
  EXPECT_EQ(message_of<InvalidArgumentError>([] { require_positive("alpha", nan); }),
            "alpha: value is nan; rule: must be > 0");
  EXPECT_NO_THROW(require_non_negative("kappa", 0.0));
  EXPECT_EQ(message_of<InvalidArgumentError>([] { require_non_negative("kappa", -1.0); }),
            "kappa: value is -1; rule: must be >= 0");
  EXPECT_NO_THROW(require_in_range("w", 1.0, 0.0, 1.0));
  EXPECT_EQ(message_of<InvalidArgumentError>([] { require_in_range("w", 1.5, 0.0, 1.0); }),
            "w: value is 1.5; rule: must lie in [0, 1]");
}

TEST(RequireSymmetric, ToleranceIsRelative) {
  Eigen::Matrix2d m;
  m << 1e6, 2.0, 2.0 + 1e-7, 1e6;  // asymmetry 1e-13 relative: fine
  EXPECT_NO_THROW(require_symmetric("P", m));
  m(1, 0) = 3.0;
  EXPECT_THAT(message_of<InvalidArgumentError>([&] { require_symmetric("P", m); }),
              HasSubstr("P: relative asymmetry max|m - mᵀ|/max|m| is 1e-06; rule: must be "
                        "symmetric to 1e-12"));
  EXPECT_DOUBLE_EQ(relative_asymmetry(Eigen::Matrix2d::Zero()), 0.0);
}

// A symmetric n × n matrix with eigenvalues 1, 2, …, n, plus a skew part that eigenvalue_range
// must ignore: its range is exactly [1, n] up to round-off.
MatrixX known_spectrum(Index n) {
  const MatrixX rotation = Eigen::HouseholderQR<MatrixX>(MatrixX::Random(n, n)).householderQ();
  const VectorX spectrum = VectorX::LinSpaced(n, 1.0, static_cast<double>(n));
  const MatrixX skew = MatrixX::Random(n, n);
  return rotation * spectrum.asDiagonal() * rotation.transpose() + (skew - skew.transpose());
}

// The compiled sizes (validate.cpp: run-time, 1, 2, 3, 6) and the inline ones give the same
// range, at compile-time and at run-time size.
template <int N>
void expect_range_of_known_spectrum() {
  const MatrixX m = known_spectrum(N);
  const SquareMatrix<N> fixed = m;
  const auto [fixed_min, fixed_max] = eigenvalue_range(fixed);
  const auto [dynamic_min, dynamic_max] = eigenvalue_range(m);
  const double tolerance = 1e-12 * N;
  EXPECT_NEAR(fixed_min, 1.0, tolerance) << "N = " << N;
  EXPECT_NEAR(fixed_max, static_cast<double>(N), tolerance) << "N = " << N;
  EXPECT_NEAR(dynamic_min, fixed_min, tolerance) << "N = " << N;
  EXPECT_NEAR(dynamic_max, fixed_max, tolerance) << "N = " << N;
}

TEST(EigenvalueRange, IsTheSymmetricPartsRangeAtEverySize) {
  std::srand(2023);
  expect_range_of_known_spectrum<1>();
  expect_range_of_known_spectrum<2>();
  expect_range_of_known_spectrum<3>();
  expect_range_of_known_spectrum<4>();
  expect_range_of_known_spectrum<6>();
  expect_range_of_known_spectrum<9>();
  EXPECT_DOUBLE_EQ(
      smallest_eigenvalue(Eigen::Matrix3d(Eigen::Vector3d(4.0, 2.0, 3.0).asDiagonal())), 2.0);
}

TEST(RequirePositiveDefinite, AcceptsSpdAndReportsSmallestEigenvalue) {
  EXPECT_NO_THROW(require_positive_definite("P", Eigen::Matrix2d::Identity()));
  Eigen::Matrix2d indefinite;
  indefinite << 1.0, 2.0, 2.0, 1.0;  // eigenvalues 3 and -1
  try {
    require_positive_definite("P", indefinite);
    FAIL() << "expected NotPositiveDefiniteError";
  } catch (const NotPositiveDefiniteError& e) {
    EXPECT_EQ(std::string(e.what()),
              "P: smallest eigenvalue is -1; rule: must be positive definite (all eigenvalues > "
              "0)");
    EXPECT_NEAR(e.smallest_eigenvalue(), -1.0, 1e-12);
  }
}

TEST(RequirePositiveDefinite, SemidefiniteIsAllowedOnRequest) {
  const Eigen::Matrix2d singular = Eigen::Vector2d(1.0, 1.0) * Eigen::RowVector2d(1.0, 1.0);
  EXPECT_NO_THROW(require_positive_definite("P", singular, /*allow_semidefinite=*/true));
  EXPECT_THAT(message_of<NotPositiveDefiniteError>(
                  [&] { require_positive_definite("P", Eigen::Matrix2d(-singular), true); }),
              HasSubstr("rule: must be positive semi-definite (all eigenvalues >= 0)"));
}

TEST(RequirePositiveDefinite, ChecksShapeFinitenessAndSymmetryFirst) {
  EXPECT_EQ(message_of<DimensionMismatchError>(
                [] { require_positive_definite("P", Eigen::MatrixXd::Identity(2, 3)); }),
            "P: is 2x3; rule: must be square");
  Eigen::Matrix2d m = Eigen::Matrix2d::Identity();
  m(0, 0) = nan;
  EXPECT_EQ(message_of<NonFiniteError>([&] { require_positive_definite("P", m); }),
            "P: entry (0, 0) is nan; rule: every entry must be finite");
  m << 1.0, 0.5, 0.0, 1.0;
  EXPECT_THAT(message_of<InvalidArgumentError>([&] { require_positive_definite("P", m); }),
              HasSubstr("P: relative asymmetry"));
}

TEST(RequireNormalParameters, ChecksTheMeanThenTheCovarianceOfItsSize) {
  const Eigen::Vector2d mean(1.0, -1.0);
  const Eigen::Matrix2d singular = Eigen::Vector2d(1.0, 1.0) * Eigen::RowVector2d(1.0, 1.0);
  EXPECT_NO_THROW(require_normal_parameters("mean", mean, singular));
  EXPECT_EQ(message_of<NonFiniteError>(
                [&] { require_normal_parameters("start", Eigen::Vector2d(nan, 0.0), singular); }),
            "start: entry 0 is nan; rule: every entry must be finite");
  EXPECT_THROW(require_normal_parameters("mean", mean, Eigen::Matrix3d::Identity()),
               DimensionMismatchError);
  EXPECT_THAT(message_of<NotPositiveDefiniteError>(
                  [&] { require_normal_parameters("mean", mean, Eigen::Matrix2d(-singular)); }),
              HasSubstr("covariance: smallest eigenvalue"));
  Eigen::Matrix2d asymmetric = Eigen::Matrix2d::Identity();
  asymmetric(0, 1) = 1e-11;
  EXPECT_THROW(require_normal_parameters("mean", mean, asymmetric), InvalidArgumentError);
  EXPECT_NO_THROW(require_normal_parameters("mean", mean, asymmetric, 1e-10));
}

TEST(ErrorHierarchy, AllDeriveFromTwincalErrorAndStdException) {
  EXPECT_THROW(require_dimension("u", 1, 2), InvalidArgumentError);
  EXPECT_THROW(require_dimension("u", 1, 2), Error);
  EXPECT_THROW(require_finite("x", nan), Error);
  EXPECT_THROW(require_finite("x", nan), std::exception);
  EXPECT_THROW(require_positive_definite("P", Eigen::Matrix2d(-Eigen::Matrix2d::Identity())),
               Error);
}

}  // namespace
}  // namespace twincal
