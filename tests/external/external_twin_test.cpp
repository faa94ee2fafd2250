#include "twincal/external/external_twin.hpp"

#include <signal.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/stopwatch.hpp"
#include "twincal/models/evaluator.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;
using json = nlohmann::json;

// tests/data/script_twin.py: Q = sqrt(q0 + Σ (u_i − a_i)²), misbehaving on request.
ExternalTwinOptions script_options() {
  ExternalTwinOptions options;
  options.command = {TWINCAL_TEST_DATA_DIR "/script_twin.py"};
  options.locator_names = {"A", "B"};
  // Generous: these bound only failures, and the machine may be loaded or sanitized.
  options.timeout = std::chrono::milliseconds{5000};
  options.startup_grace = std::chrono::milliseconds{10000};
  return options;
}

const json kAssembly = {{"q0", 0.25}, {"a", {0.1, -0.2}}};

json misbehaving(const std::string& mode) {
  return {{"q0", 0.25}, {"a", {0.1, -0.2}}, {"mode", mode}};
}

double expected(const VectorX& u) {
  return std::sqrt(0.25 + std::pow(u(0) - 0.1, 2) + std::pow(u(1) + 0.2, 2));
}

ExternalTwinFailure failure_of(const ExternalTwin& twin, const json& assembly, Index k = 2) {
  VectorX out(k);
  try {
    twin.quality_batch(assembly, MatrixX::Zero(2, k), out);
  } catch (const ExternalTwinError& error) {
    return error.failure();
  }
  ADD_FAILURE() << "expected an ExternalTwinError";
  return ExternalTwinFailure::start_failed;
}

pid_t pid_of(const ExternalTwin& twin) {
  return static_cast<pid_t>(twin.quality(misbehaving("pid"), VectorX::Zero(2)));
}

TEST(ExternalTwin, EvaluatesABatchOverTheLineProtocol) {
  const ExternalTwin twin(script_options());
  static_assert(Twin<ExternalTwin>);
  EXPECT_EQ(twin.control_dimension(), 2);
  EXPECT_THAT(twin.locator_names(), ::testing::ElementsAre("A", "B"));
  EXPECT_TRUE(std::isinf(twin.lower_bounds()(0)));
  MatrixX controls(2, 4);
  controls << 0.1, 0.3, -1.0 / 3.0, 1e-17, -0.2, 0.0, 2.0 / 7.0, -5.5;
  VectorX out(4);
  twin.quality_batch(kAssembly, controls, out);
  for (Index j = 0; j < 4; ++j) {
    // JSON numbers round-trip doubles exactly both ways, so only Python's arithmetic differs.
    EXPECT_NEAR(out(j), expected(controls.col(j)), 1e-15 * expected(controls.col(j)))
        << "column " << j;
  }
  EXPECT_EQ(out(0), 0.5);
  EXPECT_EQ(twin.quality(kAssembly, Eigen::Vector2d(0.1, -0.2)), 0.5);
}

TEST(ExternalTwin, KeepsOneLongLivedChild) {
  const ExternalTwin twin(script_options());
  const pid_t first = pid_of(twin);
  EXPECT_EQ(twin.process_id(), first);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(pid_of(twin), first);
  EXPECT_EQ(twin.starts(), 1);
}

TEST(ExternalTwin, RestartsAChildThatCrashed) {
  const ExternalTwin twin(script_options());
  const pid_t first = pid_of(twin);
  VectorX out(2);
  try {
    twin.quality_batch(misbehaving("crash"), MatrixX::Zero(2, 2), out);
    FAIL() << "expected ExternalTwinError";
  } catch (const ExternalTwinError& error) {
    EXPECT_EQ(error.failure(), ExternalTwinFailure::crashed);
    EXPECT_EQ(error.controls(), MatrixX::Zero(2, 2));
    EXPECT_THAT(error.assembly(), HasSubstr("\"mode\":\"crash\""));
    EXPECT_THAT(error.what(),
                HasSubstr("twin: external twin crashed: end of output before a complete reply; "
                          "the child exited with status 3 (request: assembly {"));
  }
  EXPECT_FALSE(twin.process_id().has_value());
  const pid_t second = pid_of(twin);
  EXPECT_NE(second, first);
  EXPECT_EQ(twin.starts(), 2);
  EXPECT_EQ(twin.quality(kAssembly, Eigen::Vector2d(0.1, -0.2)), 0.5);
}

