// twincal: run the paper's study and ablations of online calibration and control of digital
// twins, and make their figures. `twincal --help`, `twincal <command> --help`.
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "commands.hpp"
#include "twincal/experiments/build_id.hpp"
#include "twincal/external/child_groups.hpp"

namespace {

constexpr const char* usage =
    R"(twincal — online calibration and control of digital twins (Sjöberg et al. 2023)

usage: twincal <command> [options]      twincal <command> --help      twincal --version

commands:
  run       run one configuration (a case, a locator set, controllers) for N runs
  paper     run the paper's matrix: cases x locator sets A, B, C, ABC x 14 controllers x runs
  scaling   run baseline, default, w=1, per-component and active over d = 1 ... 32 locators
  sweep     run an ablation: the cartesian product of axes over a base config (JSON)
  plot      make the figures (PNG, SVG) and the Table 1 analog from a results directory, or
            the figure of a serve session's history
  summary   print the summary table of a results directory
  merge     join the results directories of a study's shards (--shard i/N) into one
  serve     the online controller for a cell: JSON lines on stdin/stdout or TCP, its
            history in SQLite, resumable after a crash (docs/serve.md)
  history   export a serve session's history as CSV (`twincal plot --history` draws it)
  trace     one episode of one controller as CSV, a row per assembly with the controller's
            own report (why it corrected, the change gate's reading): for tracing a lost run

Results directories are resumable: rerunning a command skips the finished episodes.
run, paper, scaling and sweep run over the ranks of an MPI job when started by mpirun or srun
(docs/distributed.md). See docs/cli.md.
)";

}  // namespace

int main(int argc, char** argv) {
  // Twins that are programs end with twincal, whatever signal ends it.
  twincal::child_groups::end_child_groups_on_termination();
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    fmt::print("{}", usage);
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "--version") {
    // What results directories record as `build` and `commit` (docs/cli.md, "Resume").
    fmt::print("twincal {}\nbuild: {}\ncommit: {}\n", TWINCAL_VERSION, twincal::build_id(),
               twincal::build_commit());
    return 0;
  }
  const std::string& command = args[0];
  const std::span<const std::string> rest(args.begin() + 1, args.end());
  try {
    if (command == "run") return twincal::cli::run_command(rest);
    if (command == "paper") return twincal::cli::paper_command(rest);
    if (command == "scaling") return twincal::cli::scaling_command(rest);
    if (command == "sweep") return twincal::cli::sweep_command(rest);
    if (command == "plot") return twincal::cli::plot_command(rest, argv[0]);
    if (command == "summary") return twincal::cli::summary_command(rest);
    if (command == "merge") return twincal::cli::merge_command(rest);
    if (command == "serve") return twincal::cli::serve_command(rest);
    if (command == "history") return twincal::cli::history_command(rest);
    if (command == "trace") return twincal::cli::trace_command(rest);
    fmt::print(stderr, "twincal: unknown command \"{}\"\n\n{}", command, usage);
    return 2;
  } catch (const std::bad_alloc&) {
    // The settings' own limits (docs/cli.md) catch the known cases; this names the way out of
    // the others.
    fmt::print(stderr,
               "twincal {}: error: out of memory (std::bad_alloc); rule: the study must fit in "
               "memory: lower the dimension, the candidates (--candidates, candidate_cap) or "
               "--threads\n",
               command);
    return 1;
  } catch (const std::exception& error) {
    fmt::print(stderr, "twincal {}: error: {}\n", command, error.what());
    return 1;
  }
}
