#pragma once
/// @file
/// `run_experiments`: every episode (group × controller × run) of a study that a results
/// directory does not hold yet, in parallel over episodes, stored as they finish.
///
/// Episodes are independent (run_episode) and each is run by one thread, so results do not
/// depend on the thread count; they are also stored in the study's order (groups, then runs,
/// then controllers) whatever order they finish in, so the files are the same for any thread
/// count apart from the wall-time columns. A progress line goes to standard error when it is a
/// terminal.

#include <span>

#include "twincal/core/eigen.hpp"
#include "twincal/experiments/experiment_group.hpp"
#include "twincal/experiments/result_store.hpp"

namespace twincal {

struct RunOptions {
  /// Worker threads; 0: all cores (std::thread::hardware_concurrency).
  Index threads = 0;
  /// Show the progress line (when standard error is a terminal).
  bool progress = true;

  [[nodiscard]] std::optional<std::string> validate() const;
};

struct RunReport {
  Index planned = 0;    ///< episodes in the study
  Index skipped = 0;    ///< already in the results
  Index completed = 0;  ///< run now
  double seconds = 0.0;
};

/// Runs the missing episodes of `groups` into `store` and rewrites its summary.json.
/// @throws InvalidArgumentError (a config, a group that conflicts with the stored one, two
///         groups of one name), Error (files); the first error of a worker after the others
///         have stopped (episodes finished before it stay stored).
RunReport run_experiments(std::span<const ExperimentGroup> groups, ResultStore& store,
                          const RunOptions& options = {});

}  // namespace twincal
