// Sigma-point schemes: the conformance suite for every scheme, filterpy parity of the points
// and weights (tests/data/sigma_points.json), parameter validation and the SigmaPoints moments.
#include "twincal/filters/sigma_points.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "golden.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/julier_sigma_points.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/simplex_sigma_points.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"
#include "twincal/filters/testing/sigma_point_scheme_conformance.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

// --- conformance ---------------------------------------------------------------------------
struct MerweWide {
  using Scheme = MerweScaledSigmaPoints;
  static constexpr int dimension = 3;
  static Scheme make() { return {1.0, 2.0, 0.0}; }
};
struct MerweNarrow {  // the paper's α = 0.1: large negative centre weights
  using Scheme = MerweScaledSigmaPoints;
  static constexpr int dimension = 2;
  static Scheme make() { return {0.1, 2.0, 0.0}; }
};
struct MerweNegativeKappa {
  using Scheme = MerweScaledSigmaPoints;
  static constexpr int dimension = 5;
  static Scheme make() { return {0.5, 2.0, -2.0}; }
};
struct JulierThreeMinusN {
  using Scheme = JulierSigmaPoints;
  static constexpr int dimension = 2;
  static Scheme make() { return JulierSigmaPoints{1.0}; }
};
struct JulierScalar {
  using Scheme = JulierSigmaPoints;
  static constexpr int dimension = 1;
  static Scheme make() { return JulierSigmaPoints{0.0}; }
};
struct Simplex3 {
  using Scheme = SimplexSigmaPoints;
  static constexpr int dimension = 3;
  static Scheme make() { return {}; }
};
struct Simplex1 {
  using Scheme = SimplexSigmaPoints;
  static constexpr int dimension = 1;
  static Scheme make() { return {}; }
};
struct Cubature4 {
  using Scheme = SphericalRadialSigmaPoints;
  static constexpr int dimension = 4;
  static Scheme make() { return {}; }
};
struct FifthDegree3 {
  using Scheme = FifthDegreeCubatureSigmaPoints;
  static constexpr int dimension = 3;
  static Scheme make() { return {}; }
};
struct FifthDegree6 {  // negative axis weights for n > 4
  using Scheme = FifthDegreeCubatureSigmaPoints;
  static constexpr int dimension = 6;
  static Scheme make() { return {}; }
};
using Schemes =
    ::testing::Types<MerweWide, MerweNarrow, MerweNegativeKappa, JulierThreeMinusN, JulierScalar,
                     Simplex3, Simplex1, Cubature4, FifthDegree3, FifthDegree6>;
}  // namespace
}  // namespace twincal

namespace twincal::conformance {
INSTANTIATE_TYPED_TEST_SUITE_P(Builtin, SigmaPointSchemeConformance, Schemes);
}  // namespace twincal::conformance

