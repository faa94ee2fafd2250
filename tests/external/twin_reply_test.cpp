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

TEST(TwinReply, QuotesAtMost200BytesOfAnyOutput) {
  EXPECT_EQ(quoted_output("a\xff"), "\"a\xef\xbf\xbd\"");
  EXPECT_EQ(quoted_output(std::string(500, 'x')).size(), 202U);
}

}  // namespace
}  // namespace twincal
