#include "twincal/samplers/halton.hpp"

#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "qmc_golden.hpp"
#include "twincal/core/error.hpp"
#include "twincal/samplers/sampler.hpp"

namespace twincal {
namespace {

static_assert(ConstructibleSampler<Halton>);

MatrixX draw(Halton& halton, Index count) {
  MatrixX points(halton.dimension(), count);
  halton.fill(points);
  return points;
}

TEST(Halton, UnscrambledIsBitIdenticalToScipy) {
  const auto& records = test_support::qmc_golden().at("halton");
  ASSERT_EQ(records.size(), 3U);
  for (const auto& record : records) {
    const MatrixX expected = test_support::golden_points(record);
    Halton halton(expected.rows());
    const MatrixX points = draw(halton, expected.cols());
    for (Index c = 0; c < expected.cols(); ++c) {
      for (Index j = 0; j < expected.rows(); ++j) {
        ASSERT_EQ(points(j, c), expected(j, c))
            << "d = " << expected.rows() << ", point " << c << ", coordinate " << j;
      }
    }
  }
}

TEST(Halton, BasesAreTheFirstPrimes) {
  const Halton halton(10);
  EXPECT_EQ(halton.bases(), (std::vector<std::uint32_t>{2, 3, 5, 7, 11, 13, 17, 19, 23, 29}));
  const Halton large(1000);
  EXPECT_EQ(large.bases().back(), 7919U);  // the 1000th prime
}

TEST(Halton, RadicalInverseOfTheIndex) {
  Halton halton(3);
  halton.discard(100);
  const MatrixX point = draw(halton, 1);
  // 100 = 1100100_2 = 10201_3 = 400_5: digits reversed behind the point.
  EXPECT_DOUBLE_EQ(point(0), 0b0010011 / 128.0);
  EXPECT_DOUBLE_EQ(point(1), (1 * 81 + 0 * 27 + 2 * 9 + 0 * 3 + 1) / 243.0);
  EXPECT_DOUBLE_EQ(point(2), (0 * 25 + 0 * 5 + 4) / 125.0);
}

// Seeding, discard, batch splits, the unit cube and the error types, plain and scrambled: the
// conformance suite (sampler_conformance_test.cpp).

TEST(Halton, PositionCountsDrawnAndDiscardedPoints) {
  Halton halton(6, {.scramble = true, .seed = 4});
  (void)draw(halton, 13);
  halton.discard(20);
  (void)draw(halton, 17);
  EXPECT_EQ(halton.position(), 50U);
  halton.seed(5);
  EXPECT_EQ(halton.position(), 0U);
  EXPECT_EQ(halton.options().seed, 5U);
}

TEST(Halton, RandomPermutationScramblingKeepsStratification) {
  Halton a(5, {.scramble = true, .seed = 1});
  Halton plain(5);
  const MatrixX x = draw(a, 3 * 5 * 7 * 11 * 11);
  EXPECT_GT((x - draw(plain, x.cols())).cwiseAbs().maxCoeff(), 0.1);
  // Digit permutations map the b^k cells of depth k onto themselves: the first b^k points
  // (k = 1, 2) still put one point in each cell of coordinate j.
  for (Index j = 0; j < 5; ++j) {
    const double base = a.bases()[static_cast<std::size_t>(j)];
    for (const double cells : {base, base * base}) {
      std::set<long> seen;
      for (Index k = 0; k < static_cast<Index>(cells); ++k) {
        seen.insert(static_cast<long>(std::floor(x(j, k) * cells)));
      }
      EXPECT_EQ(static_cast<double>(seen.size()), cells) << "coordinate " << j;
    }
  }
}

TEST(Halton, ScrambledPointsAreUniformOverSeeds) {
  constexpr int seeds = 3000;
  std::vector<int> quarter(4, 0);
  Halton halton(2, {.scramble = true});
  for (int s = 0; s < seeds; ++s) {
    halton.seed(static_cast<std::uint64_t>(s));
    const MatrixX point = draw(halton, 1);  // the zero point, all digits permuted zeros
    for (Index j = 0; j < 2; ++j) ++quarter[static_cast<std::size_t>(point(j) * 4.0)];
  }
  const double count = 2.0 * seeds;
  for (const int q : quarter) EXPECT_NEAR(q, count / 4.0, 5.0 * std::sqrt(count * 0.1875));
}

TEST(Halton, ErrorMessagesNameTheArgumentTheValueAndTheRule) {
  try {
    Halton bad(0);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()), "dimension: value is 0; rule: must lie in [1, 100000]");
  }
  Halton halton(2);
  halton.discard(5);
  try {
    halton.discard(UINT64_MAX);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()),
              "count: value is 18446744073709551615 at position 5; rule: the point index must "
              "fit in 64 bits");
  }
  EXPECT_EQ(halton.position(), 5U);
}

}  // namespace
}  // namespace twincal