TEST(ExternalTwin, KillsAndRestartsAChildThatSendsGarbage) {
  const ExternalTwin twin(script_options());
  const pid_t first = pid_of(twin);
  VectorX out(2);
  try {
    twin.quality_batch(misbehaving("garbage"), MatrixX::Zero(2, 2), out);
    FAIL() << "expected ExternalTwinError";
  } catch (const ExternalTwinError& error) {
    EXPECT_EQ(error.failure(), ExternalTwinFailure::malformed_reply);
    EXPECT_THAT(error.what(),
                HasSubstr("twin: external twin malformed reply: the reply is not JSON: \"this is "
                          "not json\"; the child was killed by signal 9 and will be restarted"));
  }
  EXPECT_NE(pid_of(twin), first);
}

// Replies that once escaped as an unnamed parser error or could exhaust the stack: nesting
// beyond the bound, bytes that are not UTF-8 (quoted back as U+FFFD, so the message itself is
// valid text). Both are malformed replies: the child is restarted.
TEST(ExternalTwin, NamesADeepOrNonUtf8ReplyAndRestartsTheChild) {
  const ExternalTwin twin(script_options());
  VectorX out(2);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"deep", "malformed reply: the reply nests deeper than 64 arrays and objects: \"[[[["},
      {"bad_utf8", "malformed reply: the reply is not JSON: \"{\\\"id\\\": "}};
  for (const auto& [mode, message] : cases) {
    const pid_t before = pid_of(twin);
    try {
      twin.quality_batch(misbehaving(mode), MatrixX::Zero(2, 2), out);
      FAIL() << mode << ": expected ExternalTwinError";
    } catch (const ExternalTwinError& error) {
      EXPECT_EQ(error.failure(), ExternalTwinFailure::malformed_reply) << mode;
      EXPECT_THAT(error.what(), HasSubstr(message)) << mode;
      // The message is text a JSON writer takes as it is.
      EXPECT_NO_THROW(static_cast<void>(nlohmann::json(std::string(error.what())).dump()));
    }
    EXPECT_NE(pid_of(twin), before) << mode;
  }
  EXPECT_EQ(twin.quality(kAssembly, Eigen::Vector2d(0.1, -0.2)), 0.5);
}

// A child that floods its output without a newline is stopped at max_reply_bytes (it once grew
// twincal to 261 MB until the timeout), killed and restarted.
TEST(ExternalTwin, StopsAFloodAtTheReplyLimitAndRestartsTheChild) {
  ExternalTwinOptions options = script_options();
  options.max_reply_bytes = std::size_t{1} << 20;
  const ExternalTwin twin(options);
  const pid_t first = pid_of(twin);
  VectorX out(2);
  const Stopwatch stopwatch;
  EXPECT_THAT([&] { twin.quality_batch(misbehaving("flood"), MatrixX::Zero(2, 2), out); },
              ::testing::ThrowsMessage<ExternalTwinError>(
                  HasSubstr("malformed reply: the reply exceeds 1048576 bytes without a newline "
                            "(max_reply_bytes): \"xxxx")));
  EXPECT_LT(stopwatch.seconds(), 5.0);  // not the 10 s timeout: the flood is seen as it comes
  EXPECT_NE(pid_of(twin), first);
  EXPECT_EQ(twin.quality(kAssembly, Eigen::Vector2d(0.1, -0.2)), 0.5);
}

TEST(ExternalTwin, KillsAndRestartsAChildThatTimesOut) {
  ExternalTwinOptions options = script_options();
  options.timeout = std::chrono::milliseconds{200};
  const ExternalTwin twin(options);
  const pid_t first = pid_of(twin);  // started and answered: no startup grace from here on
  const Stopwatch stopwatch;
  VectorX out(2);
  try {
    twin.quality_batch(misbehaving("hang"), MatrixX::Zero(2, 2), out);
    FAIL() << "expected ExternalTwinError";
  } catch (const ExternalTwinError& error) {
    EXPECT_EQ(error.failure(), ExternalTwinFailure::timeout);
    EXPECT_THAT(error.what(), HasSubstr("twin: external twin timed out: no reply within 200 ms; "
                                        "the child was killed by signal 9"));
  }
  EXPECT_GE(stopwatch.seconds(), 0.2);
  EXPECT_LT(stopwatch.seconds(), 5.0);  // the hanging child sleeps for 60 s
  EXPECT_EQ(::kill(first, 0), -1);      // killed and reaped
  EXPECT_EQ(errno, ESRCH);
  // The restarted child gets the startup grace for its first reply.
  EXPECT_EQ(twin.quality(kAssembly, Eigen::Vector2d(0.1, -0.2)), 0.5);
  EXPECT_EQ(twin.starts(), 2);
}

