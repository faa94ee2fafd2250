#include "twincal/samplers/sobol.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <boost/random/sobol.hpp>

#include "qmc_golden.hpp"
#include "twincal/core/error.hpp"
#include "twincal/samplers/sampler.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

static_assert(ConstructibleSampler<Sobol>);

SobolOptions quiet(SobolRandomization randomization = SobolRandomization::none,
                   std::uint64_t seed = 0) {
  return {.randomization = randomization, .seed = seed, .balance = BalanceCheck::refuse};
}

MatrixX draw(Sobol& sobol, Index count) {
  MatrixX points(sobol.dimension(), count);
  sobol.fill(points);
  return points;
}

// Number of leading binary digits two coordinates in [0, 1) share (bits = resolution).
int common_prefix(double x, double y, int bits) {
  const auto a = static_cast<std::uint64_t>(std::ldexp(x, bits));
  const auto b = static_cast<std::uint64_t>(std::ldexp(y, bits));
  return a == b ? bits : std::countl_zero(a ^ b) - (64 - bits);
}

// Every coordinate of `points` (2^m points) has exactly one point in each [k/2^m, (k+1)/2^m).
void expect_stratified(const MatrixX& points, const std::string& what) {
  const Index n = points.cols();
  ASSERT_TRUE(std::has_single_bit(static_cast<std::uint64_t>(n)));
  for (Index j = 0; j < points.rows(); ++j) {
    std::vector<int> hits(static_cast<std::size_t>(n), 0);
    for (Index c = 0; c < n; ++c) {
      const double cell = std::floor(points(j, c) * static_cast<double>(n));
      ASSERT_GE(cell, 0.0);
      ASSERT_LT(cell, static_cast<double>(n));
      ++hits[static_cast<std::size_t>(cell)];
    }
    for (Index k = 0; k < n; ++k) {
      ASSERT_EQ(hits[static_cast<std::size_t>(k)], 1)
          << what << ": coordinate " << j << ", cell " << k << " of " << n;
    }
  }
}

TEST(Sobol, UnscrambledIsBitIdenticalToScipyInEveryStoredDimension) {
  const auto& records = test_support::qmc_golden().at("sobol");
  ASSERT_EQ(records.size(), 9U);
  for (const auto& record : records) {
    const MatrixX expected = test_support::golden_points(record);
    Sobol sobol(expected.rows(), quiet());
    const MatrixX points = draw(sobol, expected.cols());
    for (Index c = 0; c < expected.cols(); ++c) {
      for (Index j = 0; j < expected.rows(); ++j) {
        ASSERT_EQ(points(j, c), expected(j, c))
            << "d = " << expected.rows() << ", point " << c << ", coordinate " << j;
      }
    }
  }
}

TEST(Sobol, MatchesBoostRandomSobolWhichSkipsTheZeroPoint) {
  for (const Index d : {1, 2, 40, 3667}) {  // 3667: Boost's largest dimension
    const Index n = d > 100 ? 64 : 4096;
    Sobol sobol(d, quiet());
    const MatrixX points = draw(sobol, n);
    ASSERT_TRUE((points.col(0).array() == 0.0).all());
    boost::random::sobol boost_sobol(static_cast<std::size_t>(d));
    for (Index c = 1; c < n; ++c) {
      for (Index j = 0; j < d; ++j) {
        const double expected = std::ldexp(static_cast<double>(boost_sobol()), -64);
        ASSERT_EQ(points(j, c), expected) << "d = " << d << ", point " << c << ", coordinate " << j;
      }
    }
  }
}

TEST(Sobol, EveryCoordinateOfEveryAlignedPowerOfTwoBlockIsExactlyStratified) {
  Sobol all(Sobol::max_dimension, quiet());  // every direction-number dimension, 2^6 points
  expect_stratified(draw(all, 64), "d = 21201, points 0-63");
  expect_stratified(draw(all, 64), "d = 21201, points 64-127");
  for (int m = 0; m <= 12; ++m) {
    Sobol sobol(64, quiet());
    const Index n = Index{1} << m;
    expect_stratified(draw(sobol, n), "first block, m = " + std::to_string(m));
    expect_stratified(draw(sobol, n), "second block, m = " + std::to_string(m));
  }
}

