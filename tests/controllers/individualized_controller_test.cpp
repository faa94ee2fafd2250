#include "twincal/controllers/individualized_controller.hpp"

#include <gtest/gtest.h>

#include "controller_fixture.hpp"
#include "twincal/controllers/controller.hpp"

namespace twincal {
namespace {

using test_support::BlackBox;

static_assert(Twin<BlackBox> && !TwinWithOptimum<BlackBox>);
static_assert(Controller<IndividualizedController<BlackBox>>);

TEST(IndividualizedController, UsesTheTwinsExactOptimumWhenItHasOne) {
  const RmsQuadraticTwin twin = test_support::make_twin(3);
  IndividualizedController<RmsQuadraticTwin> controller(twin);
  for (const AssemblyId& x : {AssemblyId{0, 0}, AssemblyId{3, 8}}) {
    EXPECT_EQ(controller.propose(x), twin.optimum(x));
    EXPECT_EQ(controller.last_optimum().quality, twin.optimal_quality(x));
    EXPECT_EQ(controller.last_optimum().evaluations, 0U);
  }
}

TEST(IndividualizedController, FindsTheOptimumOfABlackBoxWithTheOptimizer) {
  const RmsQuadraticTwin twin = test_support::make_twin(3);
  const BlackBox black_box(twin);
  IndividualizedController<BlackBox> controller(black_box);
  const AssemblyId x{6, 1};
  const VectorX u = controller.propose(x);
  EXPECT_LT((u - twin.optimum(x)).norm(), 1e-5);
  EXPECT_NEAR(controller.last_optimum().quality, twin.optimal_quality(x), 1e-9);
  EXPECT_GT(controller.last_optimum().evaluations, 0U);
}

}  // namespace
}  // namespace twincal