TEST(ExternalTwin, RejectsRepliesOutOfStep) {
  const ExternalTwin twin(script_options());
  // A reply that names another request.
  const pid_t first = pid_of(twin);
  VectorX out(2);
  EXPECT_THAT([&] { twin.quality_batch(misbehaving("wrong_id"), MatrixX::Zero(2, 2), out); },
              ::testing::ThrowsMessage<ExternalTwinError>(
                  HasSubstr("twin: external twin malformed reply: the reply is for request 3, "
                            "not 2: \"{")));
  // An extra, unrequested line after a correct reply is caught before the next request.
  const pid_t second = pid_of(twin);
  EXPECT_NE(second, first);
  twin.quality_batch(misbehaving("chatty"), MatrixX::Zero(2, 2), out);
  EXPECT_NEAR(out(0), expected(VectorX::Zero(2)), 1e-15);  // the reply itself is right
  EXPECT_THAT([&] { twin.quality_batch(kAssembly, MatrixX::Zero(2, 2), out); },
              ::testing::ThrowsMessage<ExternalTwinError>(
                  HasSubstr("twin: external twin malformed reply: unrequested output \"{")));
  EXPECT_NE(pid_of(twin), second);
}

TEST(ExternalTwin, ReportsAWrongCountAndKeepsTheChild) {
  const ExternalTwin twin(script_options());
  const pid_t first = pid_of(twin);
  VectorX out(2);
  EXPECT_THAT(
      [&] { twin.quality_batch(misbehaving("wrong_count"), MatrixX::Zero(2, 2), out); },
      ::testing::Throws<ExternalTwinError>(::testing::Property(
          &ExternalTwinError::what,
          HasSubstr("twin: external twin wrong number of qualities or deviations: the reply has 3 "
                    "qualities; rule: must have 2, one per control"))));
  EXPECT_EQ(pid_of(twin), first);
}

TEST(ExternalTwin, ReportsAnErrorReplyAndKeepsTheChild) {
  const ExternalTwin twin(script_options());
  const pid_t first = pid_of(twin);
  EXPECT_EQ(failure_of(twin, misbehaving("error")), ExternalTwinFailure::twin_error);
  VectorX out(1);
  EXPECT_THAT([&] { twin.quality_batch(misbehaving("error"), MatrixX::Zero(2, 1), out); },
              ::testing::ThrowsMessage<ExternalTwinError>(HasSubstr(
                  "twin: external twin reported an error: assembly rejected on purpose")));
  EXPECT_EQ(pid_of(twin), first);
}

TEST(ExternalTwin, RefusesANegativeOrHugeQualityAndKeepsTheChild) {
  const ExternalTwin twin(script_options());
  const pid_t first = pid_of(twin);
  VectorX out(2);
  EXPECT_THAT(
      [&] { twin.quality_batch(misbehaving("negative"), MatrixX::Zero(2, 2), out); },
      ::testing::ThrowsMessage<ExternalTwinError>(HasSubstr(
          "twin: external twin answered an implausible quality or deviation: quality 0 is -0.25; "
          "rule: a quality is an RMS deviation in [0, max_quality = 1000000] mm")));
  EXPECT_EQ(failure_of(twin, misbehaving("huge")), ExternalTwinFailure::implausible_quality);
  EXPECT_THAT([&] { twin.quality_batch(misbehaving("huge"), MatrixX::Zero(2, 2), out); },
              ::testing::ThrowsMessage<ExternalTwinError>(HasSubstr("quality 1 is 1e+300")));
  EXPECT_EQ(pid_of(twin), first);
  ExternalTwinOptions options = script_options();
  options.max_quality = std::numeric_limits<double>::infinity();
  ASSERT_TRUE(options.validate().has_value());
  EXPECT_THAT(*options.validate(),
              HasSubstr("max_quality: value is inf; rule: must be finite and > 0"));
}

