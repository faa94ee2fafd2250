#include "twincal/models/evaluator.hpp"

#include <atomic>
#include <chrono>
#include <latch>
#include <limits>
#include <stdexcept>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/random_stream.hpp"
#include "twincal/models/parallel_execution.hpp"
#include "twincal/models/quality_feedback.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

// A twin whose assembly is an int telling it how to behave:
//   ≥ 0: Q = assembly + Σ_i (i + 1) u_i (distinct per column, order-sensitive)
//   −1: throws std::runtime_error;  −2: NaN for columns with u_0 > 0;  −3: +∞ likewise;
//   −4: sleeps `sleep` per call, then behaves like 0.
// It counts its calls and the controls it evaluated. Its three "deviations" are (Q, u_0, u_1)
// with the same behaviours (−2: a NaN u_0 entry), a pattern to check the passing on, not an RMS.
struct ScriptedTwin {
  using Assembly = int;
  std::vector<std::string> names{"A", "B"};
  VectorX lower = VectorX::Constant(2, -1.0);
  VectorX upper = VectorX::Constant(2, 1.0);
  std::chrono::milliseconds sleep{0};
  mutable std::atomic<int> calls{0};
  mutable std::atomic<int> evaluated{0};

  [[nodiscard]] Index control_dimension() const { return 2; }
  [[nodiscard]] const std::vector<std::string>& locator_names() const { return names; }
  [[nodiscard]] const VectorX& lower_bounds() const { return lower; }
  [[nodiscard]] const VectorX& upper_bounds() const { return upper; }

