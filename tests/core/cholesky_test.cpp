#include "twincal/core/cholesky.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace twincal {
namespace {

using ::testing::HasSubstr;

Eigen::Matrix3d spd_matrix() {
  Eigen::Matrix3d a;
  a << 4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0;
  return a;
}

// Rank-deficient (eigenvalues 0, 0, 3) plus a small negative perturbation: not PD.
Eigen::Matrix3d indefinite_matrix() {
  const Eigen::Vector3d ones = Eigen::Vector3d::Ones();
  Eigen::Matrix3d m = ones * ones.transpose();
  m.diagonal().array() -= 1e-9;
  return m;
}

TEST(Cholesky, FactorsSpdMatrixWithoutRepair) {
  const CholeskyResult<3> result = cholesky(spd_matrix());
  EXPECT_FALSE(result.report.repaired());
  EXPECT_TRUE(result.factor.covariance().isApprox(spd_matrix(), 1e-14));
  EXPECT_TRUE(std::isnan(result.report.smallest_eigenvalue));
}

TEST(Cholesky, WorksForDynamicSize) {
  const Eigen::MatrixXd m = spd_matrix();
  const CholeskyResult<Dynamic> result = cholesky(m);
  EXPECT_EQ(result.factor.dimension(), 3);
  EXPECT_TRUE(result.factor.covariance().isApprox(m, 1e-14));
}

TEST(Cholesky, ReadsOnlyTheLowerTriangle) {
  Eigen::Matrix3d m = spd_matrix();
  m(0, 2) = 1e3;  // garbage above the diagonal is ignored, as in Eigen's LLT
  EXPECT_TRUE(cholesky(m).factor.covariance().isApprox(spd_matrix(), 1e-14));
}

TEST(Cholesky, PolicyNoneThrowsWithSmallestEigenvalue) {
  try {
    (void)cholesky(indefinite_matrix(), {}, "P_prior");
    FAIL() << "expected NotPositiveDefiniteError";
  } catch (const NotPositiveDefiniteError& e) {
    EXPECT_EQ(e.argument(), "P_prior");
    EXPECT_NEAR(e.smallest_eigenvalue(), -1e-9, 1e-12);
    EXPECT_THAT(e.what(), HasSubstr("P_prior: Cholesky factorization failed (repair policy: "
                                    "none): smallest eigenvalue is -1e-09"));
    EXPECT_THAT(e.what(), HasSubstr("rule: must be positive definite"));
  }
}

TEST(Cholesky, JitterRepairsAndReportsTheShift) {
  const CholeskyOptions options{.repair = CovarianceRepair::jitter};
  const CholeskyResult<3> result = cholesky(indefinite_matrix(), options);
  EXPECT_EQ(result.report.applied, CovarianceRepair::jitter);
  EXPECT_GT(result.report.jitter, 1e-9);  // it had to lift the -1e-9 eigenvalue
  EXPECT_LT(result.report.jitter, 1e-6);  // and stopped at the first ε that did
  const Eigen::Matrix3d expected =
      indefinite_matrix() + result.report.jitter * Eigen::Matrix3d::Identity();
  EXPECT_TRUE(result.factor.covariance().isApprox(expected, 1e-12));
}

TEST(Cholesky, JitterGivesUpAfterTheConfiguredAttempts) {
  const CholeskyOptions options{
      .repair = CovarianceRepair::jitter, .jitter_initial = 1e-16, .jitter_attempts = 2};
  Eigen::Matrix2d m = -Eigen::Matrix2d::Identity();
  try {
    (void)cholesky(m, options, "P");
    FAIL() << "expected NotPositiveDefiniteError";
  } catch (const NotPositiveDefiniteError& e) {
    EXPECT_THAT(e.what(), HasSubstr("P: Cholesky factorization failed after 2 jitter attempts "
                                    "up to 1e-15: smallest eigenvalue is -1"));
  }
}

TEST(Cholesky, NearestPdClipsNegativeEigenvalues) {
  const CholeskyOptions options{.repair = CovarianceRepair::nearest_pd};
  const CholeskyResult<3> result = cholesky(indefinite_matrix(), options);
  EXPECT_EQ(result.report.applied, CovarianceRepair::nearest_pd);
  EXPECT_EQ(result.report.clipped_eigenvalues, 2);
  EXPECT_NEAR(result.report.smallest_eigenvalue, -1e-9, 1e-12);
  // The nearest PSD matrix of ones·onesᵀ − 1e-9 I keeps the eigenvalue 3 − 1e-9 along ones.
  const Eigen::Vector3d ones = Eigen::Vector3d::Ones();
  const Eigen::Matrix3d expected = (3.0 - 1e-9) / 3.0 * ones * ones.transpose();
  EXPECT_TRUE(result.factor.covariance().isApprox(expected, 1e-9));
}

TEST(Cholesky, NearestPdRefusesANegativeDefiniteMatrix) {
  const CholeskyOptions options{.repair = CovarianceRepair::nearest_pd};
  EXPECT_THAT([&] { (void)cholesky(Eigen::Matrix2d(-Eigen::Matrix2d::Identity()), options, "P"); },
              ::testing::ThrowsMessage<NotPositiveDefiniteError>(
                  HasSubstr("(nearest_pd needs a positive largest eigenvalue)")));
}

TEST(Cholesky, RejectsNonFiniteAndNonSquareInputWhateverThePolicy) {
  Eigen::Matrix2d m = Eigen::Matrix2d::Identity();
  m(1, 1) = std::numeric_limits<double>::quiet_NaN();
  const CholeskyOptions repair{.repair = CovarianceRepair::nearest_pd};
  EXPECT_THAT([&] { (void)cholesky(m, repair, "P"); },
              ::testing::ThrowsMessage<NonFiniteError>(
                  "P: entry (1, 1) is nan; rule: every entry must be finite"));
  EXPECT_THAT([&] { (void)cholesky(Eigen::MatrixXd::Identity(2, 3), repair, "P"); },
              ::testing::ThrowsMessage<DimensionMismatchError>("P: is 2x3; rule: must be square"));
}

// cholesky_into, the filters' in-place form, at a fixed and at a run-time size.
template <typename Square>
class CholeskyInto : public ::testing::Test {};
using SquareTypes = ::testing::Types<Eigen::Matrix3d, Eigen::MatrixXd>;
TYPED_TEST_SUITE(CholeskyInto, SquareTypes);

TYPED_TEST(CholeskyInto, FactorsLikeCholeskyAndLeavesTheMatrix) {
  TypeParam m = spd_matrix();
  TypeParam lower = TypeParam::Constant(3, 3, 7.0);  // stale content must not leak into L
  const CholeskyReport report = cholesky_into(m, lower);
  EXPECT_FALSE(report.repaired());
  EXPECT_EQ(TypeParam(m), TypeParam(spd_matrix()));
  EXPECT_TRUE(lower.isApprox(cholesky(spd_matrix()).factor.lower(), 1e-15));
  EXPECT_TRUE(lower.template triangularView<Eigen::StrictlyUpper>().toDenseMatrix().isZero(0.0));
}

TYPED_TEST(CholeskyInto, ChecksEveryLowerEntryForFinitenessAndIgnoresTheUpperTriangle) {
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity()}) {
    for (Index c = 0; c < 3; ++c) {
      for (Index r = c; r < 3; ++r) {
        TypeParam m = spd_matrix();
        m(r, c) = bad;
        TypeParam before = m;
        TypeParam lower(3, 3);
        EXPECT_THAT([&] { (void)cholesky_into(m, lower, {}, "P"); },
                    ::testing::ThrowsMessage<NonFiniteError>(fmt::format(
                        "P: entry ({}, {}) is {}; rule: every entry must be finite", r, c, bad)))
            << "entry (" << r << ", " << c << ") = " << bad;
        EXPECT_EQ(std::isnan(m(r, c)), std::isnan(bad));  // unchanged (NaN != NaN, so
        m(r, c) = before(r, c) = 0.0;                     // compare the rest exactly)
        EXPECT_EQ(TypeParam(m), before);
      }
    }
  }
  TypeParam m = spd_matrix();
  m(0, 2) = std::numeric_limits<double>::quiet_NaN();  // above the diagonal: not read
  TypeParam lower(3, 3);
  (void)cholesky_into(m, lower);
  EXPECT_TRUE(lower.isApprox(cholesky(spd_matrix()).factor.lower(), 1e-15));
}

