#include "twincal/samplers/discrepancy.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "qmc_golden.hpp"
#include "twincal/core/error.hpp"
#include "twincal/samplers/latin_hypercube.hpp"
#include "twincal/samplers/pseudo_random.hpp"
#include "twincal/samplers/sobol.hpp"

namespace twincal {
namespace {

TEST(Discrepancy, MatchesScipyOnTheStoredPointSets) {
  const auto& records = test_support::qmc_golden().at("discrepancy");
  ASSERT_EQ(records.size(), 9U);
  for (const auto& record : records) {
    const MatrixX points = test_support::golden_points(record);
    const std::string set =
        record.at("set").get<std::string>() + ", d = " + std::to_string(points.rows());
    // SciPy returns CD², WD², MD² and the root of L2*². Each D² is a difference of terms of
    // the size of its constant ((13/12)^d, (4/3)^d, (19/12)^d, 3^-d), so both codes carry a
    // round-off of about 1e-13 times that size; the tolerance is 1e-12 times it.
    const double d = static_cast<double>(points.rows());
    const auto expect = [&](DiscrepancyKind kind, const char* key, double scale, bool root) {
      const double squared = squared_discrepancy(points, kind);
      const double value = root ? std::sqrt(squared) : squared;
      const double expected = record.at(key).get<double>();
      const double tolerance = root ? 1e-12 * scale / expected : 1e-12 * scale;
      EXPECT_NEAR(value, expected, tolerance) << set << ", " << key;
    };
    expect(DiscrepancyKind::centered, "CD", std::pow(13.0 / 12.0, d), false);
    expect(DiscrepancyKind::wrap_around, "WD", std::pow(4.0 / 3.0, d), false);
    expect(DiscrepancyKind::mixture, "MD", std::pow(19.0 / 12.0, d), false);
    // L2*: the error of the square is 1e-12·3^-d, so the root's is that over 2·L2*.
    expect(DiscrepancyKind::l2_star, "L2_star", 0.5 * std::pow(3.0, -d), true);
  }
}

TEST(Discrepancy, SinglePointClosedForms) {
  // One point x in d = 1: CD² = 13/12 − 2(1 + z/2 − z²/2) + (1 + z), z = |x − ½|;
  // L2*² = 1/3 − (1 − x²) + (1 − x); WD² = −4/3 + 3/2.
  MatrixX point(1, 1);
  point << 0.2;
  const double z = 0.3;
  EXPECT_NEAR(squared_discrepancy(point, DiscrepancyKind::centered),
              13.0 / 12.0 - 2.0 * (1.0 + z / 2.0 - z * z / 2.0) + (1.0 + z), 1e-15);
  EXPECT_NEAR(squared_discrepancy(point, DiscrepancyKind::l2_star), 1.0 / 3.0 - (1.0 - 0.04) + 0.8,
              1e-15);
  EXPECT_NEAR(squared_discrepancy(point, DiscrepancyKind::wrap_around), 1.5 - 4.0 / 3.0, 1e-15);
}

TEST(Discrepancy, CenteredIsInvariantUnderReflectionAndWrapAroundUnderShift) {
  PseudoRandom random(4, {.seed = 3});
  MatrixX points(4, 50);
  random.fill(points);
  MatrixX reflected = points;
  reflected.row(2) = (1.0 - reflected.row(2).array()).matrix();
  EXPECT_NEAR(squared_discrepancy(reflected, DiscrepancyKind::centered),
              squared_discrepancy(points, DiscrepancyKind::centered), 1e-14);
  MatrixX shifted = points;
  shifted.row(1) = (shifted.row(1).array() + 0.37)
                       .unaryExpr([](double x) { return x - std::floor(x); })
                       .matrix();
  EXPECT_NEAR(squared_discrepancy(shifted, DiscrepancyKind::wrap_around),
              squared_discrepancy(points, DiscrepancyKind::wrap_around), 1e-14);
}

// Mean CD² of `replicates` n-point sets of `sampler`, reseeded 1000 + r for replicate r.
template <typename S>
double mean_centered_discrepancy(S& sampler, Index n, int replicates) {
  MatrixX points(sampler.dimension(), n);
  double mean = 0.0;
  for (int r = 0; r < replicates; ++r) {
    sampler.seed(1000 + static_cast<std::uint64_t>(r));
    sampler.fill(points);
    mean += squared_discrepancy(points, DiscrepancyKind::centered) / replicates;
  }
  return mean;
}

TEST(Discrepancy, ScrambledSobolBeatsPseudoRandomOverReplicates) {
  // 64 replicates of n = 2^8 points in d = 5. Randomized QMC has mean CD² of order
  // (log n)^d / n², Monte Carlo of order 1/n; measured ratio 0.038 for both scrambles. The test
  // requires a ratio below 0.1, which a sampler without the net property fails: a Latin
  // hypercube (stratified one coordinate at a time; measured ratio 0.25) is checked to stay
  // above it.
  constexpr int replicates = 64;
  constexpr Index n = 256;
  constexpr Index d = 5;
  PseudoRandom random(d);
  const double random_mean = mean_centered_discrepancy(random, n, replicates);
  for (const auto randomization :
       {SobolRandomization::linear_matrix_scramble, SobolRandomization::owen}) {
    Sobol sobol(d, {.randomization = randomization, .balance = BalanceCheck::refuse});
    const double sobol_mean = mean_centered_discrepancy(sobol, n, replicates);
    RecordProperty(std::string(to_string(randomization)) + "_ratio",
                   std::to_string(sobol_mean / random_mean));
    EXPECT_LT(sobol_mean, 0.1 * random_mean)
        << to_string(randomization) << ": " << sobol_mean << " vs " << random_mean;
  }
  LatinHypercube lhs(d);
  const double lhs_mean = mean_centered_discrepancy(lhs, n, replicates);
  RecordProperty("latin_hypercube_ratio", std::to_string(lhs_mean / random_mean));
  EXPECT_GT(lhs_mean, 0.1 * random_mean) << lhs_mean << " vs " << random_mean;
}

TEST(Discrepancy, RejectsPointsOutsideTheUnitCube) {
  MatrixX points = MatrixX::Constant(2, 3, 0.5);
  points(1, 2) = 1.5;
  try {
    (void)squared_discrepancy(points, DiscrepancyKind::centered);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()), "points: entry (1, 2) is 1.5; rule: must lie in [0, 1]");
  }
  points(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)squared_discrepancy(points, DiscrepancyKind::l2_star), NonFiniteError);
  try {
    (void)squared_discrepancy(MatrixX(2, 0), DiscrepancyKind::mixture);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()),
              "points: is 2x0; rule: needs at least one point of dimension >= 1");
  }
}

}  // namespace
}  // namespace twincal
