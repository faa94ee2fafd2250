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
#include "twincal/experiments/run_options.hpp"
#include "twincal/experiments/run_report.hpp"

namespace twincal {

/// Runs the missing episodes of `groups` into `store` and rewrites its summary.json.
/// @throws InvalidArgumentError (a config, a group that conflicts with the stored one, two
///         groups of one name), Error (files); the first error of a worker after the others
///         have stopped (episodes finished before it stay stored).
RunReport run_experiments(std::span<const ExperimentGroup> groups, ResultStore& store,
                          const RunOptions& options = {});

}  // namespace twincal
