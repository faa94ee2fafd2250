#include "twincal/experiments/build_id.hpp"

#include <regex>
#include <string>

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(BuildId, NamesTheSourcesTheCompilerAndTheBuildType) {
  const std::string id(build_id());
  static const std::regex form(R"((sources [0-9a-f]{12}|unknown sources) \(.+ .+, .+\))");
  EXPECT_TRUE(std::regex_match(id, form)) << id;
}

TEST(BuildId, NamesTheCommit) {
  const std::string commit(build_commit());
  static const std::regex form(R"([0-9a-f]{12}(\+changes)?|unknown)");
  EXPECT_TRUE(std::regex_match(commit, form)) << commit;
  EXPECT_EQ(commit == "unknown", std::string(build_id()).starts_with("unknown"));
}

}  // namespace
}  // namespace twincal
