#include "twincal/controllers/quadratic_surrogate.hpp"

#include <gtest/gtest.h>

#include "controller_fixture.hpp"
#include "twincal/models/rugged_twin.hpp"

namespace twincal {
namespace {

TEST(QuadraticSurrogate, FitsTheSquaredQualityOfAQuadraticTwinExactly) {
  const test_support::AnalyticTwin twin = test_support::make_twin(4);
  const test_support::CountingTwin counting(twin);
  QuadraticSurrogate<test_support::CountingTwin, Dynamic> surrogate(counting);
  const AssemblyId x{3, 7};
  QuadraticModel<Dynamic> model;
  // Fitted away from the optimum, so the gradient is not zero.
  const VectorX center = twin.optimum(x) + VectorX::Constant(4, 0.1);
  EXPECT_EQ(surrogate.fit(x, center, model), 15U);  // (d + 1)(d + 2)/2
  EXPECT_EQ(counting.stats().evaluations, 15U);
  EXPECT_LT((model.hessian - twin.curvature()).cwiseAbs().maxCoeff(), 1e-9);
  const VectorX gradient = twin.curvature() * (center - twin.optimum(x));  // ∇Q²/2
  EXPECT_LT((model.half_gradient - gradient).cwiseAbs().maxCoeff(), 1e-9);
  const double q = twin.quality(x, center);
  EXPECT_NEAR(model.value, q * q, 1e-12);

  // The next assembly keeps H: d + 1 evaluations, same exactness.
  const AssemblyId y{1, 2};
  EXPECT_EQ(surrogate.fit(y, twin.optimum(y), model), 5U);
  EXPECT_LT(model.half_gradient.cwiseAbs().maxCoeff(), 1e-9);
  double error = 1.0;
  const MatrixX points = MatrixX::Random(4, 3) * 0.5;
  EXPECT_EQ(surrogate.check(y, model, points, error), 3U);
  EXPECT_LT(error, 1e-10);
}

// An earlier assembly's model refitted elsewhere with a given H (the active controller's
// relinearization): d + 1 evaluations, exact for a quadratic twin, and the surrogate's own H and
// its age untouched.
TEST(QuadraticSurrogate, RefitsAGradientWithAGivenHessianAndKeepsItsOwn) {
  const test_support::AnalyticTwin twin = test_support::make_twin(4);
  const test_support::CountingTwin counting(twin);
  QuadraticSurrogate<test_support::CountingTwin, Dynamic> surrogate(counting);
  const AssemblyId x{3, 7};
  QuadraticModel<Dynamic> own;
  static_cast<void>(surrogate.fit(x, twin.optimum(x), own));
  const bool stale = surrogate.hessian_stale();
  const VectorX center = twin.optimum(x) + VectorX::LinSpaced(4, -0.2, 0.3);
  QuadraticModel<Dynamic> refitted;
  EXPECT_EQ(surrogate.refit_gradient(x, center, twin.curvature(), refitted), 5U);
  EXPECT_EQ(counting.stats().evaluations, 15U + 5U);
  const VectorX gradient = twin.curvature() * (center - twin.optimum(x));
  EXPECT_LT((refitted.half_gradient - gradient).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(refitted.center, center);
  EXPECT_EQ(refitted.hessian, twin.curvature());
  EXPECT_EQ(surrogate.hessian_stale(), stale);
  QuadraticModel<Dynamic> next;
  EXPECT_EQ(surrogate.fit(x, twin.optimum(x), next), 5U);  // its own H is still kept
  EXPECT_EQ(next.hessian, own.hessian);
  EXPECT_THROW(
      static_cast<void>(surrogate.refit_gradient(x, center, MatrixX::Identity(3, 3), refitted)),
      DimensionMismatchError);
}

TEST(QuadraticSurrogate, ItsCheckRejectsATwinThatIsNotQuadratic) {
  const RuggedTwin twin(RuggedTwinOptions{}, RandomStream(3));
  QuadraticSurrogate<RuggedTwin, 3> surrogate(twin);
  const AssemblyId x{0, 0};
  QuadraticModel<3> model;
  static_cast<void>(surrogate.fit(x, Vector<3>(twin.optimum(x)), model));
  double error = 0.0;
  const MatrixX points = twin.optimum(x).replicate(1, 2) + MatrixX::Constant(3, 2, 0.23);
  static_cast<void>(surrogate.check(x, model, points, error));
  EXPECT_GT(error, surrogate.options().tolerance);
}

TEST(QuadraticSurrogate, OptionsNameTheRuleTheyBreak) {
  EXPECT_EQ(QuadraticSurrogateOptions{.step_fraction = 0.0}.validate(),
            "step_fraction: value is 0; rule: must lie in (0, 0.5]");
  EXPECT_EQ(QuadraticSurrogateOptions{.hessian_refresh = 0}.validate(),
            "hessian_refresh: value is 0; rule: must be >= 1");
}

}  // namespace
}  // namespace twincal