namespace twincal {
namespace {

// A scheme that claims more than it delivers must fail the suite's checks: the third-degree
// cubature rule does not integrate x⁴ (it gives n instead of 3).
TEST(SigmaPointSchemeConformance, DetectsAnOverclaimedDegree) {
  const conformance::RandomGaussian<Dynamic> g = conformance::RandomGaussian<Dynamic>::draw(2, 1);
  const auto set = draw_sigma_points(SphericalRadialSigmaPoints{}, g.mean, g.lower);
  MatrixX standardised = set.points.colwise() - g.mean;
  g.lower.triangularView<Eigen::Lower>().solveInPlace(standardised);
  const double fourth =
      set.mean_weights.dot(standardised.row(0).transpose().array().pow(4).matrix());
  EXPECT_NEAR(fourth, 2.0, 1e-12);
  EXPECT_GT(std::abs(fourth - conformance::standard_normal_moment(4)), 0.5);
}

// --- filterpy parity -----------------------------------------------------------------------
TEST(SigmaPointsGolden, MatchFilterpyPointsAndWeights) {
  const nlohmann::json data = test_support::load("sigma_points.json");
  double worst = 0.0;
  for (const nlohmann::json& c : data["cases"]) {
    const std::string scheme = c["scheme"];
    const VectorX mean = test_support::vector(c["mean"]);
    const MatrixX covariance = test_support::matrix(c["cov"]);
    const MatrixX lower = covariance.llt().matrixL();
    const MatrixX expected_points =
        test_support::matrix(c["points"]).transpose();  // rows are points
    SigmaPoints<Dynamic, Dynamic> set;
    if (scheme == "merwe") {
      set =
          draw_sigma_points(MerweScaledSigmaPoints{c["alpha"], c["beta"], c["kappa"]}, mean, lower);
    } else if (scheme == "julier") {
      set = draw_sigma_points(JulierSigmaPoints{c["kappa"]}, mean, lower);
    } else if (scheme == "simplex") {
      set = draw_sigma_points(SimplexSigmaPoints{}, mean, lower);
    } else {
      ADD_FAILURE() << "unknown scheme " << scheme;
      continue;
    }
    test_support::Agreement agreement;
    agreement.add("points", set.points, expected_points);
    agreement.add("Wm", set.mean_weights, test_support::vector(c["Wm"]));
    agreement.add("Wc", set.covariance_weights, test_support::vector(c["Wc"]));
    const std::string context = scheme + " n=" + std::to_string(int(c["n"]));
    agreement.expect_within(1e-9, context);
    worst = std::max(worst, agreement.worst().first);
  }
  std::cout << "[ parity   ] sigma_points.json: worst relative error " << worst << '\n';
  RecordProperty("worst_relative_error", std::to_string(worst));
}

// --- parameters ----------------------------------------------------------------------------
TEST(MerweScaledSigmaPoints, RejectsNonPositiveAlpha) {
  try {
    const MerweScaledSigmaPoints bad(0.0, 2.0, 0.0);
    FAIL() << "no throw";
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(e.argument(), "alpha");
    EXPECT_THAT(e.what(), HasSubstr("alpha: value is 0; rule: must be > 0"));
  }
  EXPECT_THROW(MerweScaledSigmaPoints(1.0, -1.0, 0.0), InvalidArgumentError);
  EXPECT_THROW(MerweScaledSigmaPoints(1.0, 2.0, std::nan("")), NonFiniteError);
}

TEST(MerweScaledSigmaPoints, RejectsAKappaTheDimensionDoesNotAdmit) {
  const MerweScaledSigmaPoints scheme(1.0, 2.0, -3.0);
  VectorX wm(7);
  VectorX wc(7);
  try {
    scheme.weights(3, wm, wc);
    FAIL() << "no throw";
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(e.argument(), "kappa");
    EXPECT_THAT(e.what(), HasSubstr("n + kappa is 0 (n = 3, kappa = -3); rule: must be > 0"));
  }
  VectorX wm4(9);
  VectorX wc4(9);
  EXPECT_NO_THROW(scheme.weights(4, wm4, wc4));
}

TEST(JulierSigmaPoints, RejectsAKappaTheDimensionDoesNotAdmit) {
  VectorX w(3);
  try {
    JulierSigmaPoints{-1.5}.weights(1, w, w);
    FAIL() << "no throw";
  } catch (const InvalidArgumentError& e) {
    EXPECT_THAT(e.what(), HasSubstr("kappa: n + kappa is -0.5 (n = 1, kappa = -1.5)"));
  }
}

TEST(SigmaPointSchemes, WeightVectorsMustHaveOneEntryPerPoint) {
  VectorX wrong(4);
  VectorX right(6);
  try {
    SphericalRadialSigmaPoints{}.weights(3, wrong, right);
    FAIL() << "no throw";
  } catch (const DimensionMismatchError& e) {
    EXPECT_THAT(e.what(), HasSubstr("mean_weights: size is 4; rule: must equal 6"));
  }
}

// --- SigmaPoints ---------------------------------------------------------------------------
template <typename Size>
class SigmaPointsTest : public ::testing::Test {};
using PointDimensions =
    ::testing::Types<std::integral_constant<int, 3>, std::integral_constant<int, Dynamic>>;
TYPED_TEST_SUITE(SigmaPointsTest, PointDimensions);

TYPED_TEST(SigmaPointsTest, WeightedMomentsReproduceTheGaussian) {
  constexpr int N = TypeParam::value;
  Vector<N> mean(3);
  mean << 0.5, -1.0, 2.0;
  SquareMatrix<N> lower(3, 3);
  lower << 1.0, 0.0, 0.0, 0.2, 0.5, 0.0, -0.1, 0.3, 0.7;
  auto set = draw_sigma_points(SphericalRadialSigmaPoints{}, mean, lower);
  static_assert(std::is_same_v<decltype(set.points), Matrix<N, size_product(2, N)>>);
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

TEST(SigmaPoints, DrawRejectsAFactorOfTheWrongShape) {
  try {
    (void)draw_sigma_points(SimplexSigmaPoints{}, VectorX(VectorX::Zero(2)),
                            MatrixX(MatrixX::Identity(3, 3)));
    FAIL() << "no throw";
  } catch (const DimensionMismatchError& e) {
    EXPECT_THAT(e.what(), HasSubstr("lower: is 3x3; rule: must be 2x2"));
  }
}

}  // namespace
}  // namespace twincal
