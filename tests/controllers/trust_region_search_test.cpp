#include "twincal/controllers/trust_region_search.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "affine_key_points.hpp"
#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

using search_test_support::AffineKeyPoints;
using search_test_support::total;

// Q(u) = RMS(a + B u) as the twin's only answer.
struct RmsAffine : AffineKeyPoints {
  RmsAffine(Index m, Index d, std::uint64_t seed)
      : AffineKeyPoints(m, d, seed, "trust region test") {}
  [[nodiscard]] double operator()(const Eigen::Ref<const VectorX>& u) const { return quality(u); }
  // H = ∇²Q²/2 = BᵀB/m.
  [[nodiscard]] MatrixX curvature() const {
    return b.transpose() * b / static_cast<double>(a.size());
  }
  // Evaluates each column, checking it lies in [lower, upper]; counts points and batches.
  [[nodiscard]] BatchObjective objective(const VectorX& lower, const VectorX& upper,
                                         std::vector<Index>& batch_sizes) const {
    return [this, lower, upper, &batch_sizes](const Eigen::Ref<const MatrixX>& points,
                                              Eigen::Ref<VectorX> values) {
      EXPECT_EQ(values.size(), points.cols());
      check_batch(points, lower, upper, batch_sizes);
      for (Index k = 0; k < points.cols(); ++k) values(k) = quality(points.col(k));
    };
  }
};

// It stops once its radius is below final_radius of the box, so it finds u0 to about that;
// with a tiny final_radius it finds it to round-off, the fit being exact for a quadratic Q².
TEST(TrustRegionSearch, FindsTheInteriorMinimumOfAnRmsAffineQualityInFewBatches) {
  for (const Index d : {Index{3}, Index{8}}) {
    const RmsAffine quality(40, d, 7 + static_cast<std::uint64_t>(d));
    const VectorX target = quality.argmin();
    const VectorX lower = VectorX::Constant(d, -4.0);
    const VectorX upper = VectorX::Constant(d, 4.0);
    ASSERT_TRUE((target.array().abs() < 3.0).all()) << "the test wants an interior minimum";
    const auto budget = static_cast<std::uint64_t>(4 * (d + 1) * (d + 1));
    std::vector<Index> batches;
    const TrustRegionSearchOptions options{.evaluations = budget};
    const TrustRegionSearchResult result = TrustRegionSearch(options).minimize(
        quality.objective(lower, upper, batches), VectorX::Zero(d), lower, upper);
    EXPECT_EQ(result.status, TrustRegionStatus::converged) << "d = " << d;
    EXPECT_LT((result.argmin - target).cwiseAbs().maxCoeff(), 10.0 * options.final_radius * 8.0)
        << "d = " << d;
    EXPECT_NEAR(result.minimum, quality(target), 1e-6 * quality(target)) << "d = " << d;
    EXPECT_DOUBLE_EQ(result.minimum, quality(result.argmin));
    EXPECT_EQ(result.evaluations, static_cast<std::uint64_t>(total(batches)));
    EXPECT_EQ(result.batches, std::ssize(batches));
    EXPECT_EQ(batches.front(), 2 * d + 1);  // the start and 2d points, as BOBYQA's first model
    EXPECT_LT(result.batches * 4, static_cast<Index>(result.evaluations)) << "d = " << d;
    EXPECT_GT(result.accepted_steps, 0);
    EXPECT_GT(result.fits, 0);
    EXPECT_THAT(result.summary(), HasSubstr("(converged)"));

    std::vector<Index> unused;
    const TrustRegionSearchResult exact =
        TrustRegionSearch({.evaluations = 100000, .final_radius = 1e-12})
            .minimize(quality.objective(lower, upper, unused), VectorX::Zero(d), lower, upper);
    EXPECT_NEAR(exact.minimum, quality(target), 1e-12 * quality(target)) << "d = " << d;
    EXPECT_LT((exact.argmin - target).norm(), 1e-6) << "d = " << d;
  }
}

TEST(TrustRegionSearch, AGivenCurvatureStartsWithDPlusOnePointsAndConvergesSooner) {
  const Index d = 6;
  const RmsAffine quality(50, d, 21);
  const VectorX lower = VectorX::Constant(d, -4.0);
  const VectorX upper = VectorX::Constant(d, 4.0);
  const TrustRegionSearch search({.evaluations = 400});
  std::vector<Index> without;
  std::vector<Index> with;
  const TrustRegionSearchResult cold =
      search.minimize(quality.objective(lower, upper, without), VectorX::Zero(d), lower, upper);
  const TrustRegionSearchResult warm = search.minimize(
      quality.objective(lower, upper, with), VectorX::Zero(d), lower, upper, quality.curvature());
  EXPECT_EQ(with.front(), d + 1);
  EXPECT_NEAR(warm.minimum, quality(quality.argmin()), 1e-9);
  EXPECT_LT(warm.evaluations, cold.evaluations);
  EXPECT_LE(warm.batches, cold.batches);
  // The curvature it returns is the quality's: H = BᵀB/m (to the fit's rounding).
  ASSERT_EQ(warm.curvature.rows(), d);
  EXPECT_LT((warm.curvature - quality.curvature()).norm(), 1e-6 * quality.curvature().norm());
}

