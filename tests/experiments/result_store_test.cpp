#include "twincal/experiments/result_store.hpp"

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/twin_cases.hpp"

namespace twincal {
namespace {

namespace fs = std::filesystem;

fs::path store_scratch(const std::string& name) {
  const fs::path path = fs::path(::testing::TempDir()) / ("twincal_store_" + name);
  fs::remove_all(path);
  return path;
}

ExperimentGroup store_group() {
  // From JSON: assigning "B" to the defaulted string trips a GCC 12 -O3 -Wstringop-overflow
  // false positive.
  const auto config = nlohmann::json::parse(R"({"case": "analytic", "locators": "B",
      "controllers": ["baseline", "w=0.5"], "assemblies": 5})")
                          .get<ExperimentConfig>();
  return {config, nlohmann::json::object()};
}

// A fresh scratch directory named after the test, the analytic group and its twin.
class ResultStoreOfAnalyticGroup : public ::testing::Test {
 protected:
  const fs::path dir_ =
      store_scratch(::testing::UnitTest::GetInstance()->current_test_info()->name());
  const ExperimentGroup group_ = store_group();
  const CaseTwin twin_ = make_case_twin(group_.config);
};

Index store_lines(const fs::path& path) {
  std::ifstream in(path);
  Index lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  return lines;
}

TEST_F(ResultStoreOfAnalyticGroup, AppendsRowsAndRecordsAndReloadsThem) {
  {
    ResultStore store(dir_);
    store.add_group(group_, twin_);
    store.append(run_episode(twin_, group_.config, ControllerSpec::baseline(), 0));
    store.append(run_episode(twin_, group_.config, ControllerSpec::lookahead(0.5), 0));
    store.write_summary();
    EXPECT_TRUE(store.contains("analytic/B", "w=0.5", 0));
    EXPECT_FALSE(store.contains("analytic/B", "w=0.5", 1));
  }
  EXPECT_EQ(store_lines(dir_ / ResultStore::csv_name), 1 + 2 * 5);
  const ResultStore reopened(dir_);
  ASSERT_EQ(reopened.episodes().size(), 2U);
  EXPECT_EQ(reopened.episodes()[1].at("controller"), "w=0.5");
  EXPECT_TRUE(reopened.contains("analytic/B", "baseline", 0));
  ASSERT_EQ(reopened.groups().size(), 1U);
  EXPECT_EQ(reopened.groups()[0].at("twin").at("locator_names"), nlohmann::json::array({"B"}));
  // The RMS-quadratic twin knows its optimum: nothing was searched.
  EXPECT_TRUE(reopened.groups()[0].at("twin").at("optimum_search").is_null());
}

// What u0 cost the twin that searched it, and z* the plant that is another twin: per assembly,
// as the searches count them; null where nothing was searched.
TEST(ResultStore, RecordsWhatTheU0SearchesOfTwinAndPlantCostPerAssembly) {
  for (const char* nonlinearity : {"nonlinearity", "plant_nonlinearity"}) {
    const fs::path dir = store_scratch(std::string("RecordsWhatTheU0Searches_") + nonlinearity);
    const auto config =
        nlohmann::json::parse(fmt::format(R"({{"case": "analytic", "locators": "all",
          "analytic_dimension": 2, "{}": "kink", "controllers": ["baseline"]}})",
                                          nonlinearity))
            .get<ExperimentConfig>();
    const CaseTwin twin = make_case_twin(config);
    const bool plant = twin.separate_plant();
    EXPECT_EQ(plant, std::string(nonlinearity) == "plant_nonlinearity");
    const std::optional<OptimumSearchCost> cost =
        plant ? twin.plant()->optimum_search() : twin.full_twin().optimum_search();
    ASSERT_TRUE(cost.has_value());
    ResultStore store(dir);
    store.add_group({config, nlohmann::json::object()}, twin);
    const nlohmann::json& recorded = store.groups()[0].at("twin");
    const nlohmann::json& search = recorded.at(plant ? "plant_optimum_search" : "optimum_search");
    const auto assemblies = static_cast<double>(twin.assemblies().size());
    EXPECT_DOUBLE_EQ(search.at("evaluations_per_assembly").get<double>(),
                     static_cast<double>(cost->evaluations) / assemblies);
    EXPECT_DOUBLE_EQ(search.at("requests_per_assembly").get<double>(),
                     static_cast<double>(cost->requests) / assemblies);
    EXPECT_GT(search.at("evaluations_per_assembly").get<double>(), 100.0);  // NLopt: thousands
    EXPECT_FALSE(search.contains("read_from_file"));
    // The twin is its own plant, or behind a plant with a kink it knows its optimum.
    EXPECT_TRUE(recorded.at(plant ? "optimum_search" : "plant_optimum_search").is_null());
  }
}