TYPED_TEST(CholeskyInto, RepairsReplaceTheMatrixAndFailuresLeaveIt) {
  TypeParam m = indefinite_matrix();
  TypeParam lower(3, 3);
  EXPECT_THAT([&] { (void)cholesky_into(m, lower, {}, "P"); },
              ::testing::ThrowsMessage<NotPositiveDefiniteError>(
                  HasSubstr("P: Cholesky factorization failed (repair policy: none)")));
  EXPECT_EQ(TypeParam(m), TypeParam(indefinite_matrix()));

  const CholeskyReport report = cholesky_into(m, lower, {.repair = CovarianceRepair::jitter}, "P");
  EXPECT_EQ(report.applied, CovarianceRepair::jitter);
  const TypeParam expected = indefinite_matrix() + report.jitter * Eigen::Matrix3d::Identity();
  EXPECT_TRUE(m.isApprox(expected, 1e-12));
  EXPECT_TRUE((lower * lower.transpose()).isApprox(m, 1e-12));
}

// A well-conditioned SPD matrix of size n with distinct entries: B Bᵀ + n·I.
Eigen::MatrixXd spd_matrix_of_size(Index n) {
  Eigen::MatrixXd b(n, n);
  for (Index c = 0; c < n; ++c) {
    for (Index r = 0; r < n; ++r)
      b(r, c) = std::sin(1.0 + 0.7 * static_cast<double>(r) + 1.3 * static_cast<double>(c));
  }
  Eigen::MatrixXd m = b * b.transpose();
  m.diagonal().array() += static_cast<double>(n);
  return m;
}

