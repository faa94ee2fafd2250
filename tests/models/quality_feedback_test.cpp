#include "twincal/models/quality_feedback.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/random_stream.hpp"
#include "twincal/models/evaluator.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal {
namespace {

constexpr Index kDimension = 3;

RmsQuadraticTwin make_feedback_twin() {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = kDimension;
  return RmsQuadraticTwin::generate(options, RandomStream(2023));
}

// Q(x, v) written out: sqrt(q0 + (v − a)ᵀ H (v − a)).
double expected_quality(const RmsQuadraticTwin& twin, const AssemblyId& x, const VectorX& v) {
  const VectorX e = v - twin.optimum(x);
  return std::sqrt(twin.assembly_set().q0(x) + e.dot(twin.curvature() * e));
}

template <typename Model>
class QualityFeedbackTest : public ::testing::Test {
 protected:
  static constexpr int N = Model::dimension_at_compile_time;
  using State = Vector<N>;

  RmsQuadraticTwin twin_ = make_feedback_twin();
  Evaluator<RmsQuadraticTwin> evaluator_{twin_};

  static State state(double a, double b, double c) {
    State s(kDimension);
    s << a, b, c;
    return s;
  }
};

template <int N>
using Feedback = QualityFeedback<Evaluator<RmsQuadraticTwin>, N>;
using Models = ::testing::Types<Feedback<3>, Feedback<Dynamic>>;
TYPED_TEST_SUITE(QualityFeedbackTest, Models);

// That QualityFeedback (these Models included) has the filters' MeasurementModel shape is checked
// at compile time in tests/static/models_check.cpp.
TYPED_TEST(QualityFeedbackTest, MeetsTheMeasurementModelShape) {
  const TypeParam model(this->evaluator_, 1e-4);
  EXPECT_EQ(model.noise_variance(), 1e-4);
  EXPECT_EQ(model.dimension(), kDimension);
}

TYPED_TEST(QualityFeedbackTest, MeasuresTheQualityAtTheCorrectedControl) {
  // eq. (5b) under Assumption 1: h(δu; x, u) = Q(x, u − δu).
  const TypeParam model(this->evaluator_, 1e-4);
  const AssemblyId x{3, 7};
  const typename TestFixture::State u = this->state(0.1, -0.2, 0.05);
  const typename TestFixture::State offset = this->state(0.02, 0.03, -0.04);
  const typename TypeParam::Inputs inputs{x, u};
  EXPECT_DOUBLE_EQ(model.measure(offset, inputs), expected_quality(this->twin_, x, u - offset));
  // At δu = u − u0(x) the corrected control is the optimum: h = z*(x).
  const typename TypeParam::StateVector at_optimum = u - this->twin_.optimum(x);
  EXPECT_DOUBLE_EQ(model.measure(at_optimum, inputs), this->twin_.optimal_quality(x));
}

TYPED_TEST(QualityFeedbackTest, BatchEvaluatesAllSigmaPointsInOneTwinCall) {
  const TypeParam model(this->evaluator_, 1e-4);
  const AssemblyId x{0, 9};
  const typename TypeParam::Inputs inputs{x, this->state(0.05, 0.1, -0.1)};
  MatrixX states(kDimension, 7);
  RandomStream stream(5);
  stream.fill_normal(states);
  states *= 0.1;
  VectorX out(7);
  this->evaluator_.reset_stats();
  model.measure_batch(states, inputs, out);
  EXPECT_EQ(this->evaluator_.stats().calls, 1U);
  EXPECT_EQ(this->evaluator_.stats().evaluations, 7U);
  for (Index j = 0; j < 7; ++j) {
    const typename TypeParam::StateVector s = states.col(j);
    EXPECT_DOUBLE_EQ(out(j), model.measure(s, inputs)) << "sigma point " << j;
  }
}

TYPED_TEST(QualityFeedbackTest, GridEvaluatesCandidatesTimesSigmaPointsInOneTwinCall) {
  const TypeParam model(this->evaluator_, 1e-4);
  const AssemblyId x{4, 4};
  constexpr Index kCandidates = 5;
  constexpr Index kPoints = 7;
  MatrixX candidates(kDimension, kCandidates);
  MatrixX states(kDimension, kPoints);
  RandomStream stream(6);
  stream.fill_normal(candidates);
  stream.fill_normal(states);
  states *= 0.05;
  MatrixX out(kPoints, kCandidates);
  this->evaluator_.reset_stats();
  model.measure_grid(x, candidates, states, out);
  EXPECT_EQ(this->evaluator_.stats().calls, 1U);
  EXPECT_EQ(this->evaluator_.stats().evaluations,
            static_cast<std::uint64_t>(kPoints * kCandidates));
  for (Index c = 0; c < kCandidates; ++c) {
    const typename TypeParam::Inputs inputs{x, candidates.col(c)};
    VectorX column(kPoints);
    model.measure_batch(states, inputs, column);
    EXPECT_EQ(out.col(c), column) << "candidate " << c;
  }
  // A strided output (a block of a larger matrix) receives the same values.
  MatrixX larger = MatrixX::Zero(kPoints + 2, kCandidates);
  model.measure_grid(x, candidates, states, larger.topRows(kPoints));
  EXPECT_EQ(larger.topRows(kPoints), out);
  EXPECT_TRUE(larger.bottomRows(2).isZero(0.0));
}

TYPED_TEST(QualityFeedbackTest, RepeatedBatchesOfChangingSizeStayCorrect) {
  // The per-thread workspace grows and is reused; results must not depend on its history.
  const TypeParam model(this->evaluator_, 1e-4);
  const typename TypeParam::Inputs inputs{AssemblyId{1, 1}, this->state(0.0, 0.0, 0.0)};
  for (const Index k : {Index{9}, Index{2}, Index{13}, Index{1}}) {
    const MatrixX states = MatrixX::Constant(kDimension, k, 0.01 * static_cast<double>(k));
    VectorX out(k);
    model.measure_batch(states, inputs, out);
    const typename TypeParam::StateVector s = states.col(0);
    EXPECT_TRUE(out.isConstant(model.measure(s, inputs), 0.0)) << "k = " << k;
  }
}

TYPED_TEST(QualityFeedbackTest, RejectsBadArguments) {
  EXPECT_THAT([this] { (void)TypeParam(this->evaluator_, 0.0); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "noise_variance: value is 0; rule: must be > 0"));
  EXPECT_THROW((void)TypeParam(this->evaluator_, std::nan("")), NonFiniteError);
  const TypeParam model(this->evaluator_, 1e-4);
  const typename TypeParam::Inputs inputs{AssemblyId{0, 0}, this->state(0.0, 0.0, 0.0)};
  VectorX out(3);
  EXPECT_THAT(
      [&] { model.measure_batch(MatrixX::Zero(2, 3), inputs, out); },
      ::testing::ThrowsMessage<DimensionMismatchError>("states: rows is 2; rule: must equal 3"));
  EXPECT_THAT(
      [&] { model.measure_batch(MatrixX::Zero(3, 4), inputs, out); },
      ::testing::ThrowsMessage<DimensionMismatchError>("out: size is 3; rule: must equal 4"));
  MatrixX grid(4, 2);
  EXPECT_THAT(
      [&] {
        model.measure_grid(AssemblyId{0, 0}, MatrixX::Zero(3, 2), MatrixX::Zero(3, 3), grid);
      },
      ::testing::ThrowsMessage<DimensionMismatchError>("out: is 4x2; rule: must be 3x2"));
}

TEST(QualityFeedback, DynamicModelRejectsMismatchedSizes) {
  const RmsQuadraticTwin twin = make_feedback_twin();
  const QualityFeedback<RmsQuadraticTwin> model(twin, 1e-6);
  const QualityFeedback<RmsQuadraticTwin>::Inputs inputs{AssemblyId{0, 0}, VectorX::Zero(3)};
  EXPECT_THAT(
      [&] { (void)model.measure(VectorX::Zero(2), inputs); },
      ::testing::ThrowsMessage<DimensionMismatchError>("state: size is 2; rule: must equal 3"));
  const QualityFeedback<RmsQuadraticTwin>::Inputs short_control{AssemblyId{0, 0}, VectorX::Zero(4)};
  EXPECT_THAT([&] { (void)model.measure(VectorX::Zero(3), short_control); },
              ::testing::ThrowsMessage<DimensionMismatchError>(
                  "inputs.control: size is 4; rule: must equal 3"));
}

TEST(QualityFeedback, FixedDimensionMustMatchTheTwin) {
  const RmsQuadraticTwin twin = make_feedback_twin();
  EXPECT_THAT([&] { (void)(QualityFeedback<RmsQuadraticTwin, 2>(twin, 1e-6)); },
              ::testing::ThrowsMessage<DimensionMismatchError>(
                  "twin.control_dimension(): size is 3; rule: must equal 2"));
}

}  // namespace
}  // namespace twincal
