#include "twincal/experiments/result_merge.hpp"

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "results_files.hpp"
#include "twincal/core/error.hpp"
#include "twincal/experiments/build_id.hpp"
#include "twincal/experiments/experiment_runner.hpp"
#include "twincal/experiments/result_store.hpp"

namespace twincal {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path merge_scratch(const std::string& name) {
  const fs::path path = fs::path(::testing::TempDir()) / ("twincal_merge_" + name);
  fs::remove_all(path);
  return path;
}

std::vector<ExperimentGroup> merge_study(Index runs = 2) {
  std::vector<ExperimentGroup> groups(2);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    ExperimentConfig& config = groups[g].config;
    config.twin_case = TwinCase::analytic;
    config.locators = g == 0 ? "A" : "ABC";
    config.runs = runs;
    config.assemblies = 10;
    config.controllers = {ControllerSpec::baseline(), ControllerSpec::default_controller(),
                          ControllerSpec::lookahead(1.0)};
  }
  return groups;
}

void run_into(const fs::path& directory, const std::vector<ExperimentGroup>& groups,
              StudyShard shard = {}, std::string build = std::string(build_id()),
              std::string commit = std::string(build_commit())) {
  ResultStore store(directory, std::move(build), std::move(commit));
  (void)run_experiments(groups, store, {.threads = 2, .progress = false, .shard = shard});
}

void expect_same_results(const fs::path& expected, const fs::path& actual) {
  for (const char* name :
       {ResultStore::csv_name, ResultStore::episodes_name, ResultStore::summary_name}) {
    EXPECT_EQ(test_support::timeless_results_file(expected / name),
              test_support::timeless_results_file(actual / name))
        << name;
  }
}

std::vector<fs::path> shard_directories(const fs::path& root, Index count,
                                        const std::vector<ExperimentGroup>& groups) {
  std::vector<fs::path> shards;
  for (Index i = 0; i < count; ++i) {
    shards.push_back(root / ("shard" + std::to_string(i)));
    run_into(shards.back(), groups, {.index = i, .count = count});
  }
  return shards;
}

TEST(MergeResults, ShardsMergedAreTheWholeStudy) {
  const fs::path root = merge_scratch("whole");
  const std::vector<ExperimentGroup> groups = merge_study();
  run_into(root / "whole", groups);
  for (const Index count : {1, 3, 5}) {
    const fs::path shards_root = root / ("of" + std::to_string(count));
    const std::vector<fs::path> shards = shard_directories(shards_root, count, groups);
    const MergeReport report = merge_results(shards, shards_root / "merged");
    EXPECT_EQ(report.planned, 12);
    EXPECT_EQ(report.merged, 12);
    EXPECT_EQ(report.missing(), 0);
    EXPECT_EQ(report.duplicates, 0);
    expect_same_results(root / "whole", shards_root / "merged");
  }
}

TEST(MergeResults, AShardRunsEveryCountthEpisodeAndReportsTheRest) {
  const fs::path root = merge_scratch("report");
  ResultStore store(root / "shard1");
  const RunReport report = run_experiments(
      merge_study(), store, {.threads = 1, .progress = false, .shard = {.index = 1, .count = 5}});
  EXPECT_EQ(report.planned, 12);
  EXPECT_EQ(report.completed, 3);  // episodes 1, 6 and 11 of 0 … 11
  EXPECT_EQ(report.in_other_shards, 9);
  ASSERT_EQ(store.episodes().size(), 3U);
  EXPECT_EQ(store.episodes()[0].at("controller"), "default");  // group 0, run 0, controller 1
  EXPECT_EQ(store.episodes()[1].at("group"), "analytic/ABC");  // group 1, run 0, controller 0
  EXPECT_EQ(store.episodes()[1].at("controller"), "baseline");
  EXPECT_EQ(store.episodes()[2].at("run"), 1);  // group 1, run 1, controller 2
  EXPECT_EQ(store.episodes()[2].at("controller"), "w=1");
}