// The compile-time-sized kernel agrees with Eigen's LLT and names the first bad pivot.
template <int K>
void check_unrolled_llt() {
  const SquareMatrix<K> m = spd_matrix_of_size(K);
  SquareMatrix<K> a = m;
  ASSERT_EQ(detail::llt_in_place_unrolled<K>(a), -1) << "K = " << K;
  const SquareMatrix<K> lower = a.template triangularView<Eigen::Lower>();
  const SquareMatrix<K> eigen = Eigen::LLT<SquareMatrix<K>>(m).matrixL();
  EXPECT_TRUE(lower.isApprox(eigen, 1e-14)) << "K = " << K;
  for (int bad = 0; bad < K; ++bad) {
    SquareMatrix<K> d = SquareMatrix<K>::Identity();
    d(bad, bad) = -1.0;
    EXPECT_EQ(detail::llt_in_place_unrolled<K>(d), bad) << "K = " << K;
  }
}

TEST(LltInPlaceUnrolled, AgreesWithEigenAndReportsTheFailedPivotAtEverySize) {
  [&]<int... K>(std::integer_sequence<int, K...>) { (check_unrolled_llt<K + 1>(), ...); }
  (std::make_integer_sequence<int, max_fixed_dispatch_size>{});
}

TEST(FixedSizeFactorLower, FactorsWithinTheBoundAndLeavesLargerMatricesAlone) {
  for (Index n = 1; n <= max_fixed_dispatch_size + 2; ++n) {
    const Eigen::MatrixXd m = spd_matrix_of_size(n);
    Eigen::MatrixXd lower = Eigen::MatrixXd::Constant(n, n, 7.0);
    const std::optional<bool> factored = detail::fixed_size_factor_lower(m, lower);
    if (n > max_fixed_dispatch_size) {
      EXPECT_FALSE(factored.has_value()) << "n = " << n;
      EXPECT_TRUE((lower.array() == 7.0).all()) << "n = " << n;
      continue;
    }
    ASSERT_EQ(factored, true) << "n = " << n;
    EXPECT_TRUE(lower.isApprox(Eigen::MatrixXd(Eigen::LLT<Eigen::MatrixXd>(m).matrixL()), 1e-14))
        << "n = " << n;
    Eigen::MatrixXd indefinite = m;
    indefinite(n - 1, n - 1) = -1.0;
    EXPECT_EQ(detail::fixed_size_factor_lower(indefinite, lower), false) << "n = " << n;
  }
}

TEST(CholeskyInto, RunTimeSizesOnEitherSideOfTheFixedSizeBoundFactorAlike) {
  for (const Index n : {Index{max_fixed_dispatch_size}, Index{max_fixed_dispatch_size + 1}}) {
    Eigen::MatrixXd m = spd_matrix_of_size(n);
    Eigen::MatrixXd lower(n, n);
    EXPECT_FALSE(cholesky_into(m, lower).repaired());
    EXPECT_TRUE((lower * lower.transpose()).isApprox(m, 1e-14)) << "n = " << n;
    EXPECT_TRUE(lower.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().isZero(0.0));
  }
}

TEST(CholeskyOptions, ValidateNamesTheField) {
  EXPECT_EQ(CholeskyOptions{}.validate(), std::nullopt);
  EXPECT_EQ(CholeskyOptions{.jitter_initial = 0.0}.validate(),
            "jitter_initial: value is 0; rule: must be finite and > 0");
  EXPECT_EQ(CholeskyOptions{.jitter_growth = 1.0}.validate(),
            "jitter_growth: value is 1; rule: must be finite and > 1");
  EXPECT_EQ(CholeskyOptions{.jitter_attempts = 0}.validate(),
            "jitter_attempts: value is 0; rule: must be >= 1");
  EXPECT_EQ(CholeskyOptions{.eigenvalue_floor = 1.0}.validate(),
            "eigenvalue_floor: value is 1; rule: must lie in (0, 1)");
  EXPECT_THAT([] { (void)cholesky(Eigen::Matrix2d::Identity(), {.jitter_attempts = 0}); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "CholeskyOptions: jitter_attempts: value is 0; rule: must be >= 1"));
}

TEST(CovarianceRepair, HasReadableNames) {
  EXPECT_EQ(to_string(CovarianceRepair::none), "none");
  EXPECT_EQ(to_string(CovarianceRepair::jitter), "jitter");
  EXPECT_EQ(to_string(CovarianceRepair::nearest_pd), "nearest_pd");
}

}  // namespace
}  // namespace twincal
