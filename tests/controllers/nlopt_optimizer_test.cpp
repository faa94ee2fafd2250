#include "twincal/controllers/nlopt_optimizer.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace twincal {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

static_assert(Optimizer<NloptOptimizer>);

TEST(NloptOptimizer, FindsTheMinimumOfAShiftedQuadratic) {
  const Eigen::Vector3d target(0.3, -0.2, 0.1);
  const Objective f = [&](const Eigen::Ref<const VectorX>& u) {
    return 0.5 + (u - target).squaredNorm();
  };
  const NloptOptimizer optimizer;
  const OptimizationResult result =
      optimizer.minimize(f, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Constant(3, -1.0),
                         Eigen::VectorXd::Constant(3, 1.0));
  EXPECT_LT((result.argmin - target).norm(), 1e-6);
  EXPECT_NEAR(result.minimum, 0.5, 1e-12);
  EXPECT_GT(result.evaluations, 0U);
  EXPECT_LE(result.evaluations, 3000U);
  EXPECT_THAT(result.summary, HasSubstr("GN_DIRECT_L: "));
  EXPECT_THAT(result.summary, HasSubstr("LN_BOBYQA: "));
}

TEST(NloptOptimizer, GlobalPhaseEscapesLocalMinima) {
  // Rastrigin in 2-D shifted to (0.31, -0.47): many local minima, one global minimum 0.
  const Eigen::Vector2d shift(0.31, -0.47);
  const Objective f = [&](const Eigen::Ref<const VectorX>& u) {
    double value = 20.0;
    for (Index i = 0; i < 2; ++i) {
      const double z = u(i) - shift(i);
      value += z * z - 10.0 * std::cos(2.0 * std::numbers::pi * z);
    }
    return value;
  };
  const Eigen::VectorXd start = Eigen::Vector2d(-3.0, 3.0);  // in a far local basin
  const NloptOptimizer local_only({.global_evaluations = 0});
  const NloptOptimizer global({.global_evaluations = 4000});
  const Eigen::VectorXd lower = Eigen::VectorXd::Constant(2, -4.0);
  const Eigen::VectorXd upper = Eigen::VectorXd::Constant(2, 4.0);
  EXPECT_GT(local_only.minimize(f, start, lower, upper).minimum, 1.0);
  const OptimizationResult result = global.minimize(f, start, lower, upper);
  EXPECT_LT(result.minimum, 1e-8);
  EXPECT_LT((result.argmin - shift).norm(), 1e-5);
}

TEST(NloptOptimizer, ObjectiveErrorsReachTheCallerUnchangedAndStopTheSearch) {
  int calls = 0;
  const Objective f = [&](const Eigen::Ref<const VectorX>&) -> double {
    if (++calls == 5) throw std::runtime_error("twin crashed on call 5");
    return 1.0;
  };
  const NloptOptimizer optimizer;
  EXPECT_THAT(
      [&] {
        (void)optimizer.minimize(f, Eigen::VectorXd::Zero(2), Eigen::VectorXd::Constant(2, -1.0),
                                 Eigen::VectorXd::Constant(2, 1.0));
      },
      ThrowsMessage<std::runtime_error>("twin crashed on call 5"));
  EXPECT_EQ(calls, 5);
}

TEST(NloptOptimizer, NonFiniteObjectiveIsATypedError) {
  const Objective f = [](const Eigen::Ref<const VectorX>& u) {
    return u(0) > 0.5 ? std::nan("") : 1.0 - u(0);
  };
  const NloptOptimizer optimizer;
  EXPECT_THAT(
      [&] {
        (void)optimizer.minimize(f, Eigen::VectorXd::Zero(1), Eigen::VectorXd::Constant(1, -1.0),
                                 Eigen::VectorXd::Constant(1, 1.0));
      },
      ThrowsMessage<NonFiniteError>(HasSubstr("] is nan; rule: must be finite")));
}

TEST(NloptOptimizer, RejectsInconsistentBoundsAndStart) {
  const Objective f = [](const Eigen::Ref<const VectorX>& u) { return u.squaredNorm(); };
  const NloptOptimizer optimizer;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(2);
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(2);
  EXPECT_THAT(
      [&] { (void)optimizer.minimize(f, zero, one, zero); },
      ThrowsMessage<InvalidArgumentError>("lower: entry 0 is 1 > upper 0; rule: lower <= upper"));
  EXPECT_THAT(
      [&] { (void)optimizer.minimize(f, Eigen::VectorXd::Constant(2, 2.0), -one, one); },
      ThrowsMessage<InvalidArgumentError>("start(0): value is 2; rule: must lie in [-1, 1]"));
  EXPECT_THAT([&] { (void)optimizer.minimize(f, zero, -Eigen::VectorXd::Ones(3), one); },
              ThrowsMessage<DimensionMismatchError>("lower: size is 3; rule: must equal 2"));
}

TEST(NloptOptimizerOptions, ValidateNamesTheField) {
  EXPECT_EQ(NloptOptimizerOptions{}.validate(), std::nullopt);
  EXPECT_EQ(
      NloptOptimizerOptions{.global_algorithm = NLOPT_LN_BOBYQA}.validate(),
      "global_algorithm: value is LN_BOBYQA; rule: must be a derivative-free global (GN_) one");
  EXPECT_EQ(NloptOptimizerOptions{.local_algorithm = NLOPT_LD_LBFGS}.validate(),
            "local_algorithm: value is LD_LBFGS; rule: must be a derivative-free local (LN_) one");
  EXPECT_EQ((NloptOptimizerOptions{.global_evaluations = 0, .local_evaluations = 0}.validate()),
            "global_evaluations and local_evaluations: values are 0 and 0; rule: at least one "
            "phase must run");
  EXPECT_THAT([] { NloptOptimizer{{.x_tolerance = -1.0}}; },
              ThrowsMessage<InvalidArgumentError>(
                  "NloptOptimizerOptions: x_tolerance: value is -1; rule: must be >= 0"));
}

}  // namespace
}  // namespace twincal
