#include "twincal/core/json_nesting.hpp"

#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace twincal {
namespace {

using ::testing::HasSubstr;

static_assert(json_nesting_depth("") == 0);
static_assert(json_nesting_depth("1.5") == 0);
static_assert(json_nesting_depth(R"({"a": [1, {"b": []}]})") == 4);

TEST(JsonNesting, CountsArraysAndObjectsOutsideStrings) {
  EXPECT_EQ(json_nesting_depth(R"([[1], [[2]], {}])"), 3);
  EXPECT_EQ(json_nesting_depth(R"({"key [[[": "value {{{"})"), 1);
  // An escaped quote does not end the string; an escaped backslash before a quote does.
  EXPECT_EQ(json_nesting_depth(R"(["\"[[[", "\\", [[]]])"), 3);
  // Not JSON: still counted, never negative.
  EXPECT_EQ(json_nesting_depth("]]]][["), 2);
  EXPECT_EQ(json_nesting_depth(std::string(200000, '[')), 200000);
}

TEST(JsonNesting, RefusesATextDeeperThanTheLimitNamingIt) {
  EXPECT_NO_THROW(require_json_nesting(std::string(64, '[') + std::string(64, ']'), "config"));
  try {
    require_json_nesting(std::string(65, '{'), "config");
    FAIL() << "65 levels accepted";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "config");
    EXPECT_THAT(error.what(),
                HasSubstr("config: nests 65 levels of arrays and objects; rule: at most 64"));
  }
  EXPECT_THROW(require_json_nesting("[[[", "line", 2), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
