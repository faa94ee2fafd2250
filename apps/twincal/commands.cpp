#include "commands.hpp"

#include <unistd.h>

#include <array>
#include <csignal>

#include <cctype>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "arguments.hpp"
#include "config_options.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/experiments/config_file.hpp"
#include "twincal/experiments/episode_trace.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/experiments/experiment_runner.hpp"
#include "twincal/experiments/result_merge.hpp"
#include "twincal/experiments/result_store.hpp"
#include "twincal/experiments/study_shard.hpp"
#include "twincal/experiments/summary_table.hpp"
#include "twincal/experiments/sweep.hpp"
#include "twincal/experiments/twin_cases.hpp"
#include "twincal/serve/history_export.hpp"
#include "twincal/serve/line_server.hpp"
#include "twincal/serve/serve_session.hpp"
#if TWINCAL_WITH_MPI
#include "twincal/distributed/mpi_environment.hpp"
#include "twincal/distributed/mpi_experiment_runner.hpp"
#include "twincal/distributed/mpi_twin_service.hpp"
#endif

namespace twincal::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* execution_help =
    R"(  --out DIR              results directory (created; rerunning resumes it)
  --threads N            worker threads (default: all cores; under mpirun/srun each rank runs
                         one episode at a time: docs/distributed.md)
  --shard i/N            run only shard i of N (episode k is shard k mod N's; 0 <= i < N);
                         `twincal merge` joins the shards' directories
  --mpi-twin-pool        under mpirun/srun: rank 0 runs the study on its threads and the other
                         ranks run the external twins' programs (docs/distributed.md)
  --quiet                no progress line
  --dry-run              list the groups and episodes, run nothing
)";

// How a study command runs: the run options, and whether an MPI job's other ranks are the
// external twins' workers (--mpi-twin-pool) rather than running episodes.
struct ExecutionOptions {
  RunOptions run;
  bool mpi_twin_pool = false;
};

ExecutionOptions read_execution_options(Arguments& arguments) {
  ExecutionOptions options;
  if (const auto v = arguments.integer("threads")) options.run.threads = *v;
  if (const auto v = arguments.text("shard")) {
    options.run.shard = parse_study_shard(*v, "--shard");
  }
  options.run.progress = !arguments.flag("quiet");
  options.mpi_twin_pool = arguments.flag("mpi-twin-pool");
  return options;
}

// Lists the groups and their episodes after checking each config and locator set. Runs nothing:
// a twin that is a program is not started (its locators come from its config), so checking an
// untrusted config executes none of it.
int list_study(const std::vector<ExperimentGroup>& groups) {
  const Index planned = require_study_fits(groups);  // the real run's checks and limits
  std::vector<ExperimentGroup> built;  // the groups whose twins are built to resolve locators
  for (const ExperimentGroup& group : groups) {
    if (group.config.twin_case != TwinCase::external) built.push_back(group);
  }
  const std::vector<CaseTwin> twins = make_case_twins(built);
  std::size_t next_built = 0;
  std::vector<std::string> lines;
  for (const ExperimentGroup& group : groups) {
    const ExperimentConfig& config = group.config;
    std::vector<std::string> names;
    if (config.twin_case == TwinCase::external) {
      const std::vector<std::string>& all = config.external_twin->locators;
      for (const Index i :
           resolve_locators(all, external_significant_locators(std::ssize(all)), config.locators)) {
        names.push_back(all[static_cast<std::size_t>(i)]);
      }
    } else {
      const CaseTwin& twin = twins[next_built++];
      require_twin_has_assemblies(config, twin);
      names = twin.locator_names();
    }
    const Index count = config.runs * std::ssize(config.controllers);
    lines.push_back(
        fmt::format("{}: locators [{}], {} runs x {} controllers = {} episodes of {} assemblies\n",
                    config.group_name(), fmt::join(names, ", "), config.runs,
                    config.controllers.size(), count, config.assemblies));
  }
  // Printed once every group passed, as the real run refuses before running any.
  for (const std::string& line : lines) fmt::print("{}", line);
  fmt::print("{} groups, {} episodes\n", groups.size(), planned);
  return 0;
}

// The ranks of the MPI job this process was started in, from the launcher's environment
// (OpenMPI's mpirun, MPICH/Slurm PMI, PMIx); 0 when no launcher started it.
Index launched_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    if (const char* value = std::getenv(name)) return std::max<Index>(1, std::atoll(value));
  }
  if (std::getenv("PMIX_RANK") != nullptr) {
    const char* tasks = std::getenv("SLURM_NTASKS");
    return tasks != nullptr ? std::max<Index>(1, std::atoll(tasks)) : 1;
  }
  return 0;
}

