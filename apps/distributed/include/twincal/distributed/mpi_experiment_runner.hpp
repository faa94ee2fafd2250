#pragma once
/// @file
/// `run_experiments_mpi`: run_experiments over the ranks of an MPI job (`mpirun`, `srun`).
///
/// Collective: every rank calls it with the same groups (the same command line). Every rank
/// builds the study's twins itself (make_study_twins) and rank 0 opens the results directory;
/// the job starts only when all have, and otherwise rank 0 throws the first failing rank's
/// error while the others return. Rank 0 holds the results store and a
/// StudySchedule: it hands the episodes out one at a time to whichever rank is free (their
/// costs differ by 100×), runs episodes itself in a second thread, and stores every finished
/// episode in the study's order. A rank runs one episode at a time and sends its result back as
/// bytes (episode_result_codec.hpp), which decode to the same numbers, so the results directory
/// is the same, byte for byte apart from the wall-time columns, as a single process writes with
/// any number of threads — and the same for any number of ranks. The twin-failure policy is
/// run_experiments': an episode whose twin failed on any rank is not stored.
///
/// What is not fault tolerant: a rank that dies ends the job (MPI's default), and the episodes
/// that were running or waiting to be stored in order are lost; the others are stored, and
/// running the same command again (with any number of ranks) runs only what is missing.

#include <filesystem>
#include <span>

#include "twincal/distributed/mpi_environment.hpp"
#include "twincal/experiments/experiment_group.hpp"
#include "twincal/experiments/run_options.hpp"
#include "twincal/experiments/run_report.hpp"

namespace twincal {

/// Runs the missing episodes of `groups` (of options.shard) over the ranks of `mpi` into the
/// results directory `directory` (opened, like ResultStore, by rank 0 alone).
/// @returns on rank 0 what run_experiments returns; on the other ranks an empty report.
/// @throws on rank 0: as run_experiments, with another rank's failure to build its twins and an
///         episode's error on another rank as Error naming the rank. Every rank throws
///         InvalidArgumentError for invalid options or options.threads > 1 (each rank runs one
///         episode at a time).
RunReport run_experiments_mpi(std::span<const ExperimentGroup> groups,
                              const std::filesystem::path& directory, const RunOptions& options,
                              const MpiEnvironment& mpi);

}  // namespace twincal