TEST(ExternalTwin, NullQualitiesBecomeNonFiniteErrorsInTheEvaluator) {
  const ExternalTwin twin(script_options());
  VectorX out(3);
  twin.quality_batch(misbehaving("null"), MatrixX::Zero(2, 3), out);
  EXPECT_TRUE(out.array().isNaN().all());
  const Evaluator<ExternalTwin> evaluator(twin);
  try {
    evaluator.quality_batch(misbehaving("null"), MatrixX::Zero(2, 3), out);
    FAIL() << "expected TwinEvaluationError";
  } catch (const TwinEvaluationError<json>& error) {
    EXPECT_EQ(error.failure(), EvaluationFailure::non_finite);
    EXPECT_EQ(error.column(), 0);
    EXPECT_EQ(error.assembly(), misbehaving("null"));
  }
}

TEST(ExternalTwin, EvaluatorWrapsAChildFailureWithItsCause) {
  const ExternalTwin twin(script_options());
  const Evaluator<ExternalTwin> evaluator(twin, {}, {.memoize = true});
  VectorX out(2);
  evaluator.quality_batch(kAssembly, MatrixX::Zero(2, 2), out);
  evaluator.quality_batch(kAssembly, MatrixX::Zero(2, 2), out);
  EXPECT_EQ(evaluator.cache_hits(), 2U);  // JSON assemblies are hashable: memoization works
  try {
    evaluator.quality_batch(misbehaving("crash"), MatrixX::Ones(2, 2), out);
    FAIL() << "expected TwinEvaluationError";
  } catch (const TwinEvaluationError<json>& error) {
    EXPECT_EQ(error.failure(), EvaluationFailure::twin_threw);
    EXPECT_EQ(error.controls(), MatrixX::Ones(2, 2));
    EXPECT_THAT(error.what(), HasSubstr("quality: the twin threw for assembly "));
    EXPECT_THAT(error.what(), HasSubstr("twin: external twin crashed"));
    EXPECT_THROW(std::rethrow_if_nested(error), ExternalTwinError);
  }
}

TEST(ExternalTwin, ReportsAnExecutableThatCannotStart) {
  ExternalTwinOptions options = script_options();
  options.command = {TWINCAL_TEST_DATA_DIR "/no_such_twin"};
  EXPECT_THAT([&] { const ExternalTwin twin(options); },
              ::testing::ThrowsMessage<ExternalTwinError>(
                  HasSubstr("twin: external twin could not start: \"" TWINCAL_TEST_DATA_DIR
                            "/no_such_twin\": No such file or directory")));
}

TEST(ExternalTwin, ReapsItsChildOnDestruction) {
  pid_t pid = 0;
  {
    const ExternalTwin twin(script_options());
    pid = pid_of(twin);
  }
  EXPECT_EQ(::kill(pid, 0), -1);
  EXPECT_EQ(errno, ESRCH);
}

// "deviations": true in the request: script_twin.py's d + 1 key points, whose RMS is its quality.
TEST(ExternalTwin, AsksForTheKeyPointsDeviationsWhenKeyPointsAreSet) {
  ExternalTwinOptions options = script_options();
  options.key_points = 3;
  const ExternalTwin twin(options);
  static_assert(TwinWithDeviations<ExternalTwin>);
  EXPECT_EQ(twin.key_point_count(), 3);
  MatrixX controls(2, 3);
  controls << 0.1, 0.4, -1.0 / 3.0, -0.2, 0.0, 2.0 / 7.0;
  MatrixX deviations(3, 3);
  twin.deviations_batch(kAssembly, controls, deviations);
  VectorX qualities(3);
  twin.quality_batch(kAssembly, controls, qualities);
  for (Index j = 0; j < 3; ++j) {
    EXPECT_NEAR(deviations(0, j), std::sqrt(3 * 0.25), 1e-15);
    EXPECT_NEAR(deviations(1, j), std::sqrt(3.0) * (controls(0, j) - 0.1), 1e-15);
    EXPECT_NEAR(deviations(2, j), std::sqrt(3.0) * (controls(1, j) + 0.2), 1e-15);
    EXPECT_NEAR(deviations.col(j).norm() / std::sqrt(3.0), qualities(j), 1e-15);
  }
  // Without the qualities beside them too; null deviations are a NaN column.
  json only = kAssembly;
  only["deviations_only"] = true;
  twin.deviations_batch(only, controls, deviations);
  EXPECT_NEAR(deviations(1, 1), std::sqrt(3.0) * 0.3, 1e-15);
  twin.deviations_batch(misbehaving("null"), controls, deviations);
  EXPECT_TRUE(deviations.array().isNaN().all());
}