TEST(TrustRegionSearch, StopsAtTheBoxWhereTheMinimumLiesOutside) {
  const Index d = 3;
  const RmsAffine quality(30, d, 5);
  const VectorX target = quality.argmin();
  // A box that excludes the unconstrained minimum along locator 0.
  VectorX lower = target.array() - 1.0;
  VectorX upper = target.array() + 1.0;
  upper(0) = target(0) - 0.5;
  lower(0) = target(0) - 2.0;
  std::vector<Index> batches;
  const VectorX start = 0.5 * (lower + upper);
  const TrustRegionSearchResult result =
      TrustRegionSearch({.evaluations = 200})
          .minimize(quality.objective(lower, upper, batches), start, lower, upper);
  EXPECT_DOUBLE_EQ(result.argmin(0), upper(0));  // on the bound the minimum pushes against
  // A second search from there, with twice the budget, finds nothing better.
  const TrustRegionSearchResult again =
      TrustRegionSearch({.evaluations = 400})
          .minimize(quality.objective(lower, upper, batches), result.argmin, lower, upper);
  EXPECT_NEAR(result.minimum, again.minimum, 1e-6 * again.minimum);
}

TEST(TrustRegionSearch, SpendsNoMoreThanItsBudgetAndSaysSo) {
  const Index d = 4;
  const RmsAffine quality(30, d, 9);
  const VectorX lower = VectorX::Constant(d, -4.0);
  const VectorX upper = VectorX::Constant(d, 4.0);
  for (const std::uint64_t budget : {1U, 5U, 9U, 10U, 23U}) {
    std::vector<Index> batches;
    const TrustRegionSearchResult result =
        TrustRegionSearch({.evaluations = budget})
            .minimize(quality.objective(lower, upper, batches), VectorX::Zero(d), lower, upper);
    EXPECT_EQ(result.evaluations, budget);
    EXPECT_EQ(total(batches), static_cast<Index>(budget));
    EXPECT_EQ(result.status, TrustRegionStatus::budget_spent);
    EXPECT_LE(result.minimum, quality(VectorX::Zero(d)));
  }
  std::vector<Index> batches;
  const TrustRegionSearchResult converged =
      TrustRegionSearch({.evaluations = 100000, .final_radius = 1e-3})
          .minimize(quality.objective(lower, upper, batches), VectorX::Zero(d), lower, upper);
  EXPECT_EQ(converged.status, TrustRegionStatus::converged);
  EXPECT_LT(converged.radius, 1e-3);
  EXPECT_LT(converged.evaluations, 100000U);
}

TEST(TrustRegionSearch, LeavesOutControlsTheTwinCannotEvaluate) {
  const Index d = 3;
  const RmsAffine quality(30, d, 11);
  const VectorX target = quality.argmin();
  const VectorX lower = VectorX::Constant(d, -4.0);
  const VectorX upper = VectorX::Constant(d, 4.0);
  // No answer more than 1 beyond the start on the side away from the minimum along locator 0
  // (a solver that fails there): the first stencil's point at -2 on that side is one.
  const double side = target(0) >= 0.0 ? 1.0 : -1.0;
  Index failures = 0;
  const BatchObjective objective = [&](const Eigen::Ref<const MatrixX>& points,
                                       Eigen::Ref<VectorX> values) {
    for (Index k = 0; k < points.cols(); ++k) {
      const bool fails = side * points(0, k) < -1.0;
      failures += fails ? 1 : 0;
      values(k) = fails ? std::numeric_limits<double>::quiet_NaN() : quality(points.col(k));
    }
  };
  const TrustRegionSearchResult result =
      TrustRegionSearch({.evaluations = 300}).minimize(objective, VectorX::Zero(d), lower, upper);
  EXPECT_TRUE(std::isfinite(result.minimum));
  EXPECT_NEAR(result.minimum, quality(target), 1e-6 * quality(target));
  EXPECT_GT(failures, 0);
}

