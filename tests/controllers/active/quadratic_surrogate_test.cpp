#include "twincal/controllers/active/quadratic_surrogate.hpp"

#include <gtest/gtest.h>

#include "../controller_fixture.hpp"
#include "twincal/models/rugged_twin.hpp"

namespace twincal {
namespace {

// A surrogate of the four-locator analytic twin, behind a counting evaluator.
class QuadraticSurrogateOnAnalyticTwin : public ::testing::Test {
 protected:
  const test_support::AnalyticTwin twin_ = test_support::make_twin(4);
  const test_support::CountingTwin counting_{twin_};
  QuadraticSurrogate<test_support::CountingTwin, Dynamic> surrogate_{counting_};
};

TEST_F(QuadraticSurrogateOnAnalyticTwin, FitsTheSquaredQualityOfAQuadraticTwinExactly) {
  const AssemblyId x{3, 7};
  QuadraticModel<Dynamic> model;
  // Fitted away from the optimum, so the gradient is not zero.
  const VectorX center = twin_.optimum(x) + VectorX::Constant(4, 0.1);
  EXPECT_EQ(surrogate_.fit(x, center, model), 15U);  // (d + 1)(d + 2)/2
  EXPECT_EQ(counting_.stats().evaluations, 15U);
  EXPECT_LT((model.hessian - twin_.curvature()).cwiseAbs().maxCoeff(), 1e-9);
  const VectorX gradient = twin_.curvature() * (center - twin_.optimum(x));  // ∇Q²/2
  EXPECT_LT((model.half_gradient - gradient).cwiseAbs().maxCoeff(), 1e-9);
  const double q = twin_.quality(x, center);
  EXPECT_NEAR(model.value, q * q, 1e-12);

  // The next assembly keeps H: d + 1 evaluations, same exactness.
  const AssemblyId y{1, 2};
  EXPECT_EQ(surrogate_.fit(y, twin_.optimum(y), model), 5U);
  EXPECT_LT(model.half_gradient.cwiseAbs().maxCoeff(), 1e-9);
  double error = 1.0;
  const MatrixX points = MatrixX::Random(4, 3) * 0.5;
  EXPECT_EQ(surrogate_.check(y, model, points, error), 3U);
  EXPECT_LT(error, 1e-10);
}

// An earlier assembly's model refitted elsewhere with a given H (the active controller's
// relinearization): d + 1 evaluations, exact for a quadratic twin, and the surrogate's own H and
// its age untouched.
TEST_F(QuadraticSurrogateOnAnalyticTwin, RefitsAGradientWithAGivenHessianAndKeepsItsOwn) {
  const AssemblyId x{3, 7};
  QuadraticModel<Dynamic> own;
  static_cast<void>(surrogate_.fit(x, twin_.optimum(x), own));
  const bool stale = surrogate_.hessian_stale();
  const VectorX center = twin_.optimum(x) + VectorX::LinSpaced(4, -0.2, 0.3);
  QuadraticModel<Dynamic> refitted;
  EXPECT_EQ(surrogate_.refit_gradient(x, center, twin_.curvature(), refitted), 5U);
  EXPECT_EQ(counting_.stats().evaluations, 15U + 5U);
  const VectorX gradient = twin_.curvature() * (center - twin_.optimum(x));
  EXPECT_LT((refitted.half_gradient - gradient).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(refitted.center, center);
  EXPECT_EQ(refitted.hessian, twin_.curvature());
  EXPECT_EQ(surrogate_.hessian_stale(), stale);
  QuadraticModel<Dynamic> next;
  EXPECT_EQ(surrogate_.fit(x, twin_.optimum(x), next), 5U);  // its own H is still kept
  EXPECT_EQ(next.hessian, own.hessian);
  EXPECT_THROW(
      static_cast<void>(surrogate_.refit_gradient(x, center, MatrixX::Identity(3, 3), refitted)),
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
