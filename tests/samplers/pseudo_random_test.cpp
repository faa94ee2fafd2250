#include "twincal/samplers/pseudo_random.hpp"

#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/samplers/sampler.hpp"

namespace twincal {
namespace {

static_assert(ConstructibleSampler<PseudoRandom>);

TEST(PseudoRandom, CoordinatesAreTopBitsOfTheStandardMt19937_64) {
  PseudoRandom random(3, {.seed = 42});
  MatrixX points(3, 4);
  random.fill(points);
  std::mt19937_64 engine(42);  // the standard fully specifies this engine
  for (Index c = 0; c < 4; ++c) {
    for (Index r = 0; r < 3; ++r) {
      EXPECT_EQ(points(r, c), std::ldexp(static_cast<double>(engine() >> 11U), -53));
    }
  }
}

// Seeding, discard, batches, the unit cube and the error types: the conformance suite
// (sampler_conformance_test.cpp).

TEST(PseudoRandom, SeedIsRecordedInTheOptions) {
  PseudoRandom random(4);
  random.seed(7);
  EXPECT_EQ(random.options().seed, 7U);
}

TEST(PseudoRandom, HasTheMeanAndVarianceOfUniforms) {
  PseudoRandom random(2, {.seed = 1});
  MatrixX points(2, 20000);
  random.fill(points);
  // Mean 1/2 and variance 1/12, within 5 standard errors.
  const double n = static_cast<double>(points.size());
  EXPECT_NEAR(points.mean(), 0.5, 5.0 * std::sqrt(1.0 / 12.0 / n));
  EXPECT_NEAR((points.array() - 0.5).square().mean(), 1.0 / 12.0, 5.0 * std::sqrt(1.0 / 180.0 / n));
}

TEST(PseudoRandom, ErrorMessagesNameTheArgumentTheValueAndTheRule) {
  try {
    PseudoRandom bad(0);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()), "dimension: value is 0; rule: must be >= 1");
  }
  PseudoRandom random(3);
  try {
    random.discard(UINT64_MAX / 2);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()),
              "count: value is 9223372036854775807; rule: count · dimension (3) must fit in 64 "
              "bits");
  }
}

}  // namespace
}  // namespace twincal