TEST(ExternalTwin, RefusesDeviationsThatBreakTheProtocolAndKeepsTheChild) {
  ExternalTwinOptions options = script_options();
  options.key_points = 3;
  const ExternalTwin twin(options);
  const pid_t first = pid_of(twin);
  MatrixX deviations(3, 2);
  const auto fails_with = [&](const std::string& mode, const std::string& detail) {
    EXPECT_THAT([&] { twin.deviations_batch(misbehaving(mode), MatrixX::Zero(2, 2), deviations); },
                ::testing::ThrowsMessage<ExternalTwinError>(HasSubstr(detail)))
        << mode;
  };
  fails_with("wrong_count",
             "wrong number of qualities or deviations: the reply has 3 arrays of deviations; "
             "rule: must have 2, one per control");
  fails_with("short", "control 0 has 2 deviations; rule: must have 3, one per key point");
  fails_with("huge", "deviation 2 of control 1 is 1e+300");
  fails_with("inconsistent",  // twice the quality, sqrt(0.25 + 0.01 + 0.04)
             "quality 0 is 1.0954451150103321 but its deviations' RMS is 0.547722557505166");
  fails_with("error", "assembly rejected on purpose");
  EXPECT_EQ(pid_of(twin), first);
  // A twin of 4 key points answering 3 is a wrong count.
  options.key_points = 4;
  const ExternalTwin four(options);
  MatrixX wrong(4, 1);
  EXPECT_THAT([&] { four.deviations_batch(kAssembly, MatrixX::Zero(2, 1), wrong); },
              ::testing::ThrowsMessage<ExternalTwinError>(
                  HasSubstr("control 0 has 3 deviations; rule: must have 4")));
}

TEST(ExternalTwin, RefusesDeviationsOfATwinWithoutKeyPointsBeforeSendingAnything) {
  const ExternalTwin twin(script_options());
  EXPECT_EQ(twin.key_point_count(), 0);
  MatrixX deviations(3, 1);
  EXPECT_THAT([&] { twin.deviations_batch(kAssembly, MatrixX::Zero(2, 1), deviations); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  HasSubstr("deviations: the twin answers qualities only; rule: set key_points")));
  ExternalTwinOptions options = script_options();
  options.key_points = 3;
  const ExternalTwin three(options);
  EXPECT_THAT(
      [&] { three.deviations_batch(kAssembly, MatrixX::Zero(2, 1), deviations.topRows(2)); },
      ::testing::ThrowsMessage<DimensionMismatchError>("out: rows is 2; rule: must equal 3"));
  options.key_points = -1;
  EXPECT_THAT([&] { const ExternalTwin negative(options); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "options: key_points: value is -1; rule: must be >= 0"));
  EXPECT_EQ(three.starts(), 1);
}

TEST(ExternalTwin, RejectsBadOptionsAndShapes) {
  ExternalTwinOptions options = script_options();
  options.command.clear();
  EXPECT_THAT([&] { const ExternalTwin twin(options); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "options: command: value is empty; rule: must name an executable"));
  options = script_options();
  options.lower_bounds = VectorX::Zero(3);
  EXPECT_THAT(
      [&] { const ExternalTwin twin(options); },
      ::testing::ThrowsMessage<InvalidArgumentError>(
          "options: lower_bounds: value is 0, 0, 0; rule: must be empty or hold 2 entries"));
  options = script_options();
  options.timeout = std::chrono::milliseconds{0};
  EXPECT_THAT([&] { const ExternalTwin twin(options); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "options: timeout: value is 0; rule: must be > 0 (ms)"));
  const ExternalTwin twin(script_options());
  VectorX out(2);
  EXPECT_THAT(
      [&] { twin.quality_batch(kAssembly, MatrixX::Zero(3, 2), out); },
      ::testing::ThrowsMessage<DimensionMismatchError>("controls: rows is 3; rule: must equal 2"));
}

}  // namespace
}  // namespace twincal