// What was done and the summary of these groups.
void print_study(const std::vector<ExperimentGroup>& groups, const ResultStore& store,
                 const RunReport& report, const std::string& workers) {
  fmt::print(
      "{} episodes: {} run now, {} already in {}{}; {:.1f} s on {} ({:.1f} s of it "
      "building the twins)\n\n",
      report.planned, report.completed, report.skipped, store.directory().string(),
      report.in_other_shards > 0 ? fmt::format(", {} left to other shards", report.in_other_shards)
                                 : std::string(),
      report.seconds, workers, report.setup_seconds);
  std::set<std::string> names;
  for (const ExperimentGroup& group : groups) names.insert(group.config.group_name());
  std::vector<SummaryRow> rows;
  for (SummaryRow& row : summarize(store.groups(), store.episodes())) {
    if (names.contains(row.group)) rows.push_back(std::move(row));
  }
  fmt::print("{}", format_summary(rows));
  json studied = json::array();
  for (const json& group : store.groups()) {
    if (names.contains(group.at("name").get<std::string>())) studied.push_back(group);
  }
  if (const std::string departures = format_departures(studied); !departures.empty()) {
    fmt::print("\n{}", departures);
  }
  if (const std::string searches = format_optimum_searches(studied); !searches.empty()) {
    fmt::print("\n{}", searches);
  }
  if (const std::string models = format_active_models(studied); !models.empty()) {
    fmt::print("\n{}", models);
  }
}

#if TWINCAL_WITH_MPI
// run_study over the ranks of the MPI job: episodes over every rank, or (--mpi-twin-pool) the
// study on rank 0's threads and the external twins' workers on the other ranks. Only rank 0
// prints.
int run_study_mpi(const std::vector<ExperimentGroup>& groups, const fs::path& out,
                  const ExecutionOptions& options) {
  const MpiEnvironment mpi;
  if (!options.mpi_twin_pool) {
    const RunReport report = run_experiments_mpi(groups, out, options.run, mpi);
    if (mpi.rank() == 0) {
      print_study(groups, ResultStore(out), report, fmt::format("{} MPI rank(s)", mpi.size()));
    }
    return 0;
  }
  if (mpi.rank() != 0) {
    serve_twin_requests(mpi);
    return 0;
  }
  MpiTwinService service(mpi);
  service.run([&] {
    ResultStore store(out);
    const RunReport report = run_experiments(groups, store, options.run, service.factory());
    print_study(
        groups, store, report,
        fmt::format("rank 0, its twins' workers on {} other rank(s)", service.worker_ranks()));
  });
  return 0;
}
#endif

// Runs the groups into `out` (over the ranks of an MPI job when started by mpirun or srun),
// then prints what was done and the summary of these groups.
int run_study(const std::vector<ExperimentGroup>& groups, const fs::path& out,
              const ExecutionOptions& execution, bool dry_run) {
  if (dry_run) return list_study(groups);
  const RunOptions& options = execution.run;
  const Index ranks = launched_ranks();
  if (execution.mpi_twin_pool && ranks < 2) {
    throw InvalidArgumentError("mpi-twin-pool",
                               "--mpi-twin-pool: the program was not started as one of several MPI "
                               "ranks; rule: it needs mpirun or srun with at least 2 ranks (rank 0 "
                               "runs the study, the others the external twins)");
  }
  if (ranks > 0) {
#if TWINCAL_WITH_MPI
    return run_study_mpi(groups, out, execution);
#else
    if (ranks > 1) {
      throw InvalidArgumentError(
          "mpirun",
          fmt::format("mpirun: started as one of {} MPI ranks, but this twincal was built without "
                      "MPI; rule: build with MPI (libopenmpi-dev, TWINCAL_MPI=ON, "
                      "docs/distributed.md), or use --shard i/N to split a study without it — "
                      "{} copies of one study would write the same directory",
                      ranks, ranks));
    }
#endif
  }
  ResultStore store(out);
  const RunReport report = run_experiments(groups, store, options);
  const Index threads =
      options.threads > 0
          ? options.threads
          : std::max<Index>(1, static_cast<Index>(std::thread::hardware_concurrency()));
  print_study(groups, store, report, fmt::format("{} thread(s)", threads));
  return 0;
}

bool wants_help(Arguments& arguments, const char* help) {
  if (!arguments.flag("help")) return false;
  fmt::print("{}", help);
  return true;
}

const std::set<std::string, std::less<>> common_flags{"help", "quiet", "dry-run", "mpi-twin-pool"};

// --results must name a directory written by run, paper or sweep.
void require_results_directory(const std::optional<std::string>& results) {
  if (!results || !fs::exists(fs::path(*results) / ResultStore::summary_name)) {
    throw InvalidArgumentError("results",
                               fmt::format("--results: \"{}\" holds no {}; rule: must "
                                           "be a results directory",
                                           results.value_or(""), ResultStore::summary_name));
  }
}

}  // namespace