TEST(Sobol, ScrambledSequencesStayStratifiedAndPreserveDigitPrefixes) {
  for (const auto randomization :
       {SobolRandomization::linear_matrix_scramble, SobolRandomization::owen}) {
    const std::string name(to_string(randomization));
    Sobol plain(16, quiet());
    Sobol scrambled(16, quiet(randomization, 7));
    const MatrixX x = draw(plain, 1024);
    const MatrixX y = draw(scrambled, 1024);
    expect_stratified(y, name);
    expect_stratified(y.leftCols(256), name + ", first 256");
    // Nested scrambling is an isometry of the digit tree: two points share exactly as many
    // leading digits after scrambling as before, coordinate by coordinate.
    for (Index a = 0; a < 64; ++a) {
      for (Index b = a + 1; b < 1024; b += 7) {
        for (Index j = 0; j < 16; ++j) {
          ASSERT_EQ(common_prefix(y(j, a), y(j, b), 32), common_prefix(x(j, a), x(j, b), 32))
              << name << ", points " << a << ", " << b << ", coordinate " << j;
        }
      }
    }
    EXPECT_GT((x - y).cwiseAbs().maxCoeff(), 0.1) << name;
  }
}

TEST(Sobol, ScrambledPointsAreUniformOverSeeds) {
  // Across seeds, a fixed point of a randomized net is U[0, 1)^d: check the mean and the four
  // quarters of coordinate values of the zero point and of point 5 over 4000 seeds.
  for (const auto randomization :
       {SobolRandomization::linear_matrix_scramble, SobolRandomization::owen}) {
    constexpr int seeds = 4000;
    std::vector<int> quarter(4, 0);
    double sum = 0.0;
    Sobol sobol(3, quiet(randomization, 0));
    for (int s = 0; s < seeds; ++s) {
      sobol.seed(static_cast<std::uint64_t>(s));
      const MatrixX points = draw(sobol, 8);
      for (const Index c : {0, 5}) {
        for (Index j = 0; j < 3; ++j) {
          sum += points(j, c);
          ++quarter[static_cast<std::size_t>(points(j, c) * 4.0)];
        }
      }
    }
    const double count = 6.0 * seeds;
    // Standard error of the mean is sqrt(1/12 / count) = 0.0019 (treating values as
    // independent); 5 standard errors.
    EXPECT_NEAR(sum / count, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / count)) << to_string(randomization);
    for (const int q : quarter) {  // binomial(count, 1/4): sd = 53; 5 sd
      EXPECT_NEAR(q, count / 4.0, 5.0 * std::sqrt(count * 0.25 * 0.75)) << to_string(randomization);
    }
  }
}

// Seeding, discard = fill, batch splits, the unit cube and the error types for each
// randomization: the conformance suite (sampler_conformance_test.cpp).

TEST(Sobol, SeedRestartsAtPointZeroAndIsRecorded) {
  for (const auto randomization :
       {SobolRandomization::none, SobolRandomization::linear_matrix_scramble,
        SobolRandomization::owen}) {
    Sobol sobol(5, quiet(randomization, 11));
    (void)draw(sobol, 32);
    sobol.seed(12);
    EXPECT_EQ(sobol.position(), 0U) << to_string(randomization);
    EXPECT_EQ(sobol.options().seed, 12U) << to_string(randomization);
  }
}

TEST(Sobol, PositionCountsDrawnAndDiscardedPoints) {
  Sobol sobol(20, quiet(SobolRandomization::owen, 3));
  sobol.discard(1024);
  EXPECT_EQ(sobol.position(), 1024U);
  (void)draw(sobol, 1024);
  EXPECT_EQ(sobol.position(), 2048U);
}

TEST(Sobol, ResolutionFollowsBits) {
  Sobol coarse(4, {.bits = 8, .balance = BalanceCheck::refuse});
  EXPECT_EQ(coarse.size(), 256U);
  const MatrixX points = draw(coarse, 256);
  EXPECT_TRUE(((points.array() * 256.0).floor() == points.array() * 256.0).all());
  expect_stratified(points, "bits = 8");
  Sobol fine(4, {.bits = 52, .balance = BalanceCheck::refuse});
  const MatrixX fine_points = draw(fine, 256);
  EXPECT_EQ(fine_points, points);  // more bits only refine points beyond 2^8
  EXPECT_EQ(fine.direction(0, 51), 1U);
}

