#pragma once
// What the experiments suites compare results files by: the files without their wall-time
// fields (assemblies.csv's last column, `seconds`; `seconds_per_assembly` of episodes.jsonl and
// summary.json), which are the only parts that differ between two runs of one study.

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace twincal::test_support {

inline std::string timeless_results_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::regex csv_seconds(",[^,\n]*\n");
  const std::regex json_seconds("\"seconds_per_assembly\":[^,]*,");
  const std::string s =
      path.extension() == ".csv" ? std::regex_replace(text.str(), csv_seconds, "\n") : text.str();
  return std::regex_replace(s, json_seconds, "");
}

}  // namespace twincal::test_support