int run_command(std::span<const std::string> args) {
  static const std::string help = fmt::format(
      R"(usage: twincal run [options]

Runs one configuration: one twin case and locator set, its controllers, N runs.

  --case NAME            body | door (the FEM twin) | body-contact | door-contact (the same
                         with flange contact) | analytic | external (a program:
                         --config with external_twin, docs/external.md) (default body)
  --locators SET         A | B | C | ABC | all | names or indices joined by commas (default A)
  --name NAME            group name in the results (default <case>/<locators>)
{}{})",
      config_options_help(), execution_help);
  Arguments arguments(args, common_flags);
  if (wants_help(arguments, help.c_str())) return 0;
  ExperimentConfig config = read_config(arguments);
  if (const auto v = arguments.text("case")) config.twin_case = parse_enum<TwinCase>(*v, "--case");
  if (const auto v = arguments.text("locators")) config.locators = *v;
  if (const auto v = arguments.text("name")) config.name = *v;
  const fs::path out = arguments.text("out").value_or("results");
  const ExecutionOptions options = read_execution_options(arguments);
  const bool dry_run = arguments.flag("dry-run");
  arguments.require_all_read();
  return run_study({ExperimentGroup{config, json{{"case", to_string(config.twin_case)},
                                                 {"locators", config.locators}}}},
                   out, options, dry_run);
}

int paper_command(std::span<const std::string> args) {
  static const std::string help = fmt::format(
      R"(usage: twincal paper [options]

Runs the paper's matrix (Sec. 3): for each case, locator sets A, B, C and ABC, each with the
baseline, the default controller and the w-controllers w = 0, 0.1, ..., 1 (the paper's 13) and
the active controller, over N runs of 100 assemblies; prints the summary table. Then `twincal plot --results DIR` makes Figs. 4-11 and
Table 1.

  --case NAME            body | door | all (body and door; default) | analytic
{}{})",
      config_options_help(), execution_help);
  Arguments arguments(args, common_flags);
  if (wants_help(arguments, help.c_str())) return 0;
  ExperimentConfig base = read_config(arguments);
  const std::string which = arguments.text("case").value_or("all");
  std::vector<TwinCase> cases;
  if (which == "all") {
    cases = {TwinCase::body, TwinCase::door};
  } else {
    cases = {parse_enum<TwinCase>(which, "--case")};
  }
  const fs::path out = arguments.text("out").value_or("results/paper");
  const ExecutionOptions options = read_execution_options(arguments);
  const bool dry_run = arguments.flag("dry-run");
  arguments.require_all_read();
  return run_study(paper_study(cases, base), out, options, dry_run);
}

// "1,2,3" as a list of integers.
std::vector<Index> parse_dimensions(const std::string& list) {
  std::vector<Index> dimensions;
  for (const std::string_view item : split_commas(list)) {
    Index d = 0;
    const auto [last, error] = std::from_chars(item.data(), item.data() + item.size(), d);
    if (error != std::errc{} || last != item.data() + item.size()) {
      throw InvalidArgumentError(
          "dimensions", fmt::format("--dimensions: holds \"{}\"; rule: must be integers joined "
                                    "by commas, e.g. 1,3,12",
                                    item));
    }
    dimensions.push_back(d);
  }
  return dimensions;
}

// "0,0.5,1" as a list of numbers.
std::vector<double> parse_strengths(const std::string& list) {
  std::vector<double> strengths;
  for (const std::string_view item : split_commas(list)) {
    double s = 0.0;
    const auto [last, error] = std::from_chars(item.data(), item.data() + item.size(), s);
    if (error != std::errc{} || last != item.data() + item.size()) {
      throw InvalidArgumentError(
          "strengths", fmt::format("--strengths: holds \"{}\"; rule: must be numbers joined by "
                                   "commas, e.g. 0,0.5,1",
                                   item));
    }
    strengths.push_back(s);
  }
  return strengths;
}

