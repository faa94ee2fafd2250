#include "twincal/models/locator_subset.hpp"

#include <array>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/random_stream.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal {
namespace {

// A 12-locator twin (the car body case has 12) in which A, B and C are three of the locators.
RmsQuadraticTwin make_subset_twin() {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = 12;
  options.assemblies.locator_names = {"L1", "L2", "A",  "L4", "L5",  "B",
                                      "L7", "L8", "L9", "C",  "L11", "L12"};
  return RmsQuadraticTwin::generate(options, RandomStream(21));
}

TEST(LocatorSubset, SelectsLocatorsByNameInTheGivenOrder) {
  const RmsQuadraticTwin twin = make_subset_twin();
  const std::array<std::string, 3> abc{"C", "A", "B"};
  const LocatorSubset subset = LocatorSubset<RmsQuadraticTwin>::by_name(twin, abc);
  EXPECT_THAT(subset.locators(), ::testing::ElementsAre(9, 2, 5));
  EXPECT_THAT(subset.locator_names(), ::testing::ElementsAre("C", "A", "B"));
  EXPECT_EQ(subset.control_dimension(), 3);
  EXPECT_EQ(subset.lower_bounds(), VectorX::Constant(3, -1.0));
  EXPECT_EQ(subset.upper_bounds(), VectorX::Constant(3, 1.0));
}

TEST(LocatorSubset, HoldsTheOtherLocatorsAtTheirOptimum) {
  const RmsQuadraticTwin twin = make_subset_twin();
  const std::array<std::string, 3> abc{"A", "B", "C"};
  const LocatorSubset subset = LocatorSubset<RmsQuadraticTwin>::by_name(twin, abc);
  for (const AssemblyId& x : {AssemblyId{0, 0}, AssemblyId{4, 7}, AssemblyId{9, 2}}) {
    const VectorX full_optimum = twin.optimum(x);
    const VectorX optimum = subset.optimum(x);
    EXPECT_EQ(optimum,
              (VectorX(3) << full_optimum(2), full_optimum(5), full_optimum(9)).finished());
    EXPECT_EQ(subset.optimal_quality(x), twin.optimal_quality(x));
    EXPECT_EQ(subset.quality(x, optimum), twin.optimal_quality(x));
    const VectorX v = optimum + VectorX::Constant(3, 0.05);
    VectorX full = full_optimum;
    full(2) = v(0);
    full(5) = v(1);
    full(9) = v(2);
    EXPECT_EQ(subset.embed(x, v), full);
    EXPECT_EQ(subset.quality(x, v), twin.quality(x, full));
    EXPECT_GT(subset.quality(x, v), subset.optimal_quality(x));
  }
}

// A twin that answers its key points' deviations keeps answering them, at the embedded control
// (tests/static/models_check.cpp says which subsets have them).
TEST(LocatorSubset, PassesTheKeyPointsDeviationsOn) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = 4;
  const KeyPointTwin<NoNonlinearity> twin(options, RandomStream(8));
  const LocatorSubset subset(twin, {3, 1});
  ASSERT_EQ(subset.key_point_count(), twin.key_point_count());
  const AssemblyId x{1, 4};
  MatrixX controls(2, 3);
  controls << 0.1, -0.2, 0.05, 0.3, 0.0, -0.15;
  MatrixX deviations(twin.key_point_count(), 3);
  subset.deviations_batch(x, controls, deviations);
  for (Index j = 0; j < 3; ++j) {
    EXPECT_EQ(deviations.col(j), twin.deviations(x, subset.embed(x, controls.col(j))));
  }
  MatrixX wrong(twin.key_point_count(), 2);
  EXPECT_THROW(subset.deviations_batch(x, controls, wrong), DimensionMismatchError);
}

TEST(LocatorSubset, SingleLocatorBatchMatchesSingleEvaluations) {
  const RmsQuadraticTwin twin = make_subset_twin();
  const LocatorSubset subset(twin, {5});
  EXPECT_THAT(subset.locator_names(), ::testing::ElementsAre("B"));
  const MatrixX controls = RowVector<Dynamic>::LinSpaced(7, -0.3, 0.3);
  VectorX out(7);
  subset.quality_batch({3, 3}, controls, out);
  for (Index j = 0; j < 7; ++j) EXPECT_EQ(out(j), subset.quality({3, 3}, controls.col(j)));
}

TEST(LocatorSubset, RejectsBadSelections) {
  const RmsQuadraticTwin twin = make_subset_twin();
  const std::array<std::string, 2> unknown{"A", "D"};
  EXPECT_THAT([&] { (void)LocatorSubset<RmsQuadraticTwin>::by_name(twin, unknown); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "names: locator \"D\" is unknown; rule: must be one of [L1, L2, A, L4, L5, B, "
                  "L7, L8, L9, C, L11, L12]"));
  EXPECT_THAT(
      [&] {
        (void)LocatorSubset(twin, {2, 12});
      },
      ::testing::ThrowsMessage<InvalidArgumentError>(
          "locators: entry 1 is 12; rule: must lie in [0, 11]"));
  EXPECT_THAT(
      [&] {
        (void)LocatorSubset(twin, {2, 5, 2});
      },
      ::testing::ThrowsMessage<InvalidArgumentError>(
          "locators: entry 2 repeats locator 2; rule: each locator at most once"));
  EXPECT_THAT([&] { (void)LocatorSubset(twin, {}); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "locators: is empty; rule: must name >= 1 locator"));
  const LocatorSubset subset(twin, {0, 1});
  EXPECT_THAT(
      [&] {
        (void)subset.quality({0, 0}, VectorX::Zero(3));
      },
      ::testing::ThrowsMessage<DimensionMismatchError>("control: size is 3; rule: must equal 2"));
}

}  // namespace
}  // namespace twincal
