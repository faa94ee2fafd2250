#include "twincal/distributed/mpi_experiment_runner.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "mpi_messages.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/stopwatch.hpp"
#include "twincal/experiments/episode_result_codec.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/experiment_runner.hpp"
#include "twincal/experiments/result_store.hpp"
#include "twincal/experiments/study_schedule.hpp"

namespace twincal {
namespace {

using mpi_messages::receive_bytes;
using mpi_messages::send_bytes;
using mpi_messages::wait_for_message;

// Rank 0 → worker: an EpisodeTask as three int64 (group −1: stop).
constexpr int task_tag = 1;
// Worker → rank 0: an outcome, its kind the tag — the episode's result (its CBOR bytes), a twin
// failure or another error (the message's text).
constexpr int result_tag = 2;
constexpr int twin_failure_tag = 4;
constexpr int error_tag = 5;
// A rank that could not build its twins → rank 0: its error message.
constexpr int start_failure_tag = 3;

using TaskMessage = std::array<std::int64_t, 3>;

std::vector<std::uint8_t> text_bytes(std::string_view text) { return {text.begin(), text.end()}; }

// What a rank needs to take part: the study's twins, and on rank 0 the results store.
struct Prepared {
  std::vector<CaseTwin> twins;
  std::optional<ResultStore> store;
};

// Every rank prepares (builds the twins; rank 0 also opens the store); the job goes on only if
// all did. Returns std::nullopt on a rank other than 0 when some rank failed (rank 0 then throws
// the first failing rank's error).
std::optional<Prepared> prepare_together(std::span<const ExperimentGroup> groups,
                                         const std::filesystem::path& directory,
                                         const MpiEnvironment& mpi) {
  const int rank = static_cast<int>(mpi.rank());
  std::optional<Prepared> prepared;
  std::exception_ptr failure;
  std::string message;
  try {
    prepared.emplace(Prepared{make_study_twins(groups), std::nullopt});
    if (rank == 0) prepared->store.emplace(directory);
  } catch (const std::exception& error) {
    failure = std::current_exception();
    message = error.what();
  }
  const int own = failure ? rank : static_cast<int>(mpi.size());
  int first_failed = 0;
  MPI_Allreduce(&own, &first_failed, 1, MPI_INT, MPI_MIN, mpi.communicator());
  if (first_failed == static_cast<int>(mpi.size())) return prepared;
  if (rank == 0) {
    if (first_failed == 0) std::rethrow_exception(failure);
    const MPI_Status status = wait_for_message(mpi.communicator(), first_failed, start_failure_tag);
    const std::vector<std::uint8_t> bytes = receive_bytes(mpi.communicator(), status);
    throw Error("rank", fmt::format("rank {} could not build the study's twins: {}", first_failed,
                                    std::string(bytes.begin(), bytes.end())));
  }
  if (rank == first_failed) {
    send_bytes(mpi.communicator(), std::vector<std::uint8_t>(message.begin(), message.end()), 0,
               start_failure_tag);
  }
  return std::nullopt;
}

void run_worker(std::span<const ExperimentGroup> groups, std::span<const CaseTwin> twins,
                MPI_Comm communicator) {
  for (;;) {
    (void)wait_for_message(communicator, 0, task_tag);
    TaskMessage message{};
    MPI_Recv(message.data(), 3, MPI_INT64_T, 0, task_tag, communicator, MPI_STATUS_IGNORE);
    if (message[0] < 0) return;
    const EpisodeTask task{static_cast<std::size_t>(message[0]),
                           static_cast<std::size_t>(message[1]), message[2]};
    std::vector<std::uint8_t> reply;
    int tag = result_tag;
    try {
      reply = encode_episode_result(run_episode_task(groups, twins, task));
    } catch (const TwinFailureError& error) {
      reply = text_bytes(error.what());
      tag = twin_failure_tag;
    } catch (const std::exception& error) {
      reply = text_bytes(error.what());
      tag = error_tag;
    }
    send_bytes(communicator, reply, 0, tag);
  }
}

// Rank 0: hands out the schedule's episodes to the other ranks and to a thread of its own,
// and takes their outcomes until none is running. Every other rank gets exactly one stop.
void coordinate(std::span<const ExperimentGroup> groups, std::span<const CaseTwin> twins,
                StudySchedule& schedule, const MpiEnvironment& mpi) {
  const MPI_Comm communicator = mpi.communicator();
  std::vector<std::size_t> running(static_cast<std::size_t>(mpi.size()));
  Index busy = 0;
  const auto dispatch = [&](int rank) {
    TaskMessage message{-1, -1, -1};
    if (const std::optional<std::pair<std::size_t, EpisodeTask>> next = schedule.next()) {
      const auto& [number, task] = *next;
      message = {static_cast<std::int64_t>(task.group), static_cast<std::int64_t>(task.controller),
                 task.run};
      running[static_cast<std::size_t>(rank)] = number;
      ++busy;
    }
    MPI_Send(message.data(), 3, MPI_INT64_T, rank, task_tag, communicator);
  };
  std::jthread local([&] { schedule.run_episodes(groups, twins); });
  for (int rank = 1; rank < static_cast<int>(mpi.size()); ++rank) dispatch(rank);
  while (busy > 0) {
    // Only outcomes travel to rank 0 now: the start-up messages were taken before.
    const MPI_Status status = wait_for_message(communicator, MPI_ANY_SOURCE, MPI_ANY_TAG);
    const std::vector<std::uint8_t> bytes = receive_bytes(communicator, status);
    const int rank = status.MPI_SOURCE;
    const std::size_t number = running[static_cast<std::size_t>(rank)];
    --busy;
    try {
      if (status.MPI_TAG == result_tag) {
        schedule.finish(number, decode_episode_result(bytes));
      } else if (status.MPI_TAG == twin_failure_tag) {
        schedule.twin_failed(number, std::string(bytes.begin(), bytes.end()));
      } else {
        throw Error("rank",
                    fmt::format("rank {}: {}", rank, std::string(bytes.begin(), bytes.end())));
      }
    } catch (...) {
      schedule.fail(number, std::current_exception());
    }
    dispatch(rank);
  }
}

}  // namespace

RunReport run_experiments_mpi(std::span<const ExperimentGroup> groups,
                              const std::filesystem::path& directory, const RunOptions& options,
                              const MpiEnvironment& mpi) {
  require_valid("RunOptions", options);
  const Stopwatch watch;
  if (options.threads > 1) {
    throw InvalidArgumentError(
        "threads", fmt::format("threads: is {} under MPI; rule: must be 0 or 1 — each rank "
                               "runs one episode at a time, so start more ranks instead",
                               options.threads));
  }
  std::optional<Prepared> prepared = prepare_together(groups, directory, mpi);
  if (!prepared) return {};                      // rank 0 reports which rank failed
  const double setup_seconds = watch.seconds();  // the slowest rank's: all wait for it
  if (mpi.rank() != 0) {
    run_worker(groups, prepared->twins, mpi.communicator());
    return {};
  }
  std::optional<StudySchedule> schedule;
  try {
    schedule.emplace(groups, prepared->twins, *prepared->store, options.shard, options.progress);
  } catch (...) {
    // The workers wait for episodes: stop them before reporting (a group that conflicts with
    // the stored one, a file that cannot be written).
    const TaskMessage stop{-1, -1, -1};
    for (int rank = 1; rank < static_cast<int>(mpi.size()); ++rank) {
      MPI_Send(stop.data(), 3, MPI_INT64_T, rank, task_tag, mpi.communicator());
    }
    throw;
  }
  try {
    coordinate(groups, prepared->twins, *schedule, mpi);
  } catch (const std::exception& error) {
    // Only MPI itself can get here (the schedule's errors are recorded, not thrown), and the
    // workers would wait for ever: end the job.
    fmt::print(stderr, "twincal: rank 0 cannot coordinate the study: {}\n", error.what());
    mpi.abort(1);
  }
  RunReport report = schedule->conclude();
  report.seconds = watch.seconds();
  report.setup_seconds = setup_seconds;
  return report;
}

}  // namespace twincal