int scaling_command(std::span<const std::string> args) {
  static const std::string help = fmt::format(
      R"(usage: twincal scaling [options]

Benchmarks scaling with dimension: the same controllers over a growing number d of controlled
(and drifting) locators. On the analytic twin, one group per d with every locator controlled; on
body or door, locator sets A, ABC and all. The summary table counts the diverged and the lost
runs (worse than the baseline's |du*| over the second half) per d; `twincal plot --results DIR`
draws median relative residual, diverged and lost fractions and Q-evaluations per assembly
against d, one line per controller.

With --nonlinearity (contact, stiffening, kink), the same controllers over a growing strength
of the analytic twin's nonlinearity instead, at each d of --dimensions (default 3): the
summary prints how far each twin's Q² departs from a quadratic, and `twincal plot` draws
residual, diverged and lost fractions and Q-evaluations against the strength.

  --case NAME            analytic (default) | body | door
  --dimensions LIST      the analytic twin's d values (default 1,2,3,6,12,19,32)
  --strengths LIST       with --nonlinearity: its strengths (default 0,0.25,0.5,0.75,1 for
                         contact, 0,0.5,1,1.5,2 for stiffening and kink)
  --candidate-cap N      at most N candidates per assembly for the w-controllers (default 1024:
                         the paper's 2^(2+d) up to d = 8; 2^21 at d = 19 is infeasible)
                         (default controllers: baseline, default, w=1, per-component:w=1, active)
{}{})",
      config_options_help(), execution_help);
  Arguments arguments(args, common_flags);
  if (wants_help(arguments, help.c_str())) return 0;
  if (arguments.integer("dimension")) {
    throw InvalidArgumentError("dimension",
                               "--dimension: is given; rule: scaling takes --dimensions LIST");
  }
  ExperimentConfig base =
      read_config(arguments, {ControllerSpec::baseline(), ControllerSpec::default_controller(),
                              ControllerSpec::lookahead(1.0), ControllerSpec::per_component(1.0),
                              ControllerSpec::active()});
  if (const auto v = arguments.integer("candidate-cap")) {
    base.candidate_cap = *v;
  } else if (!base.candidate_cap) {
    base.candidate_cap = 1024;
  }
  const TwinCase twin_case =
      parse_enum<TwinCase>(arguments.text("case").value_or("analytic"), "--case");
  const std::optional<std::string> list = arguments.text("dimensions");
  const std::optional<std::string> strength_list = arguments.text("strengths");
  if (base.nonlinearity != Nonlinearity::none) {
    const std::vector<Index> dimensions = list ? parse_dimensions(*list) : std::vector<Index>{3};
    const std::vector<double> strengths = strength_list ? parse_strengths(*strength_list)
                                          : base.nonlinearity == Nonlinearity::contact
                                              ? std::vector<double>{0, 0.25, 0.5, 0.75, 1}
                                              : std::vector<double>{0, 0.5, 1, 1.5, 2};
    const fs::path out = arguments.text("out").value_or("results/nonlinearity");
    const ExecutionOptions options = read_execution_options(arguments);
    const bool dry_run = arguments.flag("dry-run");
    arguments.require_all_read();
    return run_study(nonlinearity_study(dimensions, strengths, base), out, options, dry_run);
  }
  if (strength_list) {
    throw InvalidArgumentError("strengths",
                               "--strengths: is given without --nonlinearity; rule: it is the "
                               "strength of the analytic twin's nonlinearity");
  }
  std::vector<Index> dimensions;
  if (list) {
    dimensions = parse_dimensions(*list);
  } else if (twin_case == TwinCase::analytic) {
    dimensions = {1, 2, 3, 6, 12, 19, 32};
  }
  const fs::path out = arguments.text("out").value_or("results/scaling");
  const ExecutionOptions options = read_execution_options(arguments);
  const bool dry_run = arguments.flag("dry-run");
  arguments.require_all_read();
  return run_study(scaling_study(twin_case, dimensions, base), out, options, dry_run);
}

int sweep_command(std::span<const std::string> args) {
  constexpr const char* help = R"(usage: twincal sweep --config SWEEP.json [options]

Runs an ablation: the cartesian product of the axes over a base config, e.g.
  {"base": {"case": "analytic", "locators": "ABC", "runs": 5},
   "axes": {"filter": ["merwe", "cubature"], "w": [0.3, 1.0]}}
An axis is any config key (docs/cli.md), or "w", "controller", "dimension". Each point is a
group "<base>/<key>=<value> ..." tagged with its axis values.

  --config FILE.json     the sweep (required)
  --twin-command "CMD"   the program of an external twin (the base's external_twin)
  --twin-workers N       its processes (default 1; results do not depend on N)
  --out DIR              results directory (default results/sweep; rerunning resumes it)
  --threads N            worker threads (default: all cores)
  --quiet                no progress line
  --dry-run              list the groups and episodes, run nothing
)";
  Arguments arguments(args, common_flags);
  if (wants_help(arguments, help)) return 0;
  const std::optional<std::string> path = arguments.text("config");
  if (!path) throw InvalidArgumentError("config", "--config: is missing; rule: sweep needs one");
  const fs::path out = arguments.text("out").value_or("results/sweep");
  const ExecutionOptions options = read_execution_options(arguments);
  const bool dry_run = arguments.flag("dry-run");
  std::vector<ExperimentGroup> groups = expand_sweep(read_config_file(*path));
  std::vector<ExperimentConfig> configs;
  for (const ExperimentGroup& group : groups) configs.push_back(group.config);
  apply_twin_options(arguments, configs);
  for (std::size_t g = 0; g < groups.size(); ++g) groups[g].config = configs[g];
  arguments.require_all_read();
  return run_study(groups, out, options, dry_run);
}

int merge_command(std::span<const std::string> args) {
  constexpr const char* help = R"(usage: twincal merge --out DIR --shards DIR0,DIR1,...

Joins the results directories of a study's shards (each written by the same command with
--shard i/N, e.g. the tasks of a Slurm job array) into DIR, a new results directory: the one the
whole study run at once writes, byte for byte apart from the wall-time columns. Episodes that no
shard holds are left out; running the study on DIR runs only those. Prints the summary table.
)";
  Arguments arguments(args, common_flags);
  if (wants_help(arguments, help)) return 0;
  const std::optional<std::string> out = arguments.text("out");
  const std::optional<std::string> list = arguments.text("shards");
  arguments.require_all_read();
  if (!out) throw InvalidArgumentError("out", "--out: is missing; rule: merge needs one");
  if (!list) throw InvalidArgumentError("shards", "--shards: is missing; rule: merge needs them");
  std::vector<fs::path> shards;
  for (const std::string_view item : split_commas(*list)) shards.emplace_back(item);
  const MergeReport report = merge_results(shards, *out);
  fmt::print("{} of {} episodes merged from {} shard(s) into {}{}\n\n", report.merged,
             report.planned, shards.size(), *out,
             report.missing() > 0 ? fmt::format("; {} missing (run the study on {} to add them)",
                                                report.missing(), *out)
                                  : std::string());
  const ResultStore store(*out);
  fmt::print("{}", format_summary(summarize(store.groups(), store.episodes())));
  return 0;
}

