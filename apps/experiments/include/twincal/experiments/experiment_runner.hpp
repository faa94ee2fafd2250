#pragma once
/// @file
/// `run_experiments`: every episode (group × controller × run) of a study that a results
/// directory does not hold yet (of one shard, RunOptions::shard), in parallel over episodes,
/// stored as they finish.
///
/// Episodes are independent (run_episode) and each is run by one thread, so results do not
/// depend on the thread count; they are also stored in the study's order (groups, then runs,
/// then controllers) whatever order they finish in (StudySchedule), so the files are the same
/// for any thread count apart from the wall-time columns. The same holds across the ranks of an
/// MPI job (run_experiments_mpi, distributed/mpi_experiment_runner.hpp). A progress line goes
/// to standard error when it is a terminal.

#include <span>
#include <vector>

#include "twincal/core/eigen.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/experiment_group.hpp"
#include "twincal/experiments/external_case_twin.hpp"
#include "twincal/experiments/result_store.hpp"
#include "twincal/experiments/run_options.hpp"
#include "twincal/experiments/run_report.hpp"

namespace twincal {

/// The most episodes (groups × runs × controllers) one study may plan: summary.json and the
/// results store keep every episode's metrics in memory (about 3 KB each, measured on the
/// analytic twin: 1.1 GB after 368 000 episodes), so a study at the limit needs about 3 GB.
inline constexpr Index max_study_episodes = 1'000'000;

/// What run_experiments and a dry run check before anything runs: each group's config
/// (validate(), require_episodes_fit), unique group names, and the study's episode count
/// against max_study_episodes (counted without overflow). Returns the episode count.
/// @throws InvalidArgumentError naming the group, or `episodes` and the count.
Index require_study_fits(std::span<const ExperimentGroup> groups);

/// `config.assemblies` is at most `twin`'s assemblies (run and dry run alike).
/// @throws InvalidArgumentError naming the group.
void require_twin_has_assemblies(const ExperimentConfig& config, const CaseTwin& twin);

/// What every way of running a study builds first: require_study_fits, then make_case_twins
/// (the u0(x), z*(x) of each group's assemblies), then require_twin_has_assemblies per group.
/// @throws as those.
/// An external twin runs on what `backend` makes (by default its own ExternalTwinPool).
[[nodiscard]] std::vector<CaseTwin> make_study_twins(
    std::span<const ExperimentGroup> groups, const ExternalTwinBackendFactory& backend = {});

/// Runs the missing episodes of `groups` into `store` and rewrites its summary.json.
///
/// Twin failures (TwinFailureError: the twin's program crashed, hung or answered garbage again
/// after the pool's retry) are not results: such an episode is not stored, so running the same
/// study again runs it; after two such episodes in a row in one group, its twin is given up and
/// the group's remaining episodes are not started (a dead twin costs two episodes, not every
/// one); the other groups go on. At the end, one TwinFailureError lists per group how many
/// episodes failed, how many were not started and the first failure.
/// @throws InvalidArgumentError (a config, a group that conflicts with the stored one, two
///         groups of one name), Error (files); the first other error of a worker after the
///         others have stopped (episodes finished before it stay stored); TwinFailureError.
/// External twins run on what `backend` makes (by default each its own ExternalTwinPool; an
/// MpiTwinPool puts them on other ranks of an MPI job, distributed/mpi_twin_pool.hpp).
RunReport run_experiments(std::span<const ExperimentGroup> groups, ResultStore& store,
                          const RunOptions& options = {},
                          const ExternalTwinBackendFactory& backend = {});

}  // namespace twincal