TEST_F(ResultStoreOfAnalyticGroup, RecordsTheLostRuleAndTheFallbacksAndReadsThemBackIdentically) {
  EpisodeResult lost = run_episode(twin_, group_.config, ControllerSpec::lookahead(0.5), 1);
  lost.estimate_error_second_half = 0.3;  // as assess_lost would record a lost episode
  lost.offset_norm_second_half = 0.1;
  lost.lost = true;
  lost.fallbacks = 2;  // as an episode whose twin failed three times records them
  lost.dropped_measurements = 1;
  lost.first_fallback_at = 7;
  lost.first_fallback = "proposal: twin: timed out";
  const EpisodeResult baseline = run_episode(twin_, group_.config, ControllerSpec::baseline(), 1);
  std::vector<nlohmann::json> written;
  {
    ResultStore store(dir_);
    store.add_group(group_, twin_);
    store.append(lost);
    store.append(baseline);
    store.write_summary();
    written = store.episodes();
  }
  ASSERT_EQ(written.size(), 2U);
  EXPECT_EQ(written[0].at("lost"), true);
  EXPECT_EQ(written[0].at("estimate_error_second_half"), 0.3);
  EXPECT_EQ(written[0].at("offset_norm_second_half"), 0.1);
  EXPECT_EQ(written[0].at("fallbacks"), 2);
  EXPECT_EQ(written[0].at("first_fallback_at"), 7);
  EXPECT_EQ(written[0].at("dropped_measurements"), 1);
  EXPECT_EQ(written[0].at("first_fallback"), "proposal: twin: timed out");
  EXPECT_EQ(written[1].at("lost"), false);
  EXPECT_EQ(written[1].at("fallbacks"), 0);
  EXPECT_EQ(written[1].at("dropped_measurements"), 0);
  EXPECT_TRUE(written[1].at("first_fallback_at").is_null());
  EXPECT_EQ(written[1].at("estimate_error_second_half"), written[1].at("offset_norm_second_half"));
  const ResultStore reopened(dir_);
  EXPECT_EQ(reopened.episodes(), written);
}

TEST_F(ResultStoreOfAnalyticGroup, DropsTheRowsOfAnEpisodeWithoutRecordAndATornRecord) {
  {
    ResultStore store(dir_);
    store.add_group(group_, twin_);
    store.write_summary();
    store.append(run_episode(twin_, group_.config, ControllerSpec::baseline(), 0));
  }
  {
    // A run killed after writing an episode's rows and half its record.
    const EpisodeResult lost = run_episode(twin_, group_.config, ControllerSpec::baseline(), 1);
    std::ofstream csv(dir_ / ResultStore::csv_name, std::ios::app);
    csv << "analytic/B,baseline,1,0,1,1,1,1,0,0,0,0,0,nan,0,0\n";
    std::ofstream jsonl(dir_ / ResultStore::episodes_name, std::ios::app);
    jsonl << R"({"group":"analytic/B","contr)";
    (void)lost;
  }
  const ResultStore store(dir_);
  EXPECT_EQ(store.episodes().size(), 1U);
  EXPECT_FALSE(store.contains("analytic/B", "baseline", 1));
  EXPECT_EQ(store_lines(dir_ / ResultStore::csv_name), 1 + 5);
  EXPECT_EQ(store_lines(dir_ / ResultStore::episodes_name), 1);
}

TEST_F(ResultStoreOfAnalyticGroup, RecordsItsBuildAndResumesAGroupOnlyWithIt) {
  {
    ResultStore store(dir_, "build one", "commit one");
    store.add_group(group_, twin_);
    store.append(run_episode(twin_, group_.config, ControllerSpec::baseline(), 0));
    store.write_summary();
  }
  {
    // The same build from another commit (one that changed only the docs) resumes it.
    ResultStore same(dir_, "build one", "commit two");
    same.add_group(group_, twin_);
    ASSERT_EQ(same.groups().size(), 1U);
    EXPECT_EQ(same.groups()[0].at("build"), "build one");
    EXPECT_EQ(same.groups()[0].at("commit"), "commit one");
  }
  ResultStore other(dir_, "build two");
  try {
    other.add_group(group_, twin_);
    ADD_FAILURE() << "another build resumed the group";
  } catch (const InvalidArgumentError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("group \"analytic/B\""), std::string::npos) << message;
    EXPECT_NE(message.find("build \"build one\", this is build \"build two\""), std::string::npos)
        << message;
    EXPECT_EQ(error.argument(), "build");
  }
  EXPECT_EQ(other.groups()[0].at("build"), "build one");  // unchanged
  // Another group in the same directory is recorded with the new build.
  ExperimentGroup second = group_;
  second.config.locators = "A";
  other.add_group(second, make_case_twin(second.config));
  EXPECT_EQ(other.groups()[1].at("build"), "build two");
}

TEST_F(ResultStoreOfAnalyticGroup, RefusesAGroupRunWithOtherSettingsNamingThemBothWays) {
  ExperimentGroup changed = group_;
  changed.config.active.regret_probe = 0.2;
  {
    ResultStore store(dir_, "build one");
    store.add_group(changed, twin_);
    store.write_summary();
  }
  // The stored group has a setting this one leaves at its default (and so does not write).
  ResultStore other(dir_, "build one");
  try {
    other.add_group(group_, twin_);
    ADD_FAILURE() << "a group run with other settings was resumed";
  } catch (const InvalidArgumentError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("(active was {\"regret_probe\":0.2}, is now unset)"), std::string::npos)
        << message;
  }
}

TEST_F(ResultStoreOfAnalyticGroup, ResumesAGroupStoredWithoutABuild) {
  {
    ResultStore store(dir_, "build one");
    store.add_group(group_, twin_);
    store.write_summary();
  }
  // As a twincal from before 2026-11-28 wrote it.
  nlohmann::json summary;
  std::ifstream(dir_ / ResultStore::summary_name) >> summary;
  summary.at("groups")[0].erase("build");
  std::ofstream(dir_ / ResultStore::summary_name, std::ios::trunc) << summary.dump();
  ResultStore other(dir_, "build two");
  EXPECT_NO_THROW(other.add_group(group_, twin_));
  EXPECT_FALSE(other.groups()[0].contains("build"));
}

TEST(ResultStore, RefusesAForeignSummary) {
  const fs::path dir = store_scratch("foreign");
  fs::create_directories(dir);
  std::ofstream(dir / ResultStore::summary_name) << R"({"format": "other"})";
  EXPECT_THROW(ResultStore store(dir), Error);
}

}  // namespace
}  // namespace twincal