int summary_command(std::span<const std::string> args) {
  constexpr const char* help = R"(usage: twincal summary --results DIR

Prints the summary table of a results directory: per group and controller, the runs, the
divergences, the lost runs (mean |du^ - du*| over the second half of the assemblies above the
baseline's mean |du*| there; - for results from before the rule), the medians over the
non-diverged runs of the mean relative residual (z-z*)/z* and of the mean estimation error
|du^ - du*|, and the mean time (µs) and Q-evaluations per assembly.
)";
  Arguments arguments(args, common_flags);
  if (wants_help(arguments, help)) return 0;
  const std::optional<std::string> results = arguments.text("results");
  arguments.require_all_read();
  require_results_directory(results);
  ResultStore store(*results);
  store.write_summary();  // brings summary.json up to date after an interrupted run
  fmt::print("{}", format_summary(summarize(store.groups(), store.episodes())));
  return 0;
}

namespace {

std::string shell_quote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

// TWINCAL_PYTHON, else Debian's /usr/bin/python3, else python3 on PATH: the first that can
// import matplotlib.
std::string find_python() {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("TWINCAL_PYTHON"); env != nullptr && *env != '\0') {
    candidates.emplace_back(env);
  }
  candidates.emplace_back("/usr/bin/python3");
  candidates.emplace_back("python3");
  for (const std::string& python : candidates) {
    const std::string probe = shell_quote(python) + " -c 'import matplotlib' > /dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) return python;
  }
  throw Error("python", fmt::format("python: none of [{}] can import matplotlib; rule: install "
                                    "python3-matplotlib or set TWINCAL_PYTHON to an interpreter "
                                    "that has it",
                                    fmt::join(candidates, ", ")));
}

// TWINCAL_PLOT_SCRIPT, else the installed copy next to the executable (../share/twincal/), else
// the source tree's (a build-tree executable).
fs::path find_plot_script(const char* argv0) {
  if (const char* env = std::getenv("TWINCAL_PLOT_SCRIPT"); env != nullptr && *env != '\0') {
    return env;
  }
  std::error_code error;
  fs::path executable = fs::read_symlink("/proc/self/exe", error);
  if (error) executable = fs::absolute(argv0);
  const fs::path installed = executable.parent_path().parent_path() / TWINCAL_PLOT_SCRIPT_INSTALL;
  if (fs::exists(installed)) return installed;
  const fs::path source = TWINCAL_PLOT_SCRIPT_SOURCE;
  if (fs::exists(source)) return source;
  throw Error("twincal_plot.py",
              fmt::format("twincal_plot.py: found neither at {} nor at {}; rule: set "
                          "TWINCAL_PLOT_SCRIPT to its path",
                          installed.string(), source.string()));
}

}  // namespace