TEST(MergeResults, MissingEpisodesAreLeftForTheStudyToRun) {
  const fs::path root = merge_scratch("missing");
  const std::vector<ExperimentGroup> groups = merge_study();
  run_into(root / "whole", groups);
  std::vector<fs::path> shards = shard_directories(root, 3, groups);
  shards.erase(shards.begin() + 1);
  const MergeReport report = merge_results(shards, root / "merged");
  EXPECT_EQ(report.merged, 8);
  EXPECT_EQ(report.missing(), 4);
  ResultStore store(root / "merged");
  EXPECT_EQ(run_experiments(groups, store, {.threads = 1, .progress = false}).completed, 4);
}

TEST(MergeResults, AnEpisodeInTwoShardsIsKeptOnce) {
  const fs::path root = merge_scratch("duplicates");
  const std::vector<ExperimentGroup> groups = merge_study();
  run_into(root / "whole", groups);
  std::vector<fs::path> shards = shard_directories(root, 2, groups);
  shards.push_back(root / "whole");
  const MergeReport report = merge_results(shards, root / "merged");
  EXPECT_EQ(report.merged, 12);
  EXPECT_EQ(report.duplicates, 12);
  expect_same_results(root / "whole", root / "merged");
}

TEST(MergeResults, RefusesShardsOfAnotherStudyAndAnOutputThatHoldsResults) {
  const fs::path root = merge_scratch("refuses");
  run_into(root / "a", merge_study(2), {.index = 0, .count = 2});
  run_into(root / "b", merge_study(3), {.index = 1, .count = 2});
  try {
    (void)merge_results(std::vector{root / "a", root / "b"}, root / "merged");
    ADD_FAILURE() << "shards of two studies were merged";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("was run with other groups or settings"));
  }
  EXPECT_FALSE(fs::exists(root / "merged"));
  EXPECT_THROW((void)merge_results(std::vector<fs::path>{}, root / "merged"), InvalidArgumentError);
  EXPECT_THROW((void)merge_results(std::vector{root / "nowhere"}, root / "merged"),
               InvalidArgumentError);
  try {
    (void)merge_results(std::vector{root / "a"}, root / "b");
    ADD_FAILURE() << "merged into a results directory";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("already holds results"));
  }
}

TEST(MergeResults, RefusesShardsOfAnotherBuild) {
  const fs::path root = merge_scratch("builds");
  run_into(root / "a", merge_study(), {.index = 0, .count = 2}, "build one");
  run_into(root / "b", merge_study(), {.index = 1, .count = 2}, "build two");
  try {
    (void)merge_results(std::vector{root / "a", root / "b"}, root / "merged");
    ADD_FAILURE() << "shards of two builds were merged";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("another twincal build"));
    EXPECT_THAT(error.what(), HasSubstr("\"build one\""));
    EXPECT_THAT(error.what(), HasSubstr("\"build two\""));
  }
  EXPECT_FALSE(fs::exists(root / "merged"));
  // One build from two commits (one changed only the docs) is one build.
  run_into(root / "c", merge_study(), {.index = 1, .count = 2}, "build one", "another commit");
  EXPECT_NO_THROW((void)merge_results(std::vector{root / "a", root / "c"}, root / "merged"));
}

TEST(MergeResults, RefusesTwoCopiesOfAnEpisodeThatDisagree) {
  const fs::path root = merge_scratch("disagree");
  const std::vector<ExperimentGroup> groups = merge_study();
  run_into(root / "a", groups);
  run_into(root / "b", groups);
  // Edit one number of one episode's line in b.
  const fs::path jsonl = root / "b" / ResultStore::episodes_name;
  std::ifstream in(jsonl);
  std::stringstream text;
  text << in.rdbuf();
  in.close();
  const std::string edited =
      std::regex_replace(text.str(), std::regex("\"relative_residual\":[^,]*,"),
                         "\"relative_residual\":0.5,", std::regex_constants::format_first_only);
  std::ofstream(jsonl, std::ios::trunc) << edited;
  try {
    (void)merge_results(std::vector{root / "a", root / "b"}, root / "merged");
    ADD_FAILURE() << "two different copies of an episode were merged";
  } catch (const InvalidArgumentError& error) {
    EXPECT_THAT(error.what(), HasSubstr("with different results"));
  }
}

}  // namespace
}  // namespace twincal
