#include "twincal/experiments/experiment_runner.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <exception>
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

}  // namespace

RunReport run_experiments(std::span<const ExperimentGroup> groups, ResultStore& store,
                          const RunOptions& options) {
  require_valid("RunOptions", options);
  Stopwatch watch;
  std::set<std::string> names;
  for (const ExperimentGroup& group : groups) {
    require_valid("config", group.config);
    require_episodes_fit(group.config);
    const std::string name = group.config.group_name();
    if (!names.insert(name).second) {
      throw InvalidArgumentError(
          "groups",
          fmt::format("groups: \"{}\" appears twice; rule: group names are unique", name));
    }
  }
  // u0(x), z*(x) once per group for all its episodes.
  const std::vector<CaseTwin> twins = make_case_twins(groups);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const ExperimentConfig& config = groups[g].config;
    if (config.assemblies > std::ssize(twins[g].assemblies())) {
      throw InvalidArgumentError(
          "assemblies",
          fmt::format("assemblies: is {} in group \"{}\"; rule: must be <= the twin's {} "
                      "assemblies",
                      config.assemblies, config.group_name(), twins[g].assemblies().size()));
    }
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
  // study's order whatever the thread count.
  std::mutex mutex;
  std::vector<std::optional<EpisodeResult>> slots(tasks.size());
  std::size_t next_to_store = 0;
  std::atomic<std::size_t> next_task{0};
  std::atomic<bool> stop{false};
  std::exception_ptr first_error;

  const auto worker = [&] {
    while (!stop.load()) {
      const std::size_t i = next_task.fetch_add(1);
      if (i >= tasks.size()) return;
      try {
        const Task& task = tasks[i];
        EpisodeResult result =
            run_episode(twins[task.group], groups[task.group].config, task.controller, task.run);
        const std::lock_guard lock(mutex);
        slots[i] = std::move(result);
        while (next_to_store < slots.size() && slots[next_to_store]) {
          store.append(*slots[next_to_store]);
          slots[next_to_store].reset();
          ++next_to_store;
          ++report.completed;
        }
        progress.update(report.completed);
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
  return report;
}

}  // namespace twincal