int plot_command(std::span<const std::string> args, const char* argv0) {
  constexpr const char* help = R"(usage: twincal plot --results DIR [--out DIR]
       twincal plot --history FILE.csv [--out DIR]

Makes the figures of a results directory with matplotlib (apps/plots/twincal_plot.py), as PNG
and SVG: per case and locator set, box plots over the runs of the mean relative residual (upper
panel) and of the mean estimation error (lower panel) per controller, divergences as red
circles whose intensity grows with their count (the paper's Figs. 4-11), lost runs counted in
the controller's label; and the Table 1 analog,
mean time and Q-evaluations per assembly per controller for 1 and 3 locators, as Markdown and
CSV. With --history, the figure of a `twincal serve` session (exported by `twincal history`):
the estimate and its +-2 sigma band per locator, and the measured quality against the twin's
best, over the requests.

  --results DIR          results directory (of run, paper, scaling or sweep)
  --history FILE.csv     a serve session's history (twincal history --db DB --out FILE.csv)
  --out DIR              where the figures go (default DIR/figures, or the CSV's directory)

The interpreter is $TWINCAL_PYTHON, else /usr/bin/python3, else python3 (the first that has
matplotlib); the script is $TWINCAL_PLOT_SCRIPT, else the installed or the source tree's copy.
)";
  Arguments arguments(args, common_flags);
  if (wants_help(arguments, help)) return 0;
  const std::optional<std::string> results = arguments.text("results");
  const std::optional<std::string> history = arguments.text("history");
  const std::optional<std::string> out = arguments.text("out");
  arguments.require_all_read();
  std::string source;
  if (history) {
    if (results) {
      throw InvalidArgumentError("--history",
                                 "--history: given with --results; rule: plot one or the other");
    }
    if (!fs::is_regular_file(*history)) {
      throw InvalidArgumentError("--history", fmt::format("--history: {} is not a file", *history));
    }
    source = fmt::format("--history {}", shell_quote(*history));
  } else {
    require_results_directory(results);
    ResultStore store(*results);
    store.write_summary();
    const fs::path figures = out ? fs::path(*out) : fs::path(*results) / "figures";
    source =
        fmt::format("--results {} --out {}", shell_quote(*results), shell_quote(figures.string()));
  }
  if (history && out) source += fmt::format(" --out {}", shell_quote(*out));
  const std::string command = fmt::format("{} {} {}", shell_quote(find_python()),
                                          shell_quote(find_plot_script(argv0).string()), source);
  const int status = std::system(command.c_str());
  if (status != 0) {
    throw Error("twincal_plot.py",
                fmt::format("twincal_plot.py: failed (status {}): {}", status, command));
  }
  return 0;
}

int trace_command(std::span<const std::string> args) {
  static const std::string help = fmt::format(
      R"(usage: twincal trace [options]

Runs one episode — one controller, run R of one configuration — exactly as `twincal run` runs
it (the same settings and seeds give the same digits) and writes one CSV row per assembly as it
goes: t, the assembly (upper, lower), z, z*, the relative residual, the estimate's error
|du_hat - du*|, the offset's norm |du*|, tr P, the twin evaluations, then the controller's step
report (the active controller's: its model's error and tau^2, its probe, the change gate's
reading, the misfit and prediction scales, whether it corrected; docs/cli.md). A summary line
with the lost rule's means goes to stderr. Nothing is written to a results directory.

  --case NAME            body | door | body-contact | door-contact | analytic | external
                         (default body)
  --locators SET         A | B | C | ABC | all | names or indices joined by commas (default A)
  --controller LABEL     the controller (default active): any label of --controllers
  --run R                run R of `twincal run --runs N` (N > R; default 0)
  --out FILE.csv         where the CSV goes (default: standard output)
{})",
      config_options_help());
  Arguments arguments(args, {"help"});
  if (wants_help(arguments, help.c_str())) return 0;
  ExperimentConfig config = read_config(arguments, {ControllerSpec::active()});
  if (const auto v = arguments.text("case")) config.twin_case = parse_enum<TwinCase>(*v, "--case");
  if (const auto v = arguments.text("locators")) config.locators = *v;
  const Index run = arguments.integer("run").value_or(0);
  const auto out = arguments.text("out");
  arguments.require_all_read();
  if (config.controllers.size() != 1) {
    throw InvalidArgumentError(
        "--controller", fmt::format("--controller: names {} controllers; rule: trace runs one",
                                    config.controllers.size()));
  }
  const CaseTwin twin = make_case_twin(config);
  std::ofstream file;
  if (out) {
    file.open(*out);
    if (!file) throw Error(*out, fmt::format("{}: cannot be written", *out));
  }
  std::ostream& stream = out ? static_cast<std::ostream&>(file) : std::cout;
  const EpisodeResult result =
      write_episode_trace(twin, config, config.controllers.front(), run, stream);
  fmt::print(stderr,
             "twincal trace: {} {} run {} (seed {}): {} assemblies, mean relative residual {:.4g}, "
             "mean |du_hat - du*| {:.4g}; second half {:.4g} against |du*| {:.4g}: {}{}{}\n",
             result.group, result.controller, result.run, result.run_seed, result.steps,
             result.relative_residual, result.estimation_error, result.estimate_error_second_half,
             result.offset_norm_second_half, result.lost ? "lost" : "not lost",
             result.first_fallback_at < 0
                 ? std::string()
                 : fmt::format("; {} proposals fell back to the default control and {} "
                               "measurements were dropped, the first at t = {} ({})",
                               result.fallbacks, result.dropped_measurements,
                               result.first_fallback_at, result.first_fallback),
             result.failure.empty() ? std::string() : "; failed: " + result.failure);
  return 0;
}