TEST(TrustRegionSearch, RefusesAStartWithoutAnswersANegativeQualityAndBadInput) {
  const Index d = 2;
  const VectorX lower = VectorX::Constant(d, -1.0);
  const VectorX upper = VectorX::Constant(d, 1.0);
  const BatchObjective nothing = [](const Eigen::Ref<const MatrixX>&, Eigen::Ref<VectorX> values) {
    values.setConstant(std::numeric_limits<double>::quiet_NaN());
  };
  const TrustRegionSearch search;
  EXPECT_THAT([&] { (void)search.minimize(nothing, VectorX::Zero(d), lower, upper); },
              ThrowsMessage<NonFiniteError>(HasSubstr("no finite value at the start")));
  const BatchObjective negative = [](const Eigen::Ref<const MatrixX>&, Eigen::Ref<VectorX> values) {
    values.setConstant(-0.5);
  };
  EXPECT_THAT([&] { (void)search.minimize(negative, VectorX::Zero(d), lower, upper); },
              ThrowsMessage<InvalidArgumentError>(HasSubstr("quality: value is -0.5")));
  const BatchObjective fine = [](const Eigen::Ref<const MatrixX>& points,
                                 Eigen::Ref<VectorX> values) {
    values = points.colwise().norm().transpose();
  };
  EXPECT_THAT([&] { (void)search.minimize(fine, VectorX::Constant(d, 2.0), lower, upper); },
              ThrowsMessage<InvalidArgumentError>(HasSubstr("start(0)")));
  EXPECT_THAT([&] { (void)search.minimize(fine, VectorX::Zero(d), lower, lower); },
              ThrowsMessage<InvalidArgumentError>(HasSubstr("rule: lower < upper")));
  EXPECT_THROW((void)search.minimize(fine, VectorX::Zero(3), lower, upper), DimensionMismatchError);
  EXPECT_THROW((void)search.minimize(fine, VectorX::Zero(d), lower, upper, MatrixX::Ones(3, 3)),
               DimensionMismatchError);
  MatrixX skew(2, 2);
  skew << 1.0, 0.5, -0.5, 1.0;
  EXPECT_THAT([&] { (void)search.minimize(fine, VectorX::Zero(d), lower, upper, skew); },
              ThrowsMessage<InvalidArgumentError>(HasSubstr("curvature: relative asymmetry")));
}

TEST(TrustRegionSearch, PassesTheObjectivesErrorsOnUnchanged) {
  int calls = 0;
  const BatchObjective crashes = [&](const Eigen::Ref<const MatrixX>& points,
                                     Eigen::Ref<VectorX> values) {
    if (++calls == 3) throw std::runtime_error("twin crashed on batch 3");
    values = points.colwise().norm().transpose();
    values.array() += 0.1;
  };
  EXPECT_THAT(
      [&] {
        (void)TrustRegionSearch().minimize(crashes, VectorX::Constant(2, 0.5),
                                           VectorX::Constant(2, -1.0), VectorX::Constant(2, 1.0));
      },
      ThrowsMessage<std::runtime_error>(HasSubstr("twin crashed on batch 3")));
  EXPECT_EQ(calls, 3);
}

TEST(TrustRegionSearch, OptionsNameTheRuleTheyBreak) {
  EXPECT_THAT([] { TrustRegionSearch({.evaluations = 0}); },
              ThrowsMessage<InvalidArgumentError>(
                  HasSubstr("evaluations: value is 0; rule: must be >= 1")));
  EXPECT_THAT([] { TrustRegionSearch({.initial_radius = 0.6}); },
              ThrowsMessage<InvalidArgumentError>(
                  HasSubstr("initial_radius: value is 0.6; rule: must lie in (0, 0.5]")));
  EXPECT_THAT([] { TrustRegionSearch({.initial_radius = 0.1, .final_radius = 0.1}); },
              ThrowsMessage<InvalidArgumentError>(HasSubstr(
                  "final_radius: value is 0.1; rule: must lie in (0, initial_radius = 0.1)")));
}

TEST(TrustRegionSearch, IsAPolicyOfIndividualOptimumAndRepeatsItself) {
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate({}, RandomStream(2023));
  const IndividualOptimum<RmsQuadraticTwin, TrustRegionSearch> search(
      twin, TrustRegionSearch({.evaluations = 200}));
  const AssemblyId assembly{2, 3};
  const VectorX centre = 0.5 * (twin.lower_bounds() + twin.upper_bounds());
  const IndividualControl found = search.optimize(assembly, centre);
  const IndividualControl again = search.optimize(assembly, centre);
  EXPECT_EQ(found.control, again.control);  // deterministic, bit for bit
  EXPECT_EQ(found.evaluations, again.evaluations);
  EXPECT_LE(found.evaluations, 200U);
  EXPECT_NEAR(found.quality, twin.optimal_quality(assembly), 1e-6 * twin.optimal_quality(assembly));
}

}  // namespace
}  // namespace twincal
