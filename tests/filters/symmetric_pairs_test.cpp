#include "twincal/filters/symmetric_pairs.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace twincal {
namespace {

// x ± s·L_k written after `first` columns, at fixed and run-time sizes on either side of the
// fixed-size bound: every path writes the definition and nothing else.
template <int N>
void check_pairs(Index n) {
  Vector<N> mean(n);
  SquareMatrix<N> lower = SquareMatrix<N>::Zero(n, n);
  for (Index c = 0; c < n; ++c) {
    mean(c) = 0.1 * static_cast<double>(c) - 0.3;
    for (Index r = c; r < n; ++r) {
      lower(r, c) = std::cos(0.5 * static_cast<double>(r) + 0.9 * static_cast<double>(c));
    }
  }
  Matrix<N, Dynamic> points = Matrix<N, Dynamic>::Constant(n, 2 * n + 2, 7.0);
  write_symmetric_pairs(mean, lower, 1.25, 1, points);
  EXPECT_TRUE((points.col(0).array() == 7.0).all()) << "n = " << n;
  EXPECT_TRUE((points.col(2 * n + 1).array() == 7.0).all()) << "n = " << n;
  for (Index k = 0; k < n; ++k) {
    const Vector<N> step = 1.25 * lower.col(k);
    EXPECT_TRUE(points.col(1 + k).isApprox(mean + step, 1e-15)) << "n = " << n;
    EXPECT_TRUE(points.col(1 + n + k).isApprox(mean - step, 1e-15)) << "n = " << n;
  }
}

TEST(WriteSymmetricPairs, WritesTheDefinitionAtEverySizeAndPath) {
  check_pairs<3>(3);
  check_pairs<max_fixed_dispatch_size + 2>(max_fixed_dispatch_size + 2);
  for (const Index n :
       {Index{1}, Index{3}, Index{max_fixed_dispatch_size}, Index{max_fixed_dispatch_size + 2}}) {
    check_pairs<Dynamic>(n);
  }
}

}  // namespace
}  // namespace twincal