int history_command(std::span<const std::string> args) {
  constexpr const char* help = R"(usage: twincal history --db FILE [--out FILE.csv]
       twincal history --db FILE --check

Exports the history of a `twincal serve` session as CSV, one row per request: request_id,
the assembly (upper, lower), proposed_at, observed_at, the measured quality, the twin's best
quality z*, and per locator the control, the estimate after the observation and its standard
deviation. `twincal plot --history FILE.csv` draws it. With --check, verifies the history
instead: every row's checksum, and a replay of the whole session from its settings (the twin
and controller rebuilt, every control, report, estimate and covariance compared bit for bit);
prints what it verified, or the first damaged or mismatching row (exit 1). Either way the
database is only read (a running server may keep writing to it).

  --db FILE              the session's database
  --out FILE.csv         where the CSV goes (default: standard output)
  --check                verify the history instead of exporting it
)";
  Arguments arguments(args, {"help", "check"});
  if (wants_help(arguments, help)) return 0;
  const auto database = arguments.text("db");
  const auto out = arguments.text("out");
  const bool check = arguments.flag("check");
  arguments.require_all_read();
  if (!database) {
    throw InvalidArgumentError("--db", "--db: is missing; rule: history needs a database");
  }
  if (check) {
    if (out) {
      throw InvalidArgumentError("--out", "--out: given with --check; rule: --check writes no CSV");
    }
    const HistoryCheck verified = ServeSession::check(*database);
    fmt::print("{}: ok — {} requests, {} observations and {} snapshots replayed bit for bit{}\n",
               *database, verified.requests, verified.observations, verified.snapshots,
               verified.pending ? "; the last request awaits its observation" : "");
    return 0;
  }
  const HistoryStore store = HistoryStore::open_read_only(*database);
  if (!out) {
    write_history_csv(store, std::cout);
    return 0;
  }
  std::ofstream file(*out);
  if (!file) throw Error(*out, fmt::format("{}: cannot be written", *out));
  write_history_csv(store, file);
  return 0;
}

namespace {

// The first line of a token file, without trailing whitespace.
std::string read_token(const std::string& path) {
  std::ifstream in(path);
  std::string token;
  if (!in || !std::getline(in, token)) {
    throw InvalidArgumentError("--token-file",
                               fmt::format("--token-file: {} cannot be read", path));
  }
  while (!token.empty() && std::isspace(static_cast<unsigned char>(token.back())) != 0) {
    token.pop_back();
  }
  return token;
}

}  // namespace

