#include "twincal/experiments/experiment_runner.hpp"

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "external_twin_testing.hpp"
#include "results_files.hpp"
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
  return test_support::timeless_results_file(path);
}

// A group on tests/data/batch_crashing_twin.py (its u0 search works, every batch crashes it):
// a w-controller's every proposal falls back and every measurement is dropped, so each of its
// episodes has lost its twin by its third assembly (twin_failure_streak).
ExperimentGroup batch_crashing_group(std::vector<ControllerSpec> controllers) {
  ExperimentGroup group;
  group.config.twin_failure_streak = 3;
  group.config.twin_case = TwinCase::external;
  group.config.external_twin = test_support::three_locator_python_twin(
      TWINCAL_TEST_DATA_DIR "/batch_crashing_twin.py", 2, 2, 60);
  group.config.locators = "all";
  group.config.runs = 4;
  group.config.assemblies = 3;
  group.config.controllers = std::move(controllers);
  return group;
}

// The message of the TwinFailureError that running `groups` into `store` throws.
std::string twin_failure_message(const std::vector<ExperimentGroup>& groups, ResultStore& store) {
  try {
    (void)run_experiments(groups, store, RunOptions{.threads = 1, .progress = false});
  } catch (const TwinFailureError& error) {
    return error.what();
  }
  return "(no TwinFailureError)";
}

TEST(RunExperiments, StoresNoEpisodeWhoseTwinFailedAndGivesUpATwinAfterTwoInARow) {
  const fs::path out = runner_scratch("twin_failures");
  ResultStore store(out);
  // w=1 sends batches: each of its episodes fails. Alone in its group, its twin is given up after
  // two; the analytic group beside it runs to the end.
  const std::vector<ExperimentGroup> groups = {
      batch_crashing_group({ControllerSpec::lookahead(1.0)}), runner_group(1)};
  const std::string message = twin_failure_message(groups, store);
  EXPECT_THAT(message, ::testing::HasSubstr(
                           "group \"external/all\": its twin failed in 2 episode(s), then 2 "
                           "episode(s) were not started (two failures in a row); the first: w=1 "
                           "run 0 step 2: the controller could not use its twin at 3 assemblies "
                           "in a row (twin_failure_streak); the last: "));
  EXPECT_THAT(message, ::testing::HasSubstr("twin: external twin crashed"));
  EXPECT_THAT(message, ::testing::HasSubstr("(4 stored)"));
  EXPECT_EQ(store.episodes().size(), 4U);  // the analytic group's four controllers
  for (const auto& episode : store.episodes()) EXPECT_NE(episode["group"], "external/all");

  // Between successes the failures are not in a row: every episode runs, none of w=1's is stored.
  ResultStore alternating(runner_scratch("twin_failures_alternating"));
  const std::string again = twin_failure_message(
      {batch_crashing_group({ControllerSpec::lookahead(1.0), ControllerSpec::baseline()})},
      alternating);
  EXPECT_THAT(again, ::testing::HasSubstr("its twin failed in 4 episode(s); the first: w=1 run 0"));
  EXPECT_THAT(again, ::testing::Not(::testing::HasSubstr("not started")));
  EXPECT_EQ(alternating.episodes().size(), 4U);
  for (const auto& episode : alternating.episodes()) EXPECT_EQ(episode["controller"], "baseline");
}

TEST(RunExperiments, RefusesAStudyOfMoreEpisodesThanTheLimitBeforeRunningAny) {
  ExperimentGroup big = runner_group(ExperimentConfig::max_runs);  // 4 controllers
  try {
    (void)require_study_fits(std::vector<ExperimentGroup>{big});
    FAIL() << "planned 4 000 000 episodes";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "episodes");
    EXPECT_THAT(error.what(), ::testing::HasSubstr("episodes: the study plans 4000000 or more"));
  }
  ExperimentGroup half = runner_group(ExperimentConfig::max_runs / 4);
  EXPECT_EQ(require_study_fits(std::vector<ExperimentGroup>{half}), max_study_episodes);
  half.config.name = "second";
  ExperimentGroup one = runner_group(1);
  one.config.name = "one";
  EXPECT_THROW((void)require_study_fits(std::vector<ExperimentGroup>{half, one}),
               InvalidArgumentError);
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
