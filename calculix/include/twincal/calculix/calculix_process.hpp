#pragma once
/// @file
/// `run_calculix`: one CalculiX job in a directory of its own — the deck written, the solver
/// started in its own process group (killed with the caller on SIGINT/SIGTERM/SIGHUP,
/// child_groups.hpp), waited for with a deadline, its results and log read back.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "twincal/calculix/calculix_error.hpp"
#include "twincal/calculix/calculix_options.hpp"

namespace twincal {

struct CalculixRun {
  int exit_status = 0;   ///< the solver's exit code (0: every step finished)
  double seconds = 0.0;  ///< wall time of the solver process
  std::string dat;       ///< the .dat results (the *NODE PRINT blocks)
  std::string log;       ///< what the solver wrote to stdout and stderr
};

/// Writes `deck` to `directory`/`job`.inp and runs `options.executable -i job` there with
/// `options.solver_threads` threads.
/// @throws CalculixError{missing_executable} when it cannot be started, {timeout} when it ran
///         longer than `options.timeout` (its process group is killed), {crashed} when a
///         signal ended it.
[[nodiscard]] CalculixRun run_calculix(const CalculixOptions& options,
                                       const std::filesystem::path& directory, std::string_view job,
                                       std::string_view deck);

/// What went wrong in a finished run, from its exit status and log: nothing, `no_convergence`
/// (cutbacks exhausted, increments too small), `deck_error` (an *ERROR while reading the deck)
/// or `crashed` (another non-zero exit).
[[nodiscard]] std::optional<CalculixFailure> classify(const CalculixRun& run);

/// The last `lines` lines of `log`.
[[nodiscard]] std::string log_tail(std::string_view log, int lines = 12);

}  // namespace twincal
