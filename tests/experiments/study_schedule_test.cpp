#include "twincal/experiments/study_schedule.hpp"

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/experiment_runner.hpp"

namespace twincal {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path schedule_scratch(const std::string& name) {
  const fs::path path = fs::path(::testing::TempDir()) / ("twincal_schedule_" + name);
  fs::remove_all(path);
  return path;
}

std::vector<ExperimentGroup> schedule_study() {
  std::vector<ExperimentGroup> groups(1);
  ExperimentConfig& config = groups[0].config;
  config.twin_case = TwinCase::analytic;
  config.locators = "A,B";
  config.runs = 2;
  config.assemblies = 8;
  config.controllers = {ControllerSpec::baseline(), ControllerSpec::lookahead(1.0)};
  return groups;
}

std::vector<std::pair<std::size_t, EpisodeTask>> take_all(StudySchedule& schedule) {
  std::vector<std::pair<std::size_t, EpisodeTask>> tasks;
  while (std::optional<std::pair<std::size_t, EpisodeTask>> next = schedule.next()) {
    tasks.push_back(*next);
  }
  return tasks;
}

TEST(StudySchedule, HandsOutTheStudyInOrderAndStoresInOrderWhateverOrderTheyFinish) {
  const std::vector<ExperimentGroup> groups = schedule_study();
  const std::vector<CaseTwin> twins = make_study_twins(groups);
  ResultStore store(schedule_scratch("order"));
  StudySchedule schedule(groups, twins, store, {}, false);
  EXPECT_EQ(schedule.planned_now(), 4);
  const std::vector<std::pair<std::size_t, EpisodeTask>> tasks = take_all(schedule);
  ASSERT_EQ(tasks.size(), 4U);
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    EXPECT_EQ(tasks[i].first, i);
    EXPECT_EQ(tasks[i].second.run, static_cast<Index>(i / 2));
    EXPECT_EQ(tasks[i].second.controller, i % 2);
  }
  // Finish 3, 1, 2, 0: nothing is stored before episode 0 is.
  for (const std::size_t number : {3U, 1U, 2U}) {
    schedule.finish(number, run_episode_task(groups, twins, tasks[number].second));
    EXPECT_TRUE(store.episodes().empty());
  }
  schedule.finish(0, run_episode_task(groups, twins, tasks[0].second));
  const RunReport report = schedule.conclude();
  EXPECT_EQ(report.completed, 4);
  ASSERT_EQ(store.episodes().size(), 4U);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(store.episodes()[i].at("run"), static_cast<Index>(i / 2));
    EXPECT_EQ(store.episodes()[i].at("controller"), groups[0].config.controllers[i % 2].label());
  }
}

TEST(StudySchedule, PlansOnlyWhatTheStoreLacks) {
  const std::vector<ExperimentGroup> groups = schedule_study();
  const std::vector<CaseTwin> twins = make_study_twins(groups);
  const fs::path directory = schedule_scratch("resume");
  {
    ResultStore store(directory);
    StudySchedule schedule(groups, twins, store, {}, false);
    const auto first = schedule.next().value();
    schedule.finish(first.first, run_episode_task(groups, twins, first.second));
  }
  ResultStore store(directory);
  StudySchedule schedule(groups, twins, store, {}, false);
  EXPECT_EQ(schedule.planned_now(), 3);
  EXPECT_EQ(take_all(schedule).front().second.controller, 1U);
}

TEST(StudySchedule, GivesUpAGroupAfterTwoTwinFailuresInARow) {
  const std::vector<ExperimentGroup> groups = schedule_study();
  const std::vector<CaseTwin> twins = make_study_twins(groups);
  ResultStore store(schedule_scratch("twin_failures"));
  StudySchedule schedule(groups, twins, store, {}, false);
  const auto first = schedule.next().value();
  const auto second = schedule.next().value();
  schedule.twin_failed(first.first, "twin: crashed");
  schedule.twin_failed(second.first, "twin: crashed again");
  EXPECT_FALSE(schedule.next().has_value());  // the other two are not started
  try {
    (void)schedule.conclude();
    ADD_FAILURE() << "no TwinFailureError";
  } catch (const TwinFailureError& error) {
    EXPECT_THAT(error.what(), HasSubstr("its twin failed in 2 episode(s), then 2 episode(s) "
                                        "were not started"));
    EXPECT_THAT(error.what(), HasSubstr("the first: twin: crashed"));
  }
  EXPECT_TRUE(store.episodes().empty());
}

TEST(StudySchedule, AfterAnErrorHandsOutNothingMoreAndRethrowsIt) {
  const std::vector<ExperimentGroup> groups = schedule_study();
  const std::vector<CaseTwin> twins = make_study_twins(groups);
  ResultStore store(schedule_scratch("error"));
  StudySchedule schedule(groups, twins, store, {}, false);
  const auto first = schedule.next().value();
  const auto second = schedule.next().value();
  schedule.fail(second.first, std::make_exception_ptr(Error("rank", "rank 2: lost")));
  EXPECT_FALSE(schedule.next().has_value());
  // An episode still running when the error came is stored.
  schedule.finish(first.first, run_episode_task(groups, twins, first.second));
  EXPECT_EQ(store.episodes().size(), 1U);
  EXPECT_THROW((void)schedule.conclude(), Error);
}

}  // namespace
}  // namespace twincal
