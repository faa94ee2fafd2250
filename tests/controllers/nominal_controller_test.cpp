#include "twincal/controllers/nominal_controller.hpp"

#include <gtest/gtest.h>

#include "controller_fixture.hpp"
#include "twincal/controllers/controller.hpp"

namespace twincal {
namespace {

static_assert(Controller<NominalController<RmsQuadraticTwin>>);

TEST(NominalController, AppliesTheReferenceOptimumToEveryAssembly) {
  const RmsQuadraticTwin twin = test_support::make_twin(3);
  const AssemblyId reference{0, 0};
  NominalController<RmsQuadraticTwin> controller(twin, reference);
  EXPECT_EQ(controller.nominal().control, twin.optimum(reference));
  EXPECT_EQ(controller.nominal().quality, twin.optimal_quality(reference));
  for (const AssemblyId& x : twin.assemblies()) {
    EXPECT_EQ(controller.propose(x), twin.optimum(reference));
    controller.observe(x, controller.propose(x), 1.0);  // feedback changes nothing
  }
  EXPECT_EQ(controller.propose(AssemblyId{9, 9}), twin.optimum(reference));
}

TEST(NominalController, IsWorseThanIndividualOptimaOnAverage) {
  // The point of Def. 2 over Def. 1: per-assembly optima beat one reference optimum.
  const RmsQuadraticTwin twin = test_support::make_twin(3);
  NominalController<RmsQuadraticTwin> controller(twin, AssemblyId{0, 0});
  double nominal = 0.0;
  double individual = 0.0;
  for (const AssemblyId& x : twin.assemblies()) {
    nominal += twin.quality(x, controller.propose(x));
    individual += twin.optimal_quality(x);
  }
  EXPECT_GT(nominal, individual);
}

}  // namespace
}  // namespace twincal
