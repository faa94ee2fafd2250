#include "twincal/experiments/searched_optima_file.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path scratch(const std::string& name) {
  const fs::path path = fs::path(::testing::TempDir()) / ("twincal_optima_" + name + ".json");
  fs::remove(path);
  return path;
}

ExternalTwinSettings two_locators() {
  ExternalTwinSettings settings;
  settings.command = {"./cell_twin", "--mesh", "coarse"};
  settings.locators = {"U1", "L3"};
  settings.lower_bounds = {-1.0, -0.5};
  settings.upper_bounds = {1.0, 0.5};
  settings.upper_parts = 2;
  settings.lower_parts = 3;
  settings.optimum_budget = 98;
  return settings;
}

// Digits that a printout to 6 or 15 places would change.
SearchedOptima awkward_optima() {
  SearchedOptima optima(2, 6);
  optima.found.assign(6, true);
  for (Index a = 0; a < 6; ++a) {
    optima.controls(0, a) = (0.1 + 0.2) * static_cast<double>(a) / 3.0 - 0.7;
    optima.controls(1, a) = -1.0 / (3.0 + static_cast<double>(a)) + 1e-17 * static_cast<double>(a);
    optima.qualities(a) = 0.034 + std::ldexp(1.0, -40) * static_cast<double>(a);
  }
  optima.evaluations = 2940;
  optima.requests = 1470;
  return optima;
}

TEST(SearchedOptimaFile, ReadsBackEveryBitItWrote) {
  const fs::path path = scratch("round_trip");
  const ExternalTwinSettings settings = two_locators();
  const SearchedOptima written = awkward_optima();
  write_searched_optima(path, settings, written);
  const std::optional<SearchedOptima> read = read_searched_optima(path, settings);
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(read->controls, written.controls);
  EXPECT_EQ(read->qualities, written.qualities);
  EXPECT_EQ(read->evaluations, 2940U);
  EXPECT_EQ(read->requests, 1470U);
  EXPECT_TRUE(read->complete());
  EXPECT_FALSE(fs::exists(fs::path(path.string() + ".tmp")));
}

// An interrupted search's file: the pairs found so far, and what they cost.
TEST(SearchedOptimaFile, KeepsThePairsASearchHasFound) {
  const fs::path path = scratch("partial");
  SearchedOptima partial = awkward_optima();
  partial.found = {true, false, false, true, true, false};
  partial.evaluations = 1470;
  write_searched_optima(path, two_locators(), partial);
  const std::optional<SearchedOptima> read = read_searched_optima(path, two_locators());
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(read->found, partial.found);
  EXPECT_FALSE(read->complete());
  EXPECT_EQ(read->evaluations, 1470U);
  for (const Index a : {0, 3, 4}) {
    EXPECT_EQ(read->controls.col(a), partial.controls.col(a));
    EXPECT_EQ(read->qualities(a), partial.qualities(a));
  }
}

TEST(SearchedOptimaFile, IsNothingWhereThereIsNoFile) {
  EXPECT_FALSE(read_searched_optima(scratch("absent"), two_locators()).has_value());
}

TEST(SearchedOptimaFile, ServesSettingsThatChangeNoResultAndRefusesOthers) {
  const fs::path path = scratch("settings");
  write_searched_optima(path, two_locators(), awkward_optima());
  ExternalTwinSettings patient = two_locators();
  patient.workers = 8;
  patient.timeout_ms = 600000;
  patient.startup_grace_ms = 0;
  patient.optima_file = "elsewhere.json";
  patient.key_points = 60;  // matters to a least-squares search only
  EXPECT_TRUE(read_searched_optima(path, patient).has_value());

  const std::vector<std::pair<std::function<void(ExternalTwinSettings&)>, std::string>> others{
      {[](ExternalTwinSettings& s) { s.command.back() = "fine"; },
       R"(settings.command is ["./cell_twin","--mesh","coarse"] where the config has )"
       R"(["./cell_twin","--mesh","fine"])"},
      {[](ExternalTwinSettings& s) { s.upper_bounds[1] = 0.75; }, "settings.upper_bounds is"},
      {[](ExternalTwinSettings& s) { s.optimum_budget = 0; },
       "settings.optimum_budget is 98 where the config has 0"},
      {[](ExternalTwinSettings& s) { s.optimum_method = "trust_region"; },
       "settings.optimum_method is"},
      {[](ExternalTwinSettings& s) { s.lower_parts = 4; }, "settings.lower_parts is 3"}};
  for (const auto& [change, message] : others) {
    ExternalTwinSettings other = two_locators();
    change(other);
    try {
      (void)read_searched_optima(path, other);
      ADD_FAILURE() << "read under other settings: " << message;
    } catch (const InvalidArgumentError& error) {
      EXPECT_THAT(error.what(), HasSubstr("optima_file " + path.string() + ": " + message));
      EXPECT_THAT(error.what(), HasSubstr("rule: the file serves only the settings that "
                                          "searched it (delete it to search again)"));
    }
  }
}