int serve_command(std::span<const std::string> args) {
  static const std::string help = fmt::format(
      R"(usage: twincal serve --db FILE [options]
       twincal serve --db FILE --resume [--verify-all] [--listen [HOST:]PORT] [--durability full|normal]

Runs the online controller for a cell (the paper's Fig. 1): per assembly the cell sends
{{"op": "propose", "assembly": ...}} and gets the locator adjustment, then sends
{{"op": "observe", "request_id": ..., "quality": ...}} with the measured quality. One JSON
request per line on stdin, one reply per line on stdout (or over TCP with --listen). Every
proposal and observation is in the database before its reply is sent; after a crash,
--resume continues bit for bit. Protocol and schema: docs/serve.md.

  --db FILE              the session's SQLite history (created; with --resume, read)
  --resume               continue the session of --db (its settings come from the database):
                         the controller restored from the last snapshot, the requests after it
                         replayed bit for bit
  --verify-all           with --resume, replay the whole history instead, every snapshot compared
  --snapshot-every N     store the controller's state every N observations (default 1000; 0:
                         never, and a resume replays everything), and at checkpoint and shutdown
  --listen [HOST:]PORT   serve TCP connections instead of stdin/stdout (HOST defaults to
                         127.0.0.1; PORT 0 picks a free port, printed on stderr)
  --listen unix:PATH     serve connections on a Unix-domain socket (mode 0600: the owner only)
  --max-connections N    TCP connections open at once (default 64; one more is refused)
  --idle-timeout-ms T    close a TCP connection silent for T ms (default 600000)
  --token-file FILE      the shared secret (its first line, at least 16 characters) a
                         connection must send first: {{"op": "authenticate", "token": ...}};
                         required to listen beyond loopback
  --durability MODE      full (default: each record survives a power cut) | normal
                         (survives a killed process; no fsync per record)
  --case NAME            body | door | analytic | external (default body)
  --locators SET         A | B | C | ABC | all | names or indices joined by commas (default A)
  --controller LABEL     the controller (default active): any label of --controllers
  --run R                build the controller with the seeds of run R of `twincal run` (default 0)
{})",
      config_options_help());
  Arguments arguments(args, {"help", "resume", "verify-all"});
  if (wants_help(arguments, help.c_str())) return 0;
  const auto database = arguments.text("db");
  if (!database)
    throw InvalidArgumentError("--db", "--db: is missing; rule: serve needs a database");
  Durability durability = Durability::full;
  if (const auto v = arguments.text("durability")) {
    if (*v == "normal") {
      durability = Durability::normal;
    } else if (*v != "full") {
      throw InvalidArgumentError("--durability",
                                 fmt::format("--durability: is \"{}\"; rule: full | normal", *v));
    }
  }
  std::optional<ListenOptions> listen;
  const std::optional<std::string> token_file = arguments.text("token-file");
  const std::optional<Index> max_connections = arguments.integer("max-connections");
  const std::optional<Index> idle_timeout = arguments.integer("idle-timeout-ms");
  const std::optional<std::string> listen_text = arguments.text("listen");
  for (const auto& [given, name] : {std::pair{token_file.has_value(), "--token-file"},
                                    std::pair{max_connections.has_value(), "--max-connections"},
                                    std::pair{idle_timeout.has_value(), "--idle-timeout-ms"}}) {
    if (given && !listen_text) {
      throw InvalidArgumentError(
          name, fmt::format("{}: is given without --listen; rule: it sets the listener", name));
    }
  }
  if (const auto& v = listen_text) {
    ListenOptions options;
    if (v->starts_with("unix:")) {
      options.unix_socket = v->substr(5);
    } else {
      const std::size_t colon = v->rfind(':');
      if (colon != std::string::npos) options.host = v->substr(0, colon);
      const std::string port = colon == std::string::npos ? *v : v->substr(colon + 1);
      const auto [end, error] =
          std::from_chars(port.data(), port.data() + port.size(), options.port);
      if (error != std::errc{} || end != port.data() + port.size()) {
        throw InvalidArgumentError(
            "--listen",
            fmt::format("--listen: is \"{}\"; rule: [HOST:]PORT (PORT an integer) or unix:PATH",
                        *v));
      }
    }
    if (token_file) options.token = read_token(*token_file);
    if (max_connections) {
      if (*max_connections < 1 || *max_connections > 1'000'000) {
        throw InvalidArgumentError(
            "--max-connections",
            fmt::format("--max-connections: is {}; rule: 1 … 1000000", *max_connections));
      }
      options.max_connections = static_cast<int>(*max_connections);
    }
    if (idle_timeout) options.idle_timeout = std::chrono::milliseconds(*idle_timeout);
    require_valid("--listen", options);
    listen = options;
  }
  std::int64_t snapshot_interval = ServeOptions{}.snapshot_interval;
  if (const auto v = arguments.integer("snapshot-every")) {
    if (*v < 0) {
      throw InvalidArgumentError(
          "--snapshot-every",
          fmt::format("--snapshot-every: is {}; rule: must be >= 0 (0: no snapshots)", *v));
    }
    snapshot_interval = *v;
  }
  const bool verify_all = arguments.flag("verify-all");
  std::function<ServeSession()> open_session;
  if (arguments.flag("resume")) {
    arguments.require_all_read();  // the settings are the database's
    const ResumeOptions resume{durability, snapshot_interval, verify_all};
    open_session = [&, resume] {
      ServeSession resumed = ServeSession::resume(*database, resume);
      const nlohmann::json state = resumed.state();
      fmt::print(stderr, "twincal serve: resumed {}: {} observations{}\n", *database,
                 resumed.observed(),
                 state["pending"].is_null()
                     ? std::string()
                     : fmt::format(", request {} awaits its observation",
                                   state["pending"]["request_id"].get<std::int64_t>()));
      return resumed;
    };
  } else {
    ServeOptions options;
    options.config = read_config(arguments, {ControllerSpec::active()});
    if (const auto v = arguments.text("case")) {
      options.config.twin_case = parse_enum<TwinCase>(*v, "--case");
    }
    if (const auto v = arguments.text("locators")) options.config.locators = *v;
    if (options.config.controllers.size() != 1) {
      throw InvalidArgumentError(
          "--controller", fmt::format("--controller: names {} controllers; rule: serve runs one",
                                      options.config.controllers.size()));
    }
    options.controller = options.config.controllers.front();
    if (const auto v = arguments.integer("run")) options.run = *v;
    options.durability = durability;
    options.snapshot_interval = snapshot_interval;
    if (verify_all) {
      throw InvalidArgumentError("--verify-all",
                                 "--verify-all: given without --resume; rule: it sets how a "
                                 "resume replays the history");
    }
    arguments.require_all_read();
    require_valid("options", options);
    open_session = [&, options] { return ServeSession::start(options, *database); };
  }
  // A client that disconnects mid-reply must end its connection, not the server.
  std::signal(SIGPIPE, SIG_IGN);
  std::optional<ServeSession> session;
  if (listen) {
    // Bound before the session opens: a port in use leaves no new database behind.
    serve_connections(
        *listen, [&]() -> ServeSession& { return session.emplace(open_session()); },
        [&](int port) {
          if (listen->unix_socket) {
            fmt::print(stderr, "twincal serve: listening on unix:{}\n",
                       listen->unix_socket->string());
          } else {
            fmt::print(stderr, "twincal serve: listening on {}:{}\n", listen->host, port);
          }
          std::fflush(stderr);
        });
  } else {
    session.emplace(open_session());
    serve_stream(*session, STDIN_FILENO, STDOUT_FILENO);
  }
  return 0;
}

}  // namespace twincal::cli
