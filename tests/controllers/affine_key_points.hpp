#pragma once
// A test problem of the u0 searches (trust_region_search_test, least_squares_search_test): m
// key points whose deviations are affine in u, r(u) = a + B u, so Q² = ‖r‖²/m is exactly a
// quadratic with its minimum known from the normal equations.

#include <cmath>
#include <cstdint>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/QR>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal::search_test_support {

struct AffineKeyPoints {
  MatrixX b;
  VectorX a;

  // B ~ N(0, 1), a ~ N(0, 0.3²), from RandomStream(seed).substream(label).
  AffineKeyPoints(Index m, Index d, std::uint64_t seed, std::string_view label) : b(m, d), a(m) {
    RandomStream draws = RandomStream(seed).substream(label);
    draws.fill_normal(b);
    draws.fill_normal(a);
    a *= 0.3;
  }
  [[nodiscard]] double quality(const Eigen::Ref<const VectorX>& u) const {
    return std::sqrt((a + b * u).squaredNorm() / static_cast<double>(a.size()));
  }
  [[nodiscard]] VectorX argmin() const { return b.colPivHouseholderQr().solve(-a); }
  // Records a batch's size and checks that each of its points lies in [lower, upper].
  static void check_batch(const Eigen::Ref<const MatrixX>& points, const VectorX& lower,
                          const VectorX& upper, std::vector<Index>& batch_sizes) {
    batch_sizes.push_back(points.cols());
    for (Index k = 0; k < points.cols(); ++k) {
      EXPECT_TRUE((points.col(k).array() >= lower.array()).all() &&
                  (points.col(k).array() <= upper.array()).all())
          << "column " << k << " leaves the box";
    }
  }
};

inline Index total(const std::vector<Index>& sizes) {
  Index sum = 0;
  for (const Index s : sizes) sum += s;
  return sum;
}

}  // namespace twincal::search_test_support
