#include "twincal/samplers/latin_hypercube.hpp"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/samplers/sampler.hpp"

namespace twincal {
namespace {

static_assert(ConstructibleSampler<LatinHypercube>);

void expect_latin(const MatrixX& points) {
  const Index n = points.cols();
  for (Index r = 0; r < points.rows(); ++r) {
    std::vector<int> hits(static_cast<std::size_t>(n), 0);
    for (Index c = 0; c < n; ++c) {
      ASSERT_GE(points(r, c), 0.0);
      ASSERT_LT(points(r, c), 1.0);
      ++hits[static_cast<std::size_t>(std::floor(points(r, c) * static_cast<double>(n)))];
    }
    for (const int h : hits) ASSERT_EQ(h, 1) << "coordinate " << r;
  }
}

TEST(LatinHypercube, EveryCoordinateHasOnePointPerCell) {
  LatinHypercube lhs(6, {.seed = 3});
  for (const Index n : {1, 2, 7, 100, 1000}) {
    MatrixX points(6, n);
    lhs.fill(points);
    expect_latin(points);
  }
}

TEST(LatinHypercube, CenteredPutsPointsAtCellCentres) {
  LatinHypercube lhs(3, {.seed = 3, .centered = true});
  MatrixX points(3, 8);
  lhs.fill(points);
  expect_latin(points);
  EXPECT_TRUE(((points.array() * 8.0 - 0.5).round() == points.array() * 8.0 - 0.5).all());
}

// Seeding, discard (one dropped design), new designs per fill, the unit cube and the error
// types: the conformance suite (sampler_conformance_test.cpp).

TEST(LatinHypercube, ErrorMessagesNameTheArgumentTheValueAndTheRule) {
  try {
    LatinHypercube bad(-1);
    FAIL();
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()), "dimension: value is -1; rule: must be >= 1");
  }
  LatinHypercube lhs(3);
  MatrixX wrong(4, 2);
  try {
    lhs.fill(wrong);
    FAIL();
  } catch (const DimensionMismatchError& e) {
    EXPECT_EQ(std::string(e.what()), "points: rows is 4; rule: must equal 3");
  }
}

}  // namespace
}  // namespace twincal
