#include "twincal/samplers/normal_quantile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

namespace twincal {
namespace {

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::numbers::sqrt2); }

TEST(NormalQuantile, InvertsTheNormalCdf) {
  for (const double p : {1e-300, 1e-100, 1e-10, 1e-3, 0.025, 0.2, 0.5, 0.7, 0.975, 0.999999}) {
    const double x = normal_quantile(p);
    // Rounding x by a few ulps moves Φ(x) relatively by about x² ulps (dΦ/Φ ≈ |x| dx in the
    // tail): the tolerance is that condition number times 8 ε.
    const double tolerance = 8.0 * std::numeric_limits<double>::epsilon() * (1.0 + x * x);
    EXPECT_NEAR(normal_cdf(x), p, tolerance * std::min(p, 1.0 - p)) << p;
  }
  for (const double x : {-8.0, -2.5, -1.0, 0.0, 0.3, 1.0, 4.0}) {
    EXPECT_NEAR(normal_quantile(normal_cdf(x)), x, 1e-13 * std::max(1.0, std::abs(x))) << x;
  }
  EXPECT_EQ(normal_quantile(0.5), 0.0);
  EXPECT_NEAR(normal_quantile(0.975), 1.959963984540054, 1e-15);
}

TEST(NormalQuantile, IsAntisymmetric) {
  // Powers of two p, so 1 − p is exact and only the quantile's own error shows.
  for (const double p : {0x1p-30, 0x1p-10, 0.0625, 0.25, 0.375}) {
    EXPECT_NEAR(normal_quantile(p), -normal_quantile(1.0 - p), 1e-12) << p;
  }
}

TEST(NormalQuantile, EndpointsAndOutsideValues) {
  EXPECT_EQ(normal_quantile(0.0), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(normal_quantile(1.0), std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(normal_quantile(-0.1)));
  EXPECT_TRUE(std::isnan(normal_quantile(1.5)));
  EXPECT_TRUE(std::isnan(normal_quantile(std::numeric_limits<double>::quiet_NaN())));
}

}  // namespace
}  // namespace twincal
