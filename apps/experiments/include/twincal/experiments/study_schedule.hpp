#pragma once
/// @file
/// `StudySchedule`: the bookkeeping every way of running a study shares — threads on one machine
/// (run_experiments) and ranks of an MPI job (run_experiments_mpi, distributed/) alike.
///
/// It registers the groups with the results store, plans the episodes of the shard that the
/// store does not hold yet, hands them out one at a time, and stores finished episodes in the
/// study's order (groups, then runs, then controllers) whatever order they finish in, so the
/// files are the same for any number of threads or ranks apart from the wall-time columns.
/// It also keeps run_experiments' twin-failure policy: an episode whose twin failed is not
/// stored; after two such episodes in a row in one group, the group's remaining episodes are not
/// handed out. A progress line goes to standard error when it is a terminal.
/// Thread-safe: workers may call next(), finish() and the failure calls concurrently.

#include <cstddef>
#include <exception>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "twincal/core/eigen.hpp"
#include "twincal/core/stopwatch.hpp"
#include "twincal/experiments/case_twin.hpp"
#include "twincal/experiments/episode_result.hpp"
#include "twincal/experiments/experiment_group.hpp"
#include "twincal/experiments/result_store.hpp"
#include "twincal/experiments/run_report.hpp"
#include "twincal/experiments/study_shard.hpp"

namespace twincal {

/// One episode of a study: group `group`, its config's controller `controller` (an index into
/// ExperimentConfig::controllers), run `run`.
struct EpisodeTask {
  std::size_t group = 0;
  std::size_t controller = 0;
  Index run = 0;
};

/// The episode `task` of `groups` on `twins` (run_episode with the task's controller).
/// @throws as run_episode.
[[nodiscard]] EpisodeResult run_episode_task(std::span<const ExperimentGroup> groups,
                                             std::span<const CaseTwin> twins,
                                             const EpisodeTask& task);

class StudySchedule {
 public:
  /// Registers `groups` (on `twins`, as make_case_twins builds them) with `store`, rewrites its
  /// summary.json and plans the episodes of `shard` that `store` does not hold.
  /// @throws InvalidArgumentError as ResultStore::add_group; Error (files).
  StudySchedule(std::span<const ExperimentGroup> groups, std::span<const CaseTwin> twins,
                ResultStore& store, StudyShard shard, bool progress);

  /// Episodes planned to run now (this shard's, not yet stored).
  [[nodiscard]] Index planned_now() const noexcept { return std::ssize(tasks_); }

  /// The next episode to run and its number, or std::nullopt when none is left or after
  /// fail(). An episode of a group whose twin was given up is not handed out.
  [[nodiscard]] std::optional<std::pair<std::size_t, EpisodeTask>> next();

  /// Episode `number` finished: stored as soon as every earlier one is.
  void finish(std::size_t number, EpisodeResult result);
  /// Episode `number` ended with a TwinFailureError saying `message`: not stored.
  void twin_failed(std::size_t number, const std::string& message);
  /// Episode `number` ended with any other error: recorded (the first one is rethrown by
  /// conclude()) and nothing more is handed out; episodes still running may finish.
  void fail(std::size_t number, std::exception_ptr error);

  /// A worker's loop: runs the episodes next() hands out on `twins` until none is left, each
  /// ending in finish(), twin_failed() (a TwinFailureError) or fail() (any other error).
  void run_episodes(std::span<const ExperimentGroup> groups, std::span<const CaseTwin> twins);

  /// After the last episode came back: rewrites summary.json, then rethrows the first error
  /// passed to fail(), or throws one TwinFailureError listing per group how many episodes
  /// failed and were not started; otherwise returns what was done (seconds: 0, which the
  /// caller's own clock, started before the twins were built, fills in).
  RunReport conclude();

 private:
  // Stores every finished episode up to the first gap. Caller holds mutex_.
  void settle(std::size_t number, std::optional<EpisodeResult> result);

  struct GroupTwinFailures {
    Index failed = 0;       // episodes whose twin failed
    Index in_a_row = 0;     // of those, since the group's last stored episode
    Index not_started = 0;  // episodes skipped once the twin was given up
    std::string first;      // the first failure's message
    [[nodiscard]] bool given_up() const noexcept { return in_a_row >= 2; }
  };

  std::span<const ExperimentGroup> groups_;
  ResultStore& store_;
  Stopwatch watch_;
  RunReport report_;
  std::vector<EpisodeTask> tasks_;
  std::mutex mutex_;
  std::size_t next_task_ = 0;
  // Finished episodes waiting for an earlier one; an empty slot is an episode not stored.
  std::map<std::size_t, std::optional<EpisodeResult>> slots_;
  std::size_t next_to_store_ = 0;
  std::vector<GroupTwinFailures> twin_failures_;
  std::exception_ptr first_error_;
  bool progress_ = false;
  double last_progress_ = -1.0;
};

}  // namespace twincal
