#include "twincal/external/twin_reply.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

namespace twincal {
namespace {

using ::testing::HasSubstr;

constexpr double max_quality = 1e6;

// The fault of `line` as the reply to request 7 for `count` controls (nullopt: read).
std::optional<TwinReplyFault> fault_of(const std::string& line, Index count = 2) {
  VectorX qualities(count);
  return read_twin_reply(line, 7, max_quality, qualities);
}

TEST(TwinReply, ReadsNumbersAndNullInRequestOrder) {
  VectorX qualities(3);
  ASSERT_EQ(read_twin_reply(R"({"id": 7, "qualities": [0.5, null, 0]})", 7, max_quality, qualities),
            std::nullopt);
  EXPECT_EQ(qualities(0), 0.5);
  EXPECT_TRUE(std::isnan(qualities(1)));
  EXPECT_EQ(qualities(2), 0.0);
  // The id is optional.
  ASSERT_EQ(read_twin_reply(R"({"qualities": [1, 2, 3]})", 7, max_quality, qualities),
            std::nullopt);
  EXPECT_EQ(qualities(2), 3.0);
}

TEST(TwinReply, NamesEveryMalformedLineAndQuotesIt) {
  for (const std::string& line :
       {std::string("not json"), std::string("[1, 2]"), std::string(R"({"qualities": 3})"),
        std::string(R"({"id": 8, "qualities": [1, 2]})"), std::string(R"({"qualities": [1, "a"]})"),
        std::string(R"({"qualities": [1e309, 1]})"), std::string("{\"qualities\": [1, 2]}\xff"),
        std::string(100, '[') + std::string(100, ']')}) {
    const std::optional<TwinReplyFault> fault = fault_of(line);
    ASSERT_TRUE(fault) << line;
    EXPECT_EQ(fault->failure, ExternalTwinFailure::malformed_reply) << line;
    EXPECT_THAT(fault->detail, HasSubstr(quoted_output(line))) << line;
  }
  EXPECT_THAT(fault_of(std::string(65, '[') + std::string(65, ']'))->detail,
              HasSubstr("nests deeper than 64"));
  EXPECT_THAT(fault_of(R"({"id": "x", "qualities": [1, 2]})")->detail,
              HasSubstr("for request \"x\", not 7"));
  EXPECT_THAT(fault_of(R"({"qualities": [1, true]})")->detail,
              HasSubstr("quality 1 is not a number or null"));
}

TEST(TwinReply, KeepsTheTwinsErrorAndRefusesOneThatIsNotUtf8) {
  const std::optional<TwinReplyFault> fault = fault_of(R"({"error": "mesh failed"})");
  ASSERT_TRUE(fault);
  EXPECT_EQ(fault->failure, ExternalTwinFailure::twin_error);
  EXPECT_EQ(fault->detail, "mesh failed");
  const std::optional<TwinReplyFault> bytes = fault_of("{\"error\": \"mesh \xff failed\"}");
  ASSERT_TRUE(bytes);
  EXPECT_EQ(bytes->failure, ExternalTwinFailure::malformed_reply);
  EXPECT_THAT(bytes->detail, HasSubstr("mesh \xef\xbf\xbd failed"));  // U+FFFD, quoted
  EXPECT_EQ(fault_of(R"({"error": {"code": 3}})")->detail, R"({"code":3})");
  EXPECT_EQ(fault_of(R"({"error": ""})")->detail, R"("")");  // found by the fuzzer
}

TEST(TwinReply, RefusesAWrongCountAndAnImplausibleQuality) {
  const std::optional<TwinReplyFault> count = fault_of(R"({"qualities": [1, 2, 3]})");
  ASSERT_TRUE(count);
  EXPECT_EQ(count->failure, ExternalTwinFailure::wrong_count);
  EXPECT_THAT(count->detail, HasSubstr("has 3 qualities; rule: must have 2"));
  for (const char* line : {R"({"qualities": [1, -0.5]})", R"({"qualities": [1, 2e6]})"}) {
    const std::optional<TwinReplyFault> fault = fault_of(line);
    ASSERT_TRUE(fault) << line;
    EXPECT_EQ(fault->failure, ExternalTwinFailure::implausible_quality) << line;
    EXPECT_THAT(fault->detail, HasSubstr("quality 1 is")) << line;
  }
}

// The fault of `line` as the reply to request 7 asking for the deviations of 2 key points of
// `count` controls (nullopt: read).
std::optional<TwinReplyFault> deviations_fault_of(const std::string& line, Index count = 2) {
  MatrixX deviations(2, count);
  return read_twin_deviations_reply(line, 7, max_quality, deviations);
}

TEST(TwinDeviationsReply, ReadsOneColumnPerControlAndNullAsANaNColumn) {
  MatrixX deviations(2, 3);
  ASSERT_EQ(read_twin_deviations_reply(R"({"id": 7, "deviations": [[0.5, -1], null, [0, 2e-3]]})",
                                       7, max_quality, deviations),
            std::nullopt);
  EXPECT_EQ(deviations(0, 0), 0.5);
  EXPECT_EQ(deviations(1, 0), -1.0);  // a deviation has a sign, a quality has none
  EXPECT_TRUE(deviations.col(1).array().isNaN().all());
  EXPECT_EQ(deviations(1, 2), 2e-3);
  // Qualities beside them are read when they are the deviations' RMS (to a relative 1e-6).
  ASSERT_EQ(read_twin_deviations_reply(
                R"({"deviations": [[3, 4], [0, 0], null], "qualities": [3.5355339, 0, null]})", 7,
                max_quality, deviations),
            std::nullopt);
  EXPECT_EQ(deviations(1, 0), 4.0);
}

TEST(TwinDeviationsReply, RefusesEveryReplyThatBreaksARuleAndNamesTheRule) {
  struct Case {
    std::string line;
    ExternalTwinFailure failure;
    std::string detail;
  };
  const Case cases[] = {
      {R"({"qualities": [1, 2]})", ExternalTwinFailure::malformed_reply,
       "no \"deviations\" array (the request asked for them)"},
      {R"({"deviations": [[1, 2]]})", ExternalTwinFailure::wrong_count,
       "1 arrays of deviations; rule: must have 2, one per control"},
      {R"({"deviations": [[1, 2], [1, 2, 3]]})", ExternalTwinFailure::wrong_count,
       "control 1 has 3 deviations; rule: must have 2, one per key point"},
      {R"({"deviations": [[1, 2], 3]})", ExternalTwinFailure::malformed_reply,
       "the deviations of control 1 are not an array or null"},
      {R"({"deviations": [[1, null], [1, 2]]})", ExternalTwinFailure::malformed_reply,
       "deviation 1 of control 0 is not a number"},
      {R"({"deviations": [[1, 2], [-2e6, 2]]})", ExternalTwinFailure::implausible_quality,
       "deviation 0 of control 1 is -2000000.0; rule: a deviation lies in [-max_quality"},
      {R"({"deviations": [[3, 4], [0, 0]], "qualities": [5, 0]})",
       ExternalTwinFailure::implausible_quality,
       "quality 0 is 5 but its deviations' RMS is 3.5355"},
      {R"({"deviations": [[3, 4], null], "qualities": [3.5355339, 1]})",
       ExternalTwinFailure::implausible_quality, "quality 1 is 1 but its deviations are null"},
      {R"({"deviations": [[3, 4], [0, 0]], "qualities": [null, 0]})",
       ExternalTwinFailure::implausible_quality, "quality 0 is null but its deviations' RMS is"},
      {R"({"deviations": [[3, 4], [0, 0]], "qualities": [3.5355339]})",
       ExternalTwinFailure::wrong_count, "has 1 qualities; rule: must have 2"},
      {R"({"deviations": [[3, 4], [0, 0]], "qualities": 3})", ExternalTwinFailure::malformed_reply,
       "\"qualities\" is not an array"},
      {R"({"id": 8, "deviations": [[3, 4], [0, 0]]})", ExternalTwinFailure::malformed_reply,
       "for request 8, not 7"},
      {R"({"error": "no key points"})", ExternalTwinFailure::twin_error, "no key points"},
  };
  for (const Case& c : cases) {
    const std::optional<TwinReplyFault> fault = deviations_fault_of(c.line);
    ASSERT_TRUE(fault) << c.line;
    EXPECT_EQ(fault->failure, c.failure) << c.line;
    EXPECT_THAT(fault->detail, HasSubstr(c.detail)) << c.line;
  }
}

TEST(TwinReply, QuotesAtMost200BytesOfAnyOutput) {
  EXPECT_EQ(quoted_output("a\xff"), "\"a\xef\xbf\xbd\"");
  EXPECT_EQ(quoted_output(std::string(500, 'x')).size(), 202U);
}

}  // namespace
}  // namespace twincal