  [[nodiscard]] static double value(int assembly, const Eigen::Ref<const VectorX>& u) {
    return std::max(assembly, 0) + u(0) + 2.0 * u(1);
  }
  [[nodiscard]] double quality(int assembly, const Eigen::Ref<const VectorX>& u) const {
    VectorX out(1);
    quality_batch(assembly, u, out);
    return out(0);
  }
  void quality_batch(int assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    calls.fetch_add(1);
    evaluated.fetch_add(static_cast<int>(controls.cols()));
    if (assembly == -1) throw std::runtime_error("mesh generation failed");
    if (assembly == -4) std::this_thread::sleep_for(sleep);
    for (Index j = 0; j < controls.cols(); ++j) {
      out(j) = value(assembly, controls.col(j));
      if (controls(0, j) > 0.0 && assembly == -2) out(j) = std::nan("");
      if (controls(0, j) > 0.0 && assembly == -3) out(j) = std::numeric_limits<double>::infinity();
    }
  }
  [[nodiscard]] Index key_point_count() const { return 3; }
  void deviations_batch(int assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const {
    VectorX values(controls.cols());
    quality_batch(assembly, controls, values);
    out.row(0) = values.transpose();
    out.bottomRows(2) = controls;
    for (Index j = 0; j < controls.cols(); ++j) {
      if (controls(0, j) > 0.0 && assembly == -2) out(1, j) = std::nan("");
    }
  }
};
static_assert(TwinWithDeviations<ScriptedTwin>);

MatrixX random_controls(Index k, std::uint64_t seed) {
  MatrixX controls(2, k);
  RandomStream(seed).fill_normal(controls);
  return controls;
}

template <typename Execution>
Execution make_execution();
template <>
SerialExecution make_execution<SerialExecution>() {
  return {};
}
template <>
ParallelExecution make_execution<ParallelExecution>() {
  return ParallelExecution(3, 2);
}

template <typename E>
class EvaluatorTest : public ::testing::Test {
 protected:
  ScriptedTwin twin_;
};
using Executions = ::testing::Types<SerialExecution, ParallelExecution>;
TYPED_TEST_SUITE(EvaluatorTest, Executions);

TYPED_TEST(EvaluatorTest, ResultsAreInInputOrderAndCounted) {
  const Evaluator<ScriptedTwin, TypeParam> evaluator(this->twin_, make_execution<TypeParam>());
  std::uint64_t total = 0;
  for (const Index k : {Index{1}, Index{5}, Index{7}, Index{100}}) {
    const MatrixX controls = random_controls(k, static_cast<std::uint64_t>(k));
    VectorX out(k);
    evaluator.quality_batch(4, controls, out);
    for (Index j = 0; j < k; ++j) {
      EXPECT_EQ(out(j), ScriptedTwin::value(4, controls.col(j))) << "k = " << k << ", j = " << j;
    }
    total += static_cast<std::uint64_t>(k);
  }
  EXPECT_EQ(evaluator.quality(2, Eigen::Vector2d(0.5, 0.25)), 3.0);
  const EvaluationStats stats = evaluator.stats();
  EXPECT_EQ(stats.calls, 5U);
  EXPECT_EQ(stats.evaluations, total + 1);
  EXPECT_GT(stats.elapsed.count(), 0);
  EXPECT_EQ(this->twin_.evaluated.load(), static_cast<int>(total + 1));
}

TYPED_TEST(EvaluatorTest, MemoizesRepeatedAssemblyAndControl) {
  const Evaluator<ScriptedTwin, TypeParam> evaluator(this->twin_, make_execution<TypeParam>(),
                                                     {.memoize = true});
  const MatrixX controls = random_controls(6, 1);
  VectorX first(6);
  evaluator.quality_batch(1, controls, first);
  EXPECT_EQ(this->twin_.evaluated.load(), 6);
  // Same pairs: answered from the cache, no twin call.
  VectorX again(6);
  const int calls_before = this->twin_.calls.load();
  evaluator.quality_batch(1, controls, again);
  EXPECT_EQ(again, first);
  EXPECT_EQ(this->twin_.calls.load(), calls_before);
  EXPECT_EQ(evaluator.cache_hits(), 6U);
  // A mixed batch: only the new controls and the new assembly reach the twin, in order.
  MatrixX mixed(2, 3);
  mixed << controls.col(2), Eigen::Vector2d(0.1, 0.2), controls.col(4);
  VectorX out(3);
  evaluator.quality_batch(1, mixed, out);
  EXPECT_EQ(out(0), first(2));
  EXPECT_EQ(out(1), ScriptedTwin::value(1, Eigen::Vector2d(0.1, 0.2)));
  EXPECT_EQ(out(2), first(4));
  EXPECT_EQ(this->twin_.evaluated.load(), 7);
  evaluator.quality_batch(2, mixed, out);  // another assembly: all new
  EXPECT_EQ(this->twin_.evaluated.load(), 10);
  EXPECT_EQ(evaluator.cache_size(), 10U);
  EXPECT_EQ(evaluator.stats().evaluations, 10U);
  EXPECT_EQ(evaluator.stats().calls, 4U);
  evaluator.clear_cache();
  evaluator.quality_batch(1, controls, again);
  EXPECT_EQ(this->twin_.evaluated.load(), 16);
}

TYPED_TEST(EvaluatorTest, ATwinThatThrowsGivesATypedErrorWithTheCause) {
  const Evaluator<ScriptedTwin, TypeParam> evaluator(this->twin_, make_execution<TypeParam>());
  const MatrixX controls = (MatrixX(2, 1) << 0.5, -0.25).finished();
  VectorX out(1);
  try {
    evaluator.quality_batch(-1, controls, out);
    FAIL() << "expected TwinEvaluationError";
  } catch (const TwinEvaluationError<int>& error) {
    EXPECT_EQ(error.failure(), EvaluationFailure::twin_threw);
    EXPECT_EQ(error.assembly(), -1);
    EXPECT_EQ(error.controls(), controls);
    EXPECT_FALSE(error.column().has_value());
    EXPECT_STREQ(error.what(),
                 "quality: the twin threw for assembly -1, control [0.5, -0.25]: mesh "
                 "generation failed");
    try {
      std::rethrow_if_nested(error);
      FAIL() << "expected a nested cause";
    } catch (const std::runtime_error& cause) {
      EXPECT_STREQ(cause.what(), "mesh generation failed");
    }
  }
  EXPECT_EQ(evaluator.stats().calls, 1U);  // a failed call still counts
}

TYPED_TEST(EvaluatorTest, NonFiniteQualitiesAreReportedWithTheirControl) {
  const Evaluator<ScriptedTwin, TypeParam> evaluator(this->twin_, make_execution<TypeParam>(),
                                                     {.memoize = true});
  // Only column 3 has u_0 > 0.
  MatrixX controls = MatrixX::Constant(2, 5, -0.5);
  controls(0, 3) = 0.5;
  VectorX out(5);
  EXPECT_THAT([&] { evaluator.quality_batch(-2, controls, out); },
              ::testing::Throws<EvaluationError>(
                  ::testing::Property(&EvaluationError::failure, EvaluationFailure::non_finite)));
  try {
    evaluator.quality_batch(-3, controls, out);
    FAIL() << "expected TwinEvaluationError";
  } catch (const TwinEvaluationError<int>& error) {
    ASSERT_TRUE(error.column().has_value());
    EXPECT_EQ(error.controls().col(*error.column()), controls.col(3));
    EXPECT_THAT(error.what(), HasSubstr("quality: non-finite quality for assembly -3, control "
                                        "[0.5, -0.5] (column "));
    EXPECT_THAT(error.what(), HasSubstr("value is inf; rule: must be finite"));
  }
  // Failed values are not cached: the retry reaches the twin again.
  const int before = this->twin_.evaluated.load();
  EXPECT_THROW(evaluator.quality_batch(-3, controls, out), EvaluationError);
  EXPECT_GT(this->twin_.evaluated.load(), before);
}

// The deviations are passed on in input order, counted like qualities, and checked: a twin
// that throws or a non-finite deviation is a TwinEvaluationError naming the failure.
TYPED_TEST(EvaluatorTest, PassesTheDeviationsOnCountedAndChecked) {
  const Evaluator<ScriptedTwin, TypeParam> evaluator(this->twin_, make_execution<TypeParam>());
  ASSERT_EQ(evaluator.key_point_count(), 3);
  const MatrixX controls = random_controls(7, 4);
  MatrixX out(3, 7);
  evaluator.deviations_batch(2, controls, out);
  for (Index j = 0; j < 7; ++j) {
    EXPECT_EQ(out(0, j), ScriptedTwin::value(2, controls.col(j)));
    EXPECT_EQ(out.col(j).tail(2), controls.col(j));
  }
  EXPECT_EQ(evaluator.stats().evaluations, 7U);
  EXPECT_EQ(evaluator.stats().calls, 1U);
  MatrixX wrong(2, 7);
  EXPECT_THROW(evaluator.deviations_batch(2, controls, wrong), DimensionMismatchError);
  EXPECT_THROW(evaluator.deviations_batch(-1, controls, out), TwinEvaluationError<int>);
  MatrixX signs = MatrixX::Constant(2, 3, -0.5);
  signs(0, 2) = 0.5;
  try {
    evaluator.deviations_batch(-2, signs, out.leftCols(3));
    FAIL() << "a NaN deviation was passed on";
  } catch (const TwinEvaluationError<int>& error) {
    EXPECT_EQ(error.failure(), EvaluationFailure::non_finite);
    EXPECT_THAT(error.what(), HasSubstr("a deviation is not finite"));
  }
}

TYPED_TEST(EvaluatorTest, ASlowTwinExceedsTheTimeLimit) {
  this->twin_.sleep = std::chrono::milliseconds{150};
  const Evaluator<ScriptedTwin, TypeParam> evaluator(this->twin_, make_execution<TypeParam>(),
                                                     {.time_limit = std::chrono::milliseconds{50}});
  VectorX out(2);
  try {
    evaluator.quality_batch(-4, random_controls(2, 3), out);
    FAIL() << "expected TwinEvaluationError";
  } catch (const TwinEvaluationError<int>& error) {
    EXPECT_EQ(error.failure(), EvaluationFailure::time_limit);
    EXPECT_THAT(error.what(), HasSubstr("quality: time limit exceeded for assembly -4"));
    EXPECT_THAT(error.what(), HasSubstr("rule: must finish within 0.05 s"));
  }
  // A fast call passes under the same limit.
  evaluator.quality_batch(0, random_controls(2, 3), out);
}

TEST(ParallelExecution, RunsRangesConcurrently) {
  // Each range waits until both have started: this completes only if they run at once.
  const ParallelExecution execution(2);
  std::latch both(2);
  std::atomic<int> covered{0};
  execution.run(10, [&](Index, Index count) {
    both.arrive_and_wait();
    covered.fetch_add(static_cast<int>(count));
  });
  EXPECT_EQ(covered.load(), 10);
}

TEST(ParallelExecution, RethrowsTheFirstFailingRangeAfterAllFinished) {
  const ParallelExecution execution(2, 3);  // 6 ranges of 2 for 12 columns
  std::atomic<int> finished{0};
  try {
    execution.run(12, [&](Index begin, Index) {
      finished.fetch_add(1);
      if (begin == 6 || begin == 10) throw std::runtime_error(fmt::format("range {}", begin));
    });
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "range 6");
  }
  EXPECT_EQ(finished.load(), 6);
  EXPECT_THAT([] { (void)ParallelExecution(0); }, ::testing::ThrowsMessage<InvalidArgumentError>(
                                                      "threads: value is 0; rule: must be >= 1"));
}

