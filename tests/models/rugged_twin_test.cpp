#include "twincal/models/rugged_twin.hpp"

#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/random_stream.hpp"

namespace twincal {
namespace {

RuggedTwinOptions default_options() {
  RuggedTwinOptions options;  // s = 1, c = 0.05, λ = 0.1: 2πc/λ ≈ 3.1 > s, so multi-modal
  options.assemblies.dimension = 2;
  return options;
}

TEST(RuggedTwin, OptimumIsExactAndGlobal) {
  const RuggedTwin twin(default_options(), RandomStream(11));
  RandomStream stream(12);
  for (const AssemblyId& x : twin.assemblies()) {
    const VectorX a = twin.optimum(x);
    EXPECT_EQ(twin.quality(x, a), twin.optimal_quality(x));
    EXPECT_EQ(twin.optimal_quality(x), std::sqrt(twin.assembly_set().q0(x)));
    for (int trial = 0; trial < 20; ++trial) {
      VectorX u(2);
      stream.fill_normal(u);
      EXPECT_GT(twin.quality(x, a + 0.2 * u), twin.optimal_quality(x));
    }
  }
}

TEST(RuggedTwin, IsNonSmoothAtTheOptimum) {
  // One-sided difference quotients at e = 0 are ±(s + c(1 − cos(2πh/λ))/h) → ±s: a kink.
  const RuggedTwin twin(default_options(), RandomStream(11));
  const AssemblyId x{5, 6};
  const VectorX a = twin.optimum(x);
  const double h = 1e-5;
  const double ripple = 0.05 * (1.0 - std::cos(2.0 * std::numbers::pi * h / 0.1)) / h;
  const VectorX step = VectorX::Unit(2, 0) * h;
  const double right = (twin.quality(x, a + step) - twin.quality(x, a)) / h;
  const double left = (twin.quality(x, a) - twin.quality(x, a - step)) / h;
  // Round-off of the quotients is about ε·Q/h ≈ 1e-10.
  EXPECT_NEAR(right, 1.0 + ripple, 1e-9);
  EXPECT_NEAR(left, -1.0 - ripple, 1e-9);
}

TEST(RuggedTwin, HasLocalMinimaAwayFromTheOptimum) {
  // Along one locator f(e) = s|e| + c(1 − cos(2πe/λ)): f(0.1) = 0.1 lies below f(0.075) = 0.125
  // and f(0.125) = 0.175, so a local minimum lies in (0.075, 0.125), above the global f(0) = 0.
  const RuggedTwin twin(default_options(), RandomStream(11));
  const AssemblyId x{0, 3};
  const VectorX a = twin.optimum(x);
  const double z_star = twin.optimal_quality(x);
  const auto f = [&](double e) { return twin.quality(x, a + e * VectorX::Unit(2, 1)) - z_star; };
  EXPECT_NEAR(f(0.1), 0.1, 1e-14);
  EXPECT_NEAR(f(0.075), 0.125, 1e-14);
  EXPECT_NEAR(f(0.125), 0.175, 1e-14);
  EXPECT_LT(f(0.1), f(0.075));
  EXPECT_LT(f(0.1), f(0.125));
  EXPECT_GT(f(0.1), f(0.0));
}

TEST(RuggedTwin, BatchMatchesSingleEvaluations) {
  const RuggedTwin twin(default_options(), RandomStream(11));
  MatrixX controls(2, 9);
  RandomStream(13).fill_normal(controls);
  VectorX out(9);
  twin.quality_batch({9, 0}, controls, out);
  for (Index j = 0; j < 9; ++j) EXPECT_EQ(out(j), twin.quality({9, 0}, controls.col(j)));
}

TEST(RuggedTwin, RejectsInvalidOptions) {
  RuggedTwinOptions bad = default_options();
  bad.wavelength = 0.0;
  EXPECT_THAT([&] { (void)RuggedTwin(bad, RandomStream(1)); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "options: wavelength: value is 0; rule: must be finite and > 0"));
  bad = default_options();
  bad.assemblies.upper_parts = 0;
  EXPECT_THAT([&] { (void)RuggedTwin(bad, RandomStream(1)); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "options: assemblies.upper_parts: value is 0; rule: must be >= 1"));
}

}  // namespace
}  // namespace twincal
