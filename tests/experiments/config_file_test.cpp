#include "twincal/experiments/config_file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

// The message of the InvalidArgumentError that parse_config_text(text) throws ("" if none).
std::string refusal(const std::string& text) {
  try {
    (void)parse_config_text(text, "study.json");
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "study.json");
    return error.what();
  }
  return "";
}

TEST(ConfigFile, ParsesADocument) {
  const nlohmann::json document = parse_config_text(R"({"runs": 2, "case": "body"})", "a.json");
  EXPECT_EQ(document.at("runs"), 2);
  EXPECT_EQ(document.at("case"), "body");
}

TEST(ConfigFile, RefusesARepeatedKeyInOneObjectButNotAcrossObjects) {
  EXPECT_THAT(refusal(R"({"runs": 2, "seed": 1, "runs": 3})"),
              HasSubstr("study.json: the key \"runs\" appears twice in one object"));
  EXPECT_THAT(refusal(R"({"a": {"x": 1, "x": 2}})"), HasSubstr("the key \"x\" appears twice"));
  EXPECT_EQ(refusal(R"({"a": {"x": 1}, "b": {"x": 2}, "x": 3})"), "");
}

TEST(ConfigFile, NamesEveryParserFailure) {
  EXPECT_THAT(refusal(std::string(100'000, '[')), HasSubstr("nests 100000 levels"));
  EXPECT_THAT(refusal(R"({"runs": 1e309})"), HasSubstr("study.json: is not valid JSON"));
  EXPECT_THAT(refusal("{\"case\": \"\xff\"}"), HasSubstr("is not valid JSON"));
  EXPECT_THAT(refusal("{\"runs\": 2"), HasSubstr("is not valid JSON"));
  EXPECT_THAT(refusal(""), HasSubstr("is not valid JSON"));
}

TEST(ConfigFile, ReadsAFileAndNamesOneThatCannotBeOpened) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "twincal-config-file-test.json";
  std::ofstream(path) << R"({"runs": 4})";
  EXPECT_EQ(read_config_file(path).at("runs"), 4);
  std::filesystem::remove(path);
  try {
    (void)read_config_file(path);
    FAIL() << "a missing file was read";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("twincal-config-file-test.json: cannot be opened"));
  }
}

}  // namespace
}  // namespace twincal