TEST(Evaluator, ParallelFailureNamesTheFailingRange) {
  const ScriptedTwin twin;
  const Evaluator<ScriptedTwin, ParallelExecution> evaluator(twin, ParallelExecution(2));
  MatrixX controls = MatrixX::Constant(2, 8, -0.5);
  controls(0, 6) = 0.5;  // in the second range, [4, 8)
  VectorX out(8);
  try {
    evaluator.quality_batch(-2, controls, out);
    FAIL() << "expected TwinEvaluationError";
  } catch (const TwinEvaluationError<int>& error) {
    EXPECT_EQ(error.controls(), controls.rightCols(4));
    EXPECT_EQ(error.column(), 2);
  }
}

TEST(Evaluator, RejectsInvalidOptions) {
  const ScriptedTwin twin;
  EXPECT_THAT(
      [&] { (void)Evaluator<ScriptedTwin>(twin, {}, {.time_limit = std::chrono::nanoseconds{0}}); },
      ::testing::ThrowsMessage<InvalidArgumentError>(
          "options: time_limit: value is 0; rule: must be > 0 (ns)"));
  struct Unhashable {
    int id = 0;
  };
  struct UnhashableTwin : ScriptedTwin {
    using Assembly = Unhashable;
    [[nodiscard]] double quality(const Unhashable&, const Eigen::Ref<const VectorX>&) const {
      return 0.0;
    }
    void quality_batch(const Unhashable&, const Eigen::Ref<const MatrixX>&,
                       Eigen::Ref<VectorX> out) const {
      out.setZero();
    }
  };
  static_assert(Twin<UnhashableTwin>);
  const UnhashableTwin unhashable;
  EXPECT_THAT([&] { (void)Evaluator<UnhashableTwin>(unhashable, {}, {.memoize = true}); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "options.memoize: is true; rule: the twin's Assembly type needs std::hash and "
                  "== to be memoized"));
  const Evaluator<ScriptedTwin> evaluator(twin);
  VectorX out(3);
  EXPECT_THAT(
      [&] { evaluator.quality_batch(0, MatrixX::Zero(2, 2), out); },
      ::testing::ThrowsMessage<DimensionMismatchError>("out: size is 3; rule: must equal 2"));
}