// Each damage done to a written file, and the words of its refusal.
TEST(SearchedOptimaFile, RefusesADamagedFileNamingWhatIsWrong) {
  const std::vector<std::pair<std::function<void(nlohmann::json&)>, std::string>> damages{
      {[](nlohmann::json& f) { f["format"] = "twincal searched optima 2"; },
       R"(format is "twincal searched optima 2"; rule: "twincal searched optima 1")"},
      {[](nlohmann::json& f) { f.erase("search"); }, "the file has no \"search\""},
      {[](nlohmann::json& f) { f["search"]["evaluations"] = -3; },
       "search.evaluations is -3; rule: a count"},
      {[](nlohmann::json& f) {
         f["optima"] = {{"upper", 0}};
       },
       R"(optima is {"upper":0}; rule: a list of the pairs found)"},
      {[](nlohmann::json& f) { std::swap(f["optima"][1], f["optima"][2]); },
       "optima[2] is the pair (0, 1); rule: pairs of parts within 2 × 3, upper-major, each once"},
      {[](nlohmann::json& f) { f["optima"][5]["upper"] = 2; },
       "optima[5] is the pair (2, 2); rule: pairs of parts within 2 × 3"},
      {[](nlohmann::json& f) { f["optima"][1] = f["optima"][0]; },
       "optima[1] is the pair (0, 0); rule: pairs of parts within 2 × 3, upper-major, each once"},
      {[](nlohmann::json& f) { f["optima"][4]["control"] = {0.1}; },
       "optima[4].control is [0.1]; rule: one number per locator (2)"},
      {[](nlohmann::json& f) { f["optima"][4]["control"][1] = 0.6; },
       "optima[4].control[1] is 0.6; rule: within the bounds of L3, [-0.5, 0.5]"},
      {[](nlohmann::json& f) { f["optima"][0]["control"][0] = "0.1"; },
       R"(optima[0].control[0] is "0.1"; rule: a number)"},
      {[](nlohmann::json& f) { f["optima"][3]["quality"] = -0.01; },
       "optima[3].quality is -0.01; rule: finite and >= 0"},
      {[](nlohmann::json& f) { f["optima"][3].erase("quality"); }, "optima[3] has no \"quality\""}};
  const fs::path path = scratch("damaged");
  for (const auto& [damage, message] : damages) {
    write_searched_optima(path, two_locators(), awkward_optima());
    nlohmann::json file;
    std::ifstream(path) >> file;
    damage(file);
    std::ofstream(path, std::ios::trunc) << file.dump();
    try {
      (void)read_searched_optima(path, two_locators());
      ADD_FAILURE() << "a damaged file was read: " << message;
    } catch (const InvalidArgumentError& error) {
      EXPECT_THAT(error.what(), HasSubstr(message));
      EXPECT_THAT(error.what(), HasSubstr("optima_file " + path.string()));
    }
  }
  std::ofstream(path, std::ios::trunc) << "{\"format\": ";
  EXPECT_THROW((void)read_searched_optima(path, two_locators()), InvalidArgumentError);
}

TEST(SearchedOptimaFile, RefusesOptimaThatDoNotFitTheSettingsAndAPathItCannotWrite) {
  const fs::path path = scratch("misfit");
  SearchedOptima three_pairs = awkward_optima();
  three_pairs.controls.conservativeResize(2, 3);
  three_pairs.qualities.conservativeResize(3);
  try {
    write_searched_optima(path, two_locators(), three_pairs);
    ADD_FAILURE() << "optima of 3 pairs were written for 6";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("the optima are 2 × 3 controls, 3 qualities and 6 flags; "
                                        "rule: 2 × 6, 6 and 6: one per locator and pair"));
  }
  EXPECT_FALSE(fs::exists(path));

  const fs::path nowhere = fs::path(::testing::TempDir()) / "twincal_no_such_folder" / "o.json";
  try {
    require_writable_optima_file(nowhere);
    ADD_FAILURE() << "a path in a missing folder passed";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("optima_file " + nowhere.string() +
                                        ": cannot be created; rule: a path in an existing, "
                                        "writable folder"));
  }
  EXPECT_THROW(write_searched_optima(nowhere, two_locators(), awkward_optima()),
               InvalidArgumentError);
  require_writable_optima_file(path);  // leaves nothing behind
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(fs::path(path.string() + ".tmp")));
}

}  // namespace
}  // namespace twincal
