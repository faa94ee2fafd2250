#include "twincal/experiments/build_id.hpp"

#include <regex>
#include <string>

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(BuildId, NamesTheCommitItsChangesTheCompilerAndTheBuildType) {
  const std::string id(build_id());
  // "unknown" outside a git checkout; the changes' hash only with uncommitted changes.
  static const std::regex form(
      R"((unknown|[0-9a-f]{12}(\+([0-9a-f]{12}|unknown))?) \(.+ .+, .+\))");
  EXPECT_TRUE(std::regex_match(id, form)) << id;
  EXPECT_EQ(build_id().data(), build_id().data());  // one string for the process
}

}  // namespace
}  // namespace twincal