TEST(Evaluator, ComposesWithQualityFeedbackAndAnalyticTwins) {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = 3;
  const RmsQuadraticTwin twin = RmsQuadraticTwin::generate(options, RandomStream(1));
  const Evaluator<RmsQuadraticTwin, ParallelExecution> evaluator(twin, ParallelExecution(2));
  const QualityFeedback<Evaluator<RmsQuadraticTwin, ParallelExecution>, 3> model(evaluator, 1e-4);
  MatrixX states(3, 7);
  RandomStream(2).fill_normal(states);
  VectorX out(7);
  model.measure_batch(states, {AssemblyId{1, 2}, Eigen::Vector3d(0.1, 0.0, -0.1)}, out);
  for (Index j = 0; j < 7; ++j) {
    EXPECT_EQ(out(j), twin.quality({1, 2}, Eigen::Vector3d(0.1, 0.0, -0.1) - states.col(j)));
  }
  EXPECT_EQ(evaluator.stats().calls, 1U);
  EXPECT_EQ(evaluator.stats().evaluations, 7U);
  // The twin's exact optimum passes through uncounted (it is not an evaluation of Q).
  EXPECT_EQ(evaluator.optimum({1, 2}), twin.optimum({1, 2}));
  EXPECT_EQ(evaluator.optimal_quality({1, 2}), twin.optimal_quality({1, 2}));
  EXPECT_EQ(evaluator.stats().calls, 1U);
}

}  // namespace
}  // namespace twincal
