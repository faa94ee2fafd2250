#include "twincal/sheet_metal/sheet_metal_twin.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/sheet_metal/sheet_metal_process.hpp"

namespace twincal::sheet_metal_twin_test {
namespace {

// One twin per case for the whole suite: the precomputation is the expensive part.
const SheetMetalTwin& shared(SheetMetalCase which) {
  static const SheetMetalTwin body = SheetMetalTwin::body();
  static const SheetMetalTwin door = SheetMetalTwin::door();
  return which == SheetMetalCase::body ? body : door;
}

double mean_nominal_quality(const SheetMetalTwin& twin) {
  const VectorX zero = VectorX::Zero(twin.control_dimension());
  double sum = 0.0;
  for (const AssemblyId& a : twin.assemblies()) sum += twin.quality(a, zero);
  return sum / static_cast<double>(twin.assemblies().size());
}

double mean_optimal_quality(const SheetMetalTwin& twin) {
  double sum = 0.0;
  for (const AssemblyId& a : twin.assemblies()) sum += twin.optimal_quality(a);
  return sum / static_cast<double>(twin.assemblies().size());
}

TEST(SheetMetalTwin, BodyIsSensitive) {
  const SheetMetalTwin& twin = shared(SheetMetalCase::body);
  EXPECT_EQ(twin.control_dimension(), 12);
  EXPECT_EQ(twin.assemblies().size(), 100U);
  const double eta = 1.0 - mean_optimal_quality(twin) / mean_nominal_quality(twin);
  EXPECT_NEAR(eta, twin.achievable_gain(), 1e-12);
  EXPECT_GE(eta, 0.5);
  EXPECT_LE(eta, 0.8);
}

TEST(SheetMetalTwin, DoorIsInsensitiveButNotDead) {
  const SheetMetalTwin& twin = shared(SheetMetalCase::door);
  EXPECT_EQ(twin.control_dimension(), 19);
  const double eta = 1.0 - mean_optimal_quality(twin) / mean_nominal_quality(twin);
  EXPECT_NEAR(eta, twin.achievable_gain(), 1e-12);
  EXPECT_GT(eta, 0.0);
  EXPECT_LE(eta, 0.2);
}

class SheetMetalTwinCase : public ::testing::TestWithParam<SheetMetalCase> {};

TEST_P(SheetMetalTwinCase, QualityIsTheRmsOfTheKeyDeviations) {
  const SheetMetalTwin& twin = shared(GetParam());
  RandomStream stream(21);
  MatrixX controls(twin.control_dimension(), 4);
  stream.fill_normal(controls);
  VectorX batch(4);
  const AssemblyId assembly{3, 7};
  twin.quality_batch(assembly, controls, batch);
  for (Index j = 0; j < 4; ++j) {
    const VectorX y = twin.key_deviation(assembly, controls.col(j));
    const double rms = y.norm() / std::sqrt(static_cast<double>(y.size()));
    EXPECT_NEAR(twin.quality(assembly, controls.col(j)), rms, 1e-12 * (1.0 + rms));
    EXPECT_EQ(batch(j), twin.quality(assembly, controls.col(j)));
  }
}

// The box-constrained least-squares conditions (KKT): the gradient Bᵀy of ½‖y‖² vanishes at
// interior components and points outwards at active bounds; and no feasible neighbour is better.
void expect_box_optimal(const SheetMetalTwin& twin, const AssemblyId& assembly,
                        RandomStream& stream) {
  const VectorX u0 = twin.optimum(assembly);
  const VectorX& low = twin.lower_bounds();
  const VectorX& high = twin.upper_bounds();
  const VectorX y = twin.key_deviation(assembly, u0);
  const VectorX gradient = twin.influence().transpose() * y;
  const double tolerance = 1e-10 * twin.influence().norm() * (y.norm() + 1.0);
  for (Index k = 0; k < u0.size(); ++k) {
    EXPECT_GE(u0(k), low(k) - 1e-15);
    EXPECT_LE(u0(k), high(k) + 1e-15);
    if (u0(k) >= high(k) - 1e-12) {
      EXPECT_LE(gradient(k), tolerance);
    } else if (u0(k) <= low(k) + 1e-12) {
      EXPECT_GE(gradient(k), -tolerance);
    } else {
      EXPECT_NEAR(gradient(k), 0.0, tolerance);
    }
  }
  EXPECT_NEAR(twin.optimal_quality(assembly), twin.quality(assembly, u0), 1e-12);
  for (int trial = 0; trial < 5; ++trial) {
    VectorX step(u0.size());
    stream.fill_normal(step);
    const VectorX other = (u0 + 1e-2 * step).cwiseMax(low).cwiseMin(high);
    EXPECT_LE(twin.optimal_quality(assembly), twin.quality(assembly, other) + 1e-14);
  }
}

TEST_P(SheetMetalTwinCase, OptimumIsTheBoxConstrainedLeastSquaresSolution) {
  const SheetMetalTwin& twin = shared(GetParam());
  RandomStream stream(22);
  for (const AssemblyId& assembly : {AssemblyId{0, 0}, AssemblyId{9, 4}, AssemblyId{5, 9}}) {
    expect_box_optimal(twin, assembly, stream);
  }
}

TEST_P(SheetMetalTwinCase, SignificantLocatorsHaveTheLargestSingleLocatorGain) {
  const SheetMetalTwin& twin = shared(GetParam());
  // The documented rule, evaluated independently: the mean over assemblies of Q(x, 0) minus the
  // best Q(x, t e_k) over t in the box, found by ternary search (Q is convex in t).
  const Index d = twin.control_dimension();
  VectorX effects = VectorX::Zero(d);
  for (const AssemblyId& a : twin.assemblies()) {
    const double nominal = twin.quality(a, VectorX::Zero(d));
    for (Index k = 0; k < d; ++k) {
      double low = twin.lower_bounds()(k);
      double high = twin.upper_bounds()(k);
      const auto q = [&](double t) { return twin.quality(a, t * VectorX::Unit(d, k)); };
      for (int it = 0; it < 200; ++it) {
        const double m1 = low + (high - low) / 3.0;
        const double m2 = high - (high - low) / 3.0;
        if (q(m1) < q(m2)) {
          high = m2;
        } else {
          low = m1;
        }
      }
      effects(k) += nominal - q(0.5 * (low + high));
    }
  }
  effects /= static_cast<double>(twin.assemblies().size());
  EXPECT_LT((effects - twin.locator_effects()).cwiseAbs().maxCoeff(), 1e-9);
  std::vector<Index> order(static_cast<std::size_t>(d));
  for (Index k = 0; k < d; ++k) order[static_cast<std::size_t>(k)] = k;
  std::sort(order.begin(), order.end(), [&](Index a, Index b) { return effects(a) > effects(b); });
  const std::array<Index, 3> abc = twin.significant_locators();
  EXPECT_EQ((std::array<Index, 3>{order[0], order[1], order[2]}), abc);
  EXPECT_GT(effects(abc[2]), effects(order[3]));
}

INSTANTIATE_TEST_SUITE_P(Cases, SheetMetalTwinCase,
                         ::testing::Values(SheetMetalCase::body, SheetMetalCase::door));

TEST(SheetMetalTwin, TightBoundsBindAndUnboundedOptimumSolvesTheNormalEquations) {
  SheetMetalTwinOptions options;
  options.upper_parts = 2;
  options.lower_parts = 2;
  options.locator_bound = 0.05;  // tight, so bounds bind
  const SheetMetalTwin tight = SheetMetalTwin::make(SheetMetalCase::body, 2023, options);
  RandomStream stream(23);
  Index active = 0;
  for (const AssemblyId& a : tight.assemblies()) {
    expect_box_optimal(tight, a, stream);
    active += (tight.optimum(a).cwiseAbs().array() >= 0.05 - 1e-12).count();
  }
  EXPECT_GT(active, 0);

  options.locator_bound = 1.0;
  options.bounded_optimum = false;
  const SheetMetalTwin unbounded = SheetMetalTwin::make(SheetMetalCase::body, 2023, options);
  for (const AssemblyId& a : unbounded.assemblies()) {
    const VectorX y = unbounded.key_deviation(a, unbounded.optimum(a));
    EXPECT_LT((unbounded.influence().transpose() * y).norm(),
              1e-10 * unbounded.influence().norm() * y.norm());
    EXPECT_LE(unbounded.optimal_quality(a), tight.optimal_quality(a) + 1e-14);
  }
}

TEST(SheetMetalTwin, IsReproducibleAndChecksItsArguments) {
  SheetMetalTwinOptions options;
  options.upper_parts = 2;
  options.lower_parts = 3;
  const SheetMetalTwin a = SheetMetalTwin::make(SheetMetalCase::body, 99, options);
  const SheetMetalTwin b = SheetMetalTwin::make(SheetMetalCase::body, 99, options);
  EXPECT_EQ(a.upper_part(1), b.upper_part(1));
  EXPECT_EQ(a.optimum({1, 2}), b.optimum({1, 2}));
  EXPECT_EQ(a.assemblies().size(), 6U);
  EXPECT_EQ(a.locator_names().front(), "U1");
  EXPECT_EQ(a.locator_names().back(), "L6");
  EXPECT_THROW((void)a.quality({2, 0}, VectorX::Zero(12)), InvalidArgumentError);
  EXPECT_THROW((void)a.quality({0, 0}, VectorX::Zero(11)), DimensionMismatchError);
  EXPECT_THROW((void)a.upper_part(2), InvalidArgumentError);
  options.locator_bound = 0.0;
  EXPECT_THROW((void)SheetMetalTwin::make(SheetMetalCase::body, 1, options), InvalidArgumentError);
  const SheetMetalLayout layout = SheetMetalLayout::body();
  EXPECT_THROW(SheetMetalTwin(layout, {}, {VectorX::Zero(5)}, {a.lower_part(0)}),
               DimensionMismatchError);
  EXPECT_THROW(SheetMetalTwin(layout, {}, {}, {a.lower_part(0)}), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal::sheet_metal_twin_test
