#pragma once
// Seeded random controls for the lap joint's six locators, uniform in ±half_width mm, and the
// check that a twin's quality is the RMS of its deviations.

#include <cmath>
#include <cstdint>

#include <gtest/gtest.h>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/assembly_id.hpp"

namespace twincal::test_support {

inline MatrixX random_controls(Index columns, std::uint64_t seed, double half_width) {
  RandomStream stream(seed);
  MatrixX controls(6, columns);
  for (Index c = 0; c < columns; ++c) {
    for (Index k = 0; k < 6; ++k) controls(k, c) = half_width * (2.0 * stream.uniform() - 1.0);
  }
  return controls;
}

// The deviations of `controls` at `assembly` in one batch, each checked to have `twin`'s quality
// (also one batch) as its RMS, to `relative`.
template <typename T>
MatrixX expect_quality_is_rms_of_deviations(const T& twin, const AssemblyId& assembly,
                                            const MatrixX& controls, double relative) {
  const Index m = twin.key_point_count();
  MatrixX deviations(m, controls.cols());
  twin.deviations_batch(assembly, controls, deviations);
  VectorX q(controls.cols());
  twin.quality_batch(assembly, controls, q);
  for (Index k = 0; k < controls.cols(); ++k) {
    EXPECT_NEAR(deviations.col(k).norm() / std::sqrt(static_cast<double>(m)), q(k), relative * q(k))
        << k;
  }
  return deviations;
}

}  // namespace twincal::test_support
