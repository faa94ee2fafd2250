#include "twincal/experiments/experiment_runner.hpp"

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

namespace fs = std::filesystem;

fs::path runner_scratch(const std::string& name) {
  const fs::path path = fs::path(::testing::TempDir()) / ("twincal_runner_" + name);
  fs::remove_all(path);
  return path;
}

ExperimentGroup runner_group(Index runs) {
  ExperimentGroup group;
  group.config.twin_case = TwinCase::analytic;
  group.config.locators = "ABC";
  group.config.runs = runs;
  group.config.assemblies = 12;
  group.config.controllers = {ControllerSpec::baseline(), ControllerSpec::default_controller(),
                              ControllerSpec::lookahead(0.5), ControllerSpec::lookahead(1.0)};
  return group;
}

// A results file without its wall-time fields.
std::string runner_timeless(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::regex csv_seconds(",[^,\n]*\n");
  const std::regex json_seconds("\"seconds_per_assembly\":[^,]*,");
  const std::string s =
      path.extension() == ".csv" ? std::regex_replace(text.str(), csv_seconds, "\n") : text.str();
  return std::regex_replace(s, json_seconds, "");
}

TEST(RunExperiments, ResultsDoNotDependOnTheThreadCount) {
  const std::vector<ExperimentGroup> groups{runner_group(3)};
  const fs::path one = runner_scratch("one");
  const fs::path three = runner_scratch("three");
  {
    ResultStore store(one);
    const RunReport report = run_experiments(groups, store, {.threads = 1, .progress = false});
    EXPECT_EQ(report.planned, 12);
    EXPECT_EQ(report.completed, 12);
  }
  {
    ResultStore store(three);
    (void)run_experiments(groups, store, {.threads = 3, .progress = false});
  }
  for (const char* file : {ResultStore::csv_name, ResultStore::episodes_name}) {
    EXPECT_EQ(runner_timeless(one / file), runner_timeless(three / file)) << file;
  }
}

TEST(RunExperiments, ResumesAndGrowsWithoutChangingWhatIsStored) {
  const fs::path grown = runner_scratch("grown");
  const fs::path fresh = runner_scratch("fresh");
  {
    ResultStore store(grown);
    EXPECT_EQ(run_experiments(std::vector{runner_group(1)}, store, {.progress = false}).completed,
              4);
  }
  {
    ResultStore store(grown);
    const RunReport report =
        run_experiments(std::vector{runner_group(2)}, store, {.progress = false});
    EXPECT_EQ(report.skipped, 4);
    EXPECT_EQ(report.completed, 4);
    EXPECT_EQ(run_experiments(std::vector{runner_group(2)}, store, {.progress = false}).completed,
              0);
  }
  {
    ResultStore store(fresh);
    (void)run_experiments(std::vector{runner_group(2)}, store, {.progress = false});
  }
  for (const char* file : {ResultStore::csv_name, ResultStore::episodes_name}) {
    EXPECT_EQ(runner_timeless(grown / file), runner_timeless(fresh / file)) << file;
  }
}

TEST(RunExperiments, RefusesDuplicateGroupsAndConflictingConfigs) {
  const fs::path dir = runner_scratch("conflict");
  ResultStore store(dir);
  EXPECT_THROW((void)run_experiments(std::vector{runner_group(1), runner_group(1)}, store,
                                     {.progress = false}),
               InvalidArgumentError);
  (void)run_experiments(std::vector{runner_group(1)}, store, {.progress = false});
  ExperimentGroup changed = runner_group(1);
  changed.config.box_half_width = 0.2;
  try {
    (void)run_experiments(std::vector{changed}, store, {.progress = false});
    FAIL() << "no error";
  } catch (const InvalidArgumentError& error) {
    EXPECT_NE(std::string(error.what()).find("box_half_width was 0.1, is now 0.2"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace twincal
