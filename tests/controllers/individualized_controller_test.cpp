#include "twincal/controllers/individualized_controller.hpp"

#include <gtest/gtest.h>

#include "controller_fixture.hpp"
#include "twincal/controllers/controller.hpp"

namespace twincal {
namespace {

// The RMS-quadratic twin without its known optimum: a black box to the controller.
class BlackBox {
 public:
  using Assembly = AssemblyId;
  explicit BlackBox(const RmsQuadraticTwin& twin) : twin_(&twin) {}
  [[nodiscard]] Index control_dimension() const { return twin_->control_dimension(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const {
    return twin_->locator_names();
  }
  [[nodiscard]] const VectorX& lower_bounds() const { return twin_->lower_bounds(); }
  [[nodiscard]] const VectorX& upper_bounds() const { return twin_->upper_bounds(); }
  [[nodiscard]] double quality(const Assembly& x, const Eigen::Ref<const VectorX>& u) const {
    return twin_->quality(x, u);
  }
  void quality_batch(const Assembly& x, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    twin_->quality_batch(x, controls, out);
  }

 private:
  const RmsQuadraticTwin* twin_;
};
static_assert(Twin<BlackBox> && !TwinWithOptimum<BlackBox>);
static_assert(Controller<IndividualizedController<BlackBox>>);

TEST(IndividualizedController, UsesTheTwinsExactOptimumWhenItHasOne) {
  const RmsQuadraticTwin twin = testing::make_twin(3);
  IndividualizedController<RmsQuadraticTwin> controller(twin);
  for (const AssemblyId& x : {AssemblyId{0, 0}, AssemblyId{3, 8}}) {
    EXPECT_EQ(controller.propose(x), twin.optimum(x));
    EXPECT_EQ(controller.last_optimum().quality, twin.optimal_quality(x));
    EXPECT_EQ(controller.last_optimum().evaluations, 0U);
  }
}

TEST(IndividualizedController, FindsTheOptimumOfABlackBoxWithTheOptimizer) {
  const RmsQuadraticTwin twin = testing::make_twin(3);
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
