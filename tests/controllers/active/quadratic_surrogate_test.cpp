#include "twincal/controllers/active/quadratic_surrogate.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

#include "../controller_fixture.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/no_nonlinearity.hpp"
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
// relinearization): 2d + 1 evaluations, exact for a quadratic twin, and the surrogate's own H and
// its age untouched.
TEST_F(QuadraticSurrogateOnAnalyticTwin, RefitsAGradientWithAGivenHessianAndKeepsItsOwn) {
  const AssemblyId x{3, 7};
  QuadraticModel<Dynamic> own;
  static_cast<void>(surrogate_.fit(x, twin_.optimum(x), own));
  const bool stale = surrogate_.hessian_stale();
  const VectorX center = twin_.optimum(x) + VectorX::LinSpaced(4, -0.2, 0.3);
  QuadraticModel<Dynamic> refitted;
  EXPECT_EQ(surrogate_.refit_gradient(x, center, twin_.curvature(), refitted), 9U);
  EXPECT_EQ(surrogate_.refit_evaluations(), 9);
  EXPECT_EQ(counting_.stats().evaluations, 15U + 9U);
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

// The controller refits only models that failed their check, whose H is wrong: the refit's
// gradient comes from central differences and is exact for a quadratic Q² whatever H it is given
// (forward differences corrected by a wrong H err by h (H − H_twin)_ii / 2 per locator).
TEST_F(QuadraticSurrogateOnAnalyticTwin, RefitsTheGradientWhateverTheHessianItIsGiven) {
  const AssemblyId x{5, 2};
  const VectorX center = twin_.optimum(x) + VectorX::LinSpaced(4, 0.3, -0.1);
  const VectorX gradient = twin_.curvature() * (center - twin_.optimum(x));
  const double q = twin_.quality(x, center);
  for (const double scale : {0.0, 0.5, 3.0}) {
    const MatrixX wrong = scale * twin_.curvature() + MatrixX::Identity(4, 4);
    QuadraticModel<Dynamic> refitted;
    static_cast<void>(surrogate_.refit_gradient(x, center, wrong, refitted));
    EXPECT_LT((refitted.half_gradient - gradient).cwiseAbs().maxCoeff(), 1e-9) << scale;
    EXPECT_EQ(refitted.hessian, wrong);  // the model keeps the H it was given
    EXPECT_NEAR(refitted.value, q * q, 1e-12);
  }
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

// A four-locator key-point twin without a nonlinearity: r(u) affine, so Q² = ‖r‖²/m is a
// quadratic, and the Gauss–Newton model of its deviations is exact.
KeyPointTwin<NoNonlinearity> affine_key_points() {
  KeyPointTwinOptions options;
  options.assemblies.dimension = 4;
  options.key_points = 12;
  return KeyPointTwin<NoNonlinearity>(options, RandomStream(5));
}

TEST(QuadraticSurrogateFromDeviations, FitsTheModelOfAQuadraticFitIn2DPlusOneEvaluations) {
  const KeyPointTwin<NoNonlinearity> twin = affine_key_points();
  QuadraticSurrogate<KeyPointTwin<NoNonlinearity>, 4> deviations(twin);
  QuadraticSurrogate<KeyPointTwin<NoNonlinearity>, 4> squares(
      twin, QuadraticSurrogateOptions{.from_deviations = false});
  ASSERT_TRUE(deviations.uses_deviations());
  ASSERT_FALSE(squares.uses_deviations());
  const AssemblyId x{2, 3};
  const Vector<4> center = Vector<4>(twin.optimum(x)) + Vector<4>(0.1, -0.2, 0.05, 0.3);
  QuadraticModel<4> from_deviations;
  QuadraticModel<4> from_squares;
  EXPECT_EQ(deviations.fit(x, center, from_deviations), 9U);  // 2d + 1
  EXPECT_EQ(squares.fit(x, center, from_squares), 15U);       // (d + 1)(d + 2)/2
  EXPECT_LT((from_deviations.hessian - from_squares.hessian).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((from_deviations.half_gradient - from_squares.half_gradient).cwiseAbs().maxCoeff(),
            1e-9);
  const double q = twin.quality(x, center);
  EXPECT_NEAR(from_deviations.value, q * q, 1e-12);
  EXPECT_EQ(from_deviations.hessian, from_deviations.hessian.transpose());
  EXPECT_EQ(deviations.full_fit_evaluations(), 9);
  EXPECT_EQ(deviations.refit_evaluations(), 9);
  EXPECT_EQ(squares.refit_evaluations(), 9);  // central differences from Q²

  // The next assembly keeps J: r at v0 alone, same exactness; after hessian_refresh
  // assemblies a full fit again.
  EXPECT_FALSE(deviations.hessian_stale());
  EXPECT_EQ(deviations.gradient_fit_evaluations(), 1);
  const AssemblyId y{0, 1};
  const Vector<4> other = Vector<4>(twin.optimum(y)) + Vector<4>(-0.3, 0.1, 0.2, 0.0);
  QuadraticModel<4> kept;
  EXPECT_EQ(deviations.fit(y, other, kept), 1U);
  EXPECT_EQ(kept.hessian, from_deviations.hessian);
  const double q_other = twin.quality(y, other);
  EXPECT_NEAR(kept.value, q_other * q_other, 1e-12);
  double error = 1.0;
  const MatrixX points = other.replicate(1, 3) + MatrixX::Random(4, 3) * 0.5;
  EXPECT_EQ(deviations.check(y, kept, points, error), 3U);
  EXPECT_LT(error, 1e-10);
  for (Index k = 2; k < deviations.options().hessian_refresh; ++k) {
    EXPECT_EQ(deviations.fit(y, other, kept), 1U) << k;
  }
  EXPECT_TRUE(deviations.hessian_stale());
  EXPECT_EQ(deviations.fit(y, other, kept), 9U);
  deviations.invalidate_hessian();
  EXPECT_EQ(deviations.fit(y, other, kept), 9U);
}

// A snapshot keeps J: the restored surrogate fits the next assembly as the original does; a
// snapshot without J (saved from Q²) or with a bad one is refused, naming the field.
TEST(QuadraticSurrogateFromDeviations, ASnapshotKeepsTheJacobian) {
  const KeyPointTwin<NoNonlinearity> twin = affine_key_points();
  QuadraticSurrogate<KeyPointTwin<NoNonlinearity>, Dynamic> original(twin);
  QuadraticModel<Dynamic> model;
  const AssemblyId x{1, 2};
  static_cast<void>(original.fit(x, twin.optimum(x), model));
  const nlohmann::json saved = nlohmann::json::parse(original.save().dump());
  ASSERT_TRUE(saved.contains("jacobian"));
  QuadraticSurrogate<KeyPointTwin<NoNonlinearity>, Dynamic> restored(twin);
  restored.restore(saved);
  const VectorX center = twin.optimum(x) + VectorX::Constant(4, 0.1);
  QuadraticModel<Dynamic> expected;
  QuadraticModel<Dynamic> actual;
  EXPECT_EQ(original.fit(x, center, expected), 1U);
  EXPECT_EQ(restored.fit(x, center, actual), 1U);
  EXPECT_EQ(actual.value, expected.value);
  EXPECT_EQ(actual.half_gradient, expected.half_gradient);
  EXPECT_EQ(actual.hessian, expected.hessian);

  QuadraticSurrogate<KeyPointTwin<NoNonlinearity>, Dynamic> squares(
      twin, QuadraticSurrogateOptions{.from_deviations = false});
  static_cast<void>(squares.fit(x, twin.optimum(x), model));
  EXPECT_FALSE(squares.save().contains("jacobian"));
  const nlohmann::json kept = restored.save();
  EXPECT_THAT([&] { restored.restore(squares.save()); },
              ::testing::ThrowsMessage<InvalidArgumentError>(::testing::HasSubstr("jacobian")));
  nlohmann::json bad = saved;
  bad["jacobian"][0][0] = "x";
  EXPECT_THAT([&] { restored.restore(bad); },
              ::testing::ThrowsMessage<InvalidArgumentError>(::testing::HasSubstr("jacobian[0]")));
  EXPECT_EQ(restored.save(), kept);
}

// A refit from the deviations fits H where the entry is now used; the H it is given (the
// entry's old one) is not used.
TEST(QuadraticSurrogateFromDeviations, RefitsItsOwnHessian) {
  const KeyPointTwin<NoNonlinearity> twin = affine_key_points();
  QuadraticSurrogate<KeyPointTwin<NoNonlinearity>, Dynamic> surrogate(twin);
  const AssemblyId x{1, 1};
  QuadraticModel<Dynamic> own;
  static_cast<void>(surrogate.fit(x, twin.optimum(x), own));
  const nlohmann::json before = surrogate.save();
  QuadraticModel<Dynamic> refitted;
  const VectorX center = twin.optimum(x) + VectorX::LinSpaced(4, -0.2, 0.3);
  EXPECT_EQ(surrogate.refit_gradient(x, center, MatrixX::Identity(4, 4), refitted), 9U);
  EXPECT_EQ(surrogate.save(), before);  // its own J, H and age are untouched
  EXPECT_LT((refitted.hessian - own.hessian).cwiseAbs().maxCoeff(), 1e-9);
  const VectorX gradient = own.hessian * (center - twin.optimum(x));  // ∇Q²/2 of a quadratic
  EXPECT_LT((refitted.half_gradient - gradient).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_THROW(
      static_cast<void>(surrogate.refit_gradient(x, center, MatrixX::Identity(3, 3), refitted)),
      DimensionMismatchError);
}

// The key-point twin with one deviation that is NaN at the last control of every batch.
class NanDeviationTwin : public KeyPointTwin<NoNonlinearity> {
 public:
  explicit NanDeviationTwin(KeyPointTwin<NoNonlinearity> twin)
      : KeyPointTwin<NoNonlinearity>(std::move(twin)) {}
  void deviations_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const {
    KeyPointTwin<NoNonlinearity>::deviations_batch(assembly, controls, out);
    out(3, controls.cols() - 1) = std::numeric_limits<double>::quiet_NaN();
  }
};

TEST(QuadraticSurrogateFromDeviations, RefusesANonFiniteDeviationAndKeepsItsState) {
  const NanDeviationTwin twin(affine_key_points());
  QuadraticSurrogate<NanDeviationTwin, 4> surrogate(twin);
  ASSERT_TRUE(surrogate.uses_deviations());
  const nlohmann::json before = surrogate.save();
  QuadraticModel<4> model;
  try {
    static_cast<void>(surrogate.fit(AssemblyId{0, 0}, Vector<4>::Zero(), model));
    FAIL() << "expected NonFiniteError";
  } catch (const NonFiniteError& error) {
    EXPECT_NE(std::string(error.what()).find("column 8"), std::string::npos) << error.what();
  }
  EXPECT_EQ(surrogate.save(), before);
}

// A twin that answers only Q (the RMS-quadratic analytic twin) is fitted from Q².
TEST(QuadraticSurrogateFromDeviations, FitsFromTheQualityWhereTheTwinHasNoKeyPoints) {
  const test_support::AnalyticTwin twin = test_support::make_twin(4);
  QuadraticSurrogate<test_support::AnalyticTwin, Dynamic> surrogate(twin);
  EXPECT_FALSE(surrogate.uses_deviations());
  QuadraticModel<Dynamic> model;
  EXPECT_EQ(surrogate.fit(AssemblyId{0, 0}, twin.optimum(AssemblyId{0, 0}), model), 15U);
}

// The step follows the model's source: step_fraction of the box from the deviations,
// quality_step_fraction from Q² (a twin without key points, or from_deviations off).
TEST(QuadraticSurrogateFromDeviations, StepsByTheModelsSource) {
  const KeyPointTwin<NoNonlinearity> twin = affine_key_points();
  const VectorX width = twin.upper_bounds() - twin.lower_bounds();
  const QuadraticSurrogateOptions options{.step_fraction = 0.04, .quality_step_fraction = 0.01};
  const QuadraticSurrogate<KeyPointTwin<NoNonlinearity>, Dynamic> from_deviations(twin, options);
  ASSERT_TRUE(from_deviations.uses_deviations());
  EXPECT_EQ(from_deviations.steps(), VectorX(0.04 * width));
  QuadraticSurrogateOptions quality = options;
  quality.from_deviations = false;
  const QuadraticSurrogate<KeyPointTwin<NoNonlinearity>, Dynamic> from_squares(twin, quality);
  ASSERT_FALSE(from_squares.uses_deviations());
  EXPECT_EQ(from_squares.steps(), VectorX(0.01 * width));
  const test_support::AnalyticTwin analytic = test_support::make_twin(4);
  const QuadraticSurrogate<test_support::AnalyticTwin, Dynamic> only_quality(analytic, options);
  EXPECT_EQ(only_quality.steps(),
            VectorX(0.01 * (analytic.upper_bounds() - analytic.lower_bounds())));
}

TEST(QuadraticSurrogate, OptionsNameTheRuleTheyBreak) {
  EXPECT_EQ(QuadraticSurrogateOptions{.step_fraction = 0.0}.validate(),
            "step_fraction: value is 0; rule: must lie in (0, 0.5]");
  EXPECT_EQ(QuadraticSurrogateOptions{.quality_step_fraction = 0.6}.validate(),
            "quality_step_fraction: value is 0.6; rule: must lie in (0, 0.5]");
  EXPECT_EQ(QuadraticSurrogateOptions{.hessian_refresh = 0}.validate(),
            "hessian_refresh: value is 0; rule: must be >= 1");
}

}  // namespace
}  // namespace twincal
