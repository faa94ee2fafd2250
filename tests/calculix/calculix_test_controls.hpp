#pragma once
// Seeded random controls for the lap joint's six locators, uniform in ±half_width mm.

#include <cstdint>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal::test_support {

inline MatrixX random_controls(Index columns, std::uint64_t seed, double half_width) {
  RandomStream stream(seed);
  MatrixX controls(6, columns);
  for (Index c = 0; c < columns; ++c) {
    for (Index k = 0; k < 6; ++k) controls(k, c) = half_width * (2.0 * stream.uniform() - 1.0);
  }
  return controls;
}

}  // namespace twincal::test_support