TEST(Sobol, LinearMatrixScrambleIsAffineInTheGrayCodeAndOwenIsNot) {
  // Point k is shift ⊕ (XOR of the directions selected by the Gray code g(k)), so points whose
  // Gray codes XOR to zero, g(a) ⊕ g(b) ⊕ g(c) = g(0) = 0, XOR to the shift (the zero point)
  // under a linear scramble; a nested uniform scramble is not linear.
  const auto gray_inverse = [](std::uint64_t g) {
    std::uint64_t k = 0;
    for (; g != 0; g >>= 1U) k ^= g;
    return k;
  };
  const auto bits = [](double x) { return static_cast<std::uint64_t>(std::ldexp(x, 32)); };
  for (const auto randomization :
       {SobolRandomization::linear_matrix_scramble, SobolRandomization::owen}) {
    Sobol sobol(8, quiet(randomization, 21));
    const MatrixX points = draw(sobol, 1024);
    int violations = 0;
    for (std::uint64_t a = 1; a < 1024; a += 37) {
      for (std::uint64_t b = 2; b < 1024; b += 53) {
        const std::uint64_t c = gray_inverse((a ^ (a >> 1U)) ^ (b ^ (b >> 1U)));
        for (Index j = 0; j < 8; ++j) {
          const auto ia = static_cast<Index>(a);
          const auto ib = static_cast<Index>(b);
          const auto ic = static_cast<Index>(c);
          if ((bits(points(j, ia)) ^ bits(points(j, ib)) ^ bits(points(j, ic))) !=
              bits(points(j, 0))) {
            ++violations;
          }
        }
      }
    }
    if (randomization == SobolRandomization::linear_matrix_scramble) {
      EXPECT_EQ(violations, 0);
    } else {
      EXPECT_GT(violations, 100);
    }
  }
}

TEST(Sobol, BalanceCheckWarnsRefusesOrIgnores) {
  std::vector<std::string> warnings;
  Sobol warned(2, {.balance = BalanceCheck::warn,
                   .warning_handler = [&](const std::string& m) { warnings.push_back(m); }});
  MatrixX points(2, 10);
  warned.fill(points);
  ASSERT_EQ(warnings.size(), 1U);
  EXPECT_EQ(warnings[0],
            "points: Sobol fill asks for 10 points starting at point 0; rule: the power-of-two "
            "balance property needs a power-of-two count starting at a multiple of it");
  EXPECT_EQ(warned.position(), 10U);  // a warning still generates

  Sobol refused(2, quiet());
  refused.discard(8);
  MatrixX sixteen(2, 16);
  try {
    refused.fill(sixteen);  // 16 points starting at 8: not an aligned block
    FAIL() << "expected InvalidArgumentError";
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(e.argument(), "points");
    EXPECT_THAT(e.what(), HasSubstr("asks for 16 points starting at point 8"));
  }
  EXPECT_EQ(refused.position(), 8U);  // unchanged
  MatrixX eight(2, 8);
  refused.fill(eight);
  EXPECT_EQ(refused.position(), 16U);
  refused.discard(1);                                       // one point is a block of 2^0 ...
  EXPECT_THROW(refused.fill(eight), InvalidArgumentError);  // ... but then 8 start at 17
  EXPECT_EQ(refused.position(), 17U);

  Sobol ignored(2, {.balance = BalanceCheck::ignore});
  ignored.discard(1);
  ignored.fill(points);
  EXPECT_EQ(ignored.position(), 11U);
}

TEST(Sobol, RejectsBadArgumentsWithoutChangingState) {
  try {
    Sobol bad(0);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()),
              "dimension: value is 0; rule: must lie in [1, 21201] (Joe & Kuo's direction "
              "numbers)");
  }
  EXPECT_THROW(Sobol(Sobol::max_dimension + 1), InvalidArgumentError);
  try {
    Sobol bad(2, {.bits = 53});
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(
        std::string(e.what()),
        "options: bits: value is 53; rule: must lie in [1, 52] so that every point is an exact "
        "double");
  }

  Sobol sobol(3, {.bits = 4, .balance = BalanceCheck::refuse});
  MatrixX wrong(2, 4);
  try {
    sobol.fill(wrong);
    FAIL();
  } catch (const DimensionMismatchError& e) {
    EXPECT_EQ(std::string(e.what()), "points: rows is 2; rule: must equal 3");
  }
  MatrixX sixteen(3, 16);
  sobol.fill(sixteen);  // all 2^4 points
  MatrixX one(3, 1);
  try {
    sobol.fill(one);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()),
              "points: 1 points from position 16 pass the end of the sequence; rule: a Sobol "
              "sequence with bits = 4 has 16 points");
  }
  EXPECT_THROW(sobol.discard(1), InvalidArgumentError);
  EXPECT_EQ(sobol.position(), 16U);
  EXPECT_THROW((void)sobol.direction(3, 0), InvalidArgumentError);
  EXPECT_THROW((void)sobol.direction(0, 4), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
