#include "twincal/experiments/study_schedule.hpp"

#include <unistd.h>

#include <cstdio>
#include <utility>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/experiments/episode_runner.hpp"

namespace twincal {

EpisodeResult run_episode_task(std::span<const ExperimentGroup> groups,
                               std::span<const CaseTwin> twins, const EpisodeTask& task) {
  const ExperimentConfig& config = groups[task.group].config;
  return run_episode(twins[task.group], config, config.controllers[task.controller], task.run);
}

StudySchedule::StudySchedule(std::span<const ExperimentGroup> groups,
                             std::span<const CaseTwin> twins, ResultStore& store, StudyShard shard,
                             bool progress)
    : groups_(groups),
      store_(store),
      twin_failures_(groups.size()),
      progress_(progress && isatty(fileno(stderr)) != 0) {
  require_valid("shard", shard);
  for (std::size_t g = 0; g < groups.size(); ++g) store.add_group(groups[g], twins[g]);
  store.write_summary();
  Index episode = 0;  // the episode's place in the whole study, which decides its shard
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const ExperimentConfig& config = groups[g].config;
    for (Index run = 0; run < config.runs; ++run) {
      for (std::size_t c = 0; c < config.controllers.size(); ++c, ++episode) {
        ++report_.planned;
        if (!shard.holds(episode)) {
          ++report_.in_other_shards;
        } else if (store.contains(config.group_name(), config.controllers[c].label(), run)) {
          ++report_.skipped;
        } else {
          tasks_.push_back({g, c, run});
        }
      }
    }
  }
}

std::optional<std::pair<std::size_t, EpisodeTask>> StudySchedule::next() {
  const std::lock_guard lock(mutex_);
  while (!first_error_ && next_task_ < tasks_.size()) {
    const std::size_t number = next_task_++;
    GroupTwinFailures& failures = twin_failures_[tasks_[number].group];
    if (!failures.given_up()) return std::pair{number, tasks_[number]};
    ++failures.not_started;
    settle(number, std::nullopt);
  }
  return std::nullopt;
}

void StudySchedule::finish(std::size_t number, EpisodeResult result) {
  const std::lock_guard lock(mutex_);
  twin_failures_[tasks_[number].group].in_a_row = 0;
  settle(number, std::move(result));
}

void StudySchedule::twin_failed(std::size_t number, const std::string& message) {
  const std::lock_guard lock(mutex_);
  GroupTwinFailures& failures = twin_failures_[tasks_[number].group];
  if (failures.failed++ == 0) failures.first = message;
  ++failures.in_a_row;
  settle(number, std::nullopt);
}

void StudySchedule::fail(std::size_t /*number*/, std::exception_ptr error) {
  const std::lock_guard lock(mutex_);
  if (!first_error_) first_error_ = std::move(error);
}

void StudySchedule::settle(std::size_t number, std::optional<EpisodeResult> result) {
  slots_.emplace(number, std::move(result));
  for (auto it = slots_.begin(); it != slots_.end() && it->first == next_to_store_;
       it = slots_.erase(it)) {
    if (it->second) {
      store_.append(*it->second);
      ++report_.completed;
    }
    ++next_to_store_;
  }
  if (!progress_) return;
  const double elapsed = watch_.seconds();
  const std::size_t total = tasks_.size();
  if (next_to_store_ < total && elapsed - last_progress_ < 0.2) return;
  last_progress_ = elapsed;
  const double eta = next_to_store_ > 0 ? elapsed * static_cast<double>(total - next_to_store_) /
                                              static_cast<double>(next_to_store_)
                                        : 0.0;
  fmt::print(stderr, "\r  {}/{} episodes  {:.0f} s  eta {:.0f} s   ", next_to_store_, total,
             elapsed, eta);
  std::fflush(stderr);
}

void StudySchedule::run_episodes(std::span<const ExperimentGroup> groups,
                                 std::span<const CaseTwin> twins) {
  while (const std::optional<std::pair<std::size_t, EpisodeTask>> handed = next()) {
    const auto& [number, task] = *handed;
    try {
      finish(number, run_episode_task(groups, twins, task));
    } catch (const TwinFailureError& error) {
      twin_failed(number, error.what());
    } catch (...) {
      fail(number, std::current_exception());
    }
  }
}

RunReport StudySchedule::conclude() {
  const std::lock_guard lock(mutex_);
  if (progress_ && !tasks_.empty()) fmt::print(stderr, "\n");
  store_.write_summary();
  if (first_error_) std::rethrow_exception(first_error_);
  std::string failed_twins;
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const GroupTwinFailures& failures = twin_failures_[g];
    if (failures.failed == 0) continue;
    failed_twins += fmt::format(
        "\n  group \"{}\": its twin failed in {} episode(s){}; the first: {}",
        groups_[g].config.group_name(), failures.failed,
        failures.not_started > 0
            ? fmt::format(", then {} episode(s) were not started (two failures in a row)",
                          failures.not_started)
            : std::string(),
        failures.first);
  }
  if (!failed_twins.empty()) {
    throw TwinFailureError(
        "twin", fmt::format("twin: episodes not stored because their twin failed:{}\nrule: a "
                            "twin failure is not a result of the controller, so those episodes "
                            "are not in {} ({} stored); fix the twin and run the same command "
                            "again: it runs only what is missing",
                            failed_twins, store_.directory().string(), report_.completed));
  }
  return report_;
}

}  // namespace twincal
