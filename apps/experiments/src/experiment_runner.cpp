#include "twincal/experiments/experiment_runner.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <exception>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/stopwatch.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/twin_cases.hpp"

namespace twincal {

namespace {

struct Task {
  std::size_t group = 0;
  ControllerSpec controller;
  Index run = 0;
};

class ProgressLine {
 public:
  ProgressLine(bool enabled, Index total)
      : enabled_(enabled && isatty(fileno(stderr)) != 0), total_(total) {}

  void update(Index done) {
    if (!enabled_) return;
    const double elapsed = watch_.seconds();
    if (done < total_ && elapsed - last_ < 0.2) return;
    last_ = elapsed;
    const double eta =
        done > 0 ? elapsed * static_cast<double>(total_ - done) / static_cast<double>(done) : 0.0;
    fmt::print(stderr, "\r  {}/{} episodes  {:.0f} s  eta {:.0f} s   ", done, total_, elapsed, eta);
    std::fflush(stderr);
  }

  void finish() {
    if (enabled_ && total_ > 0) fmt::print(stderr, "\n");
  }

 private:
  bool enabled_;
  Index total_;
  Stopwatch watch_;
  double last_ = -1.0;
};

// The twin failures of one group's episodes (the policy: run_experiments, experiment_runner.hpp).
struct GroupTwinFailures {
  Index failed = 0;       // episodes whose twin failed
  Index in_a_row = 0;     // of those, since the group's last stored episode
  Index not_started = 0;  // episodes skipped once the twin was given up
  std::string first;      // the first failure's message
  [[nodiscard]] bool given_up() const noexcept { return in_a_row >= 2; }
};

}  // namespace

Index require_study_fits(std::span<const ExperimentGroup> groups) {
  std::set<std::string> names;
  Index episodes = 0;
  for (const ExperimentGroup& group : groups) {
    const std::string name = group.config.group_name();
    require_valid(fmt::format("group \"{}\"", name), group.config);
    require_episodes_fit(group.config);
    if (!names.insert(name).second) {
      throw InvalidArgumentError(
          "groups",
          fmt::format("groups: \"{}\" appears twice; rule: group names are unique", name));
    }
    // runs <= max_runs and the controllers a config can list keep each product far below 2^63;
    // the sum is checked against the limit before it can grow past it.
    const Index count = group.config.runs * std::ssize(group.config.controllers);
    if (count > max_study_episodes - episodes) {
      throw InvalidArgumentError(
          "episodes",
          fmt::format("episodes: the study plans {} or more (group \"{}\": {} runs x {} "
                      "controllers); rule: at most max_study_episodes = {} per study (each "
                      "episode's metrics stay in memory, about 3 KB) — split it into studies",
                      episodes + count, name, group.config.runs, group.config.controllers.size(),
                      max_study_episodes));
    }
    episodes += count;
  }
  return episodes;
}

void require_twin_has_assemblies(const ExperimentConfig& config, const CaseTwin& twin) {
  if (config.assemblies > std::ssize(twin.assemblies())) {
    throw InvalidArgumentError(
        "assemblies",
        fmt::format("assemblies: is {} in group \"{}\"; rule: must be <= the twin's {} "
                    "assemblies",
                    config.assemblies, config.group_name(), twin.assemblies().size()));
  }
}

RunReport run_experiments(std::span<const ExperimentGroup> groups, ResultStore& store,
                          const RunOptions& options) {
  require_valid("RunOptions", options);
  Stopwatch watch;
  (void)require_study_fits(groups);
  // u0(x), z*(x) once per group for all its episodes.
  const std::vector<CaseTwin> twins = make_case_twins(groups);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    require_twin_has_assemblies(groups[g].config, twins[g]);
  }
  for (std::size_t g = 0; g < groups.size(); ++g) store.add_group(groups[g], twins[g]);
  store.write_summary();

  RunReport report;
  std::vector<Task> tasks;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const ExperimentConfig& config = groups[g].config;
    for (Index run = 0; run < config.runs; ++run) {
      for (const ControllerSpec& controller : config.controllers) {
        ++report.planned;
        if (store.contains(config.group_name(), controller.label(), run)) {
          ++report.skipped;
        } else {
          tasks.push_back({g, controller, run});
        }
      }
    }
  }

  const Index hardware = static_cast<Index>(std::thread::hardware_concurrency());
  const Index threads = std::max<Index>(
      1, std::min<Index>(options.threads > 0 ? options.threads : std::max<Index>(hardware, 1),
                         std::ssize(tasks)));
  ProgressLine progress(options.progress, std::ssize(tasks));

  // Finished episodes wait in `slots` until every earlier one is stored: the files keep the
  // study's order whatever the thread count. An empty slot is an episode not stored (its twin
  // failed, or its group's twin was given up).
  std::mutex mutex;
  std::map<std::size_t, std::optional<EpisodeResult>> slots;  // those that finished early
  std::size_t next_to_store = 0;
  std::vector<GroupTwinFailures> twin_failures(groups.size());
  std::atomic<std::size_t> next_task{0};
  std::atomic<bool> stop{false};
  std::exception_ptr first_error;

  const auto finish = [&](std::size_t i, std::optional<EpisodeResult> result) {
    slots.emplace(i, std::move(result));
    for (auto it = slots.begin(); it != slots.end() && it->first == next_to_store;
         it = slots.erase(it)) {
      if (it->second) {
        store.append(*it->second);
        ++report.completed;
      }
      ++next_to_store;
    }
    progress.update(static_cast<Index>(next_to_store));
  };
  const auto worker = [&] {
    while (!stop.load()) {
      const std::size_t i = next_task.fetch_add(1);
      if (i >= tasks.size()) return;
      const Task& task = tasks[i];
      GroupTwinFailures& failures = twin_failures[task.group];
      try {
        {
          const std::lock_guard lock(mutex);
          if (failures.given_up()) {
            ++failures.not_started;
            finish(i, std::nullopt);
            continue;
          }
        }
        EpisodeResult result =
            run_episode(twins[task.group], groups[task.group].config, task.controller, task.run);
        const std::lock_guard lock(mutex);
        failures.in_a_row = 0;
        finish(i, std::move(result));
      } catch (const TwinFailureError& error) {
        const std::lock_guard lock(mutex);
        if (failures.failed++ == 0) failures.first = error.what();
        ++failures.in_a_row;
        finish(i, std::nullopt);
      } catch (...) {
        const std::lock_guard lock(mutex);
        if (!first_error) first_error = std::current_exception();
        stop.store(true);
      }
    }
  };
  {
    std::vector<std::jthread> pool;
    for (Index k = 1; k < threads; ++k) pool.emplace_back(worker);
    worker();
  }
  progress.finish();
  store.write_summary();
  report.seconds = watch.seconds();
  if (first_error) std::rethrow_exception(first_error);
  std::string failed_twins;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const GroupTwinFailures& failures = twin_failures[g];
    if (failures.failed == 0) continue;
    failed_twins += fmt::format(
        "\n  group \"{}\": its twin failed in {} episode(s){}; the first: {}",
        groups[g].config.group_name(), failures.failed,
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
                            failed_twins, store.directory().string(), report.completed));
  }
  if (first_error) std::rethrow_exception(first_error);
  return report;
}

}  // namespace twincal
