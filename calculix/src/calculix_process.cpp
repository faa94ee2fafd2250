#include "twincal/calculix/calculix_process.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "twincal/external/child_groups.hpp"

extern char** environ;

namespace twincal {
namespace {

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return std::move(text).str();
}

// The caller's environment with the solver's thread counts set (CalculiX reads all four).
std::vector<std::string> solver_environment(Index threads) {
  std::vector<std::string> variables;
  const std::string count = std::to_string(threads);
  constexpr std::string_view names[] = {"OMP_NUM_THREADS", "CCX_NPROC_EQUATION_SOLVER",
                                        "CCX_NPROC_STIFFNESS", "CCX_NPROC_RESULTS"};
  for (char** entry = environ; *entry != nullptr; ++entry) {
    const std::string_view variable(*entry);
    bool replaced = false;
    for (const std::string_view name : names) {
      replaced = replaced || (variable.starts_with(name) && variable.size() > name.size() &&
                              variable[name.size()] == '=');
    }
    if (!replaced) variables.emplace_back(variable);
  }
  for (const std::string_view name : names) variables.push_back(fmt::format("{}={}", name, count));
  return variables;
}

}  // namespace

CalculixRun run_calculix(const CalculixOptions& options, const std::filesystem::path& directory,
                         std::string_view job, std::string_view deck) {
  const std::filesystem::path input = directory / fmt::format("{}.inp", job);
  const std::filesystem::path log_path = directory / fmt::format("{}.log", job);
  {
    std::ofstream out(input, std::ios::binary);
    out.write(deck.data(), static_cast<std::streamsize>(deck.size()));
    if (!out) {
      throw CalculixError(CalculixFailure::crashed,
                          fmt::format("calculix: cannot write the deck {}", input.string()), "");
    }
  }
  std::vector<std::string> environment = solver_environment(options.solver_threads);
  std::vector<char*> envp;
  for (std::string& variable : environment) envp.push_back(variable.data());
  envp.push_back(nullptr);
  std::string executable = options.executable;
  std::string flag = "-i";
  std::string job_name(job);
  std::vector<char*> argv{executable.data(), flag.data(), job_name.data(), nullptr};

  posix_spawn_file_actions_t actions;
  posix_spawnattr_t attributes;
  posix_spawn_file_actions_init(&actions);
  posix_spawnattr_init(&attributes);
  posix_spawn_file_actions_addchdir_np(&actions, directory.c_str());
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  sigset_t defaults;
  sigset_t empty;
  sigfillset(&defaults);
  sigemptyset(&empty);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setsigmask(&attributes, &empty);
  posix_spawnattr_setpgroup(&attributes, 0);
  posix_spawnattr_setflags(&attributes,
                           POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  pid_t pid = 0;
  const auto started = std::chrono::steady_clock::now();
  const int spawned =
      ::posix_spawnp(&pid, executable.c_str(), &actions, &attributes, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (spawned != 0) {
    throw CalculixError(CalculixFailure::missing_executable,
                        fmt::format("calculix: cannot start '{}': {}; rule: executable names the "
                                    "CalculiX solver (Debian: apt-get install calculix-ccx)",
                                    options.executable, std::strerror(spawned)),
                        "");
  }
  child_groups::add(pid);
  // Poll with a growing pause: a solve takes 0.05 s to minutes, and a sleeping parent costs
  // the solver nothing.
  const auto deadline = started + options.timeout;
  auto pause = std::chrono::microseconds(200);
  int status = 0;
  pid_t reaped = 0;
  while ((reaped = ::waitpid(pid, &status, WNOHANG)) == 0 || (reaped < 0 && errno == EINTR)) {
    if (std::chrono::steady_clock::now() >= deadline) {
      ::kill(-pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      child_groups::remove(pid);
      throw CalculixError(
          CalculixFailure::timeout,
          fmt::format("calculix: the solver ran longer than {} ms and was killed; rule: "
                      "options.timeout bounds one run",
                      options.timeout.count()),
          log_tail(read_file(log_path)));
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(20000));
  }
  child_groups::remove(pid);
  CalculixRun run;
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  run.log = read_file(log_path);
  if (WIFSIGNALED(status)) {
    throw CalculixError(
        CalculixFailure::crashed,
        fmt::format("calculix: the solver was ended by signal {}", WTERMSIG(status)),
        log_tail(run.log));
  }
  run.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.dat = read_file(directory / fmt::format("{}.dat", job));
  return run;
}

std::optional<CalculixFailure> classify(const CalculixRun& run) {
  const std::string_view log = run.log;
  const bool any_error = log.find("*ERROR") != std::string_view::npos;
  if (run.exit_status == 0 && !any_error) return std::nullopt;
  for (const std::string_view sign : {"too many cutbacks", "increment size smaller than minimum",
                                      "max. # of increments", "divergence", "no convergence"}) {
    if (log.find(sign) != std::string_view::npos && log.find("STEP") != std::string_view::npos) {
      return CalculixFailure::no_convergence;
    }
  }
  if (any_error) return CalculixFailure::deck_error;
  return CalculixFailure::crashed;
}

std::string log_tail(std::string_view log, int lines) {
  std::size_t start = log.size();
  int seen = 0;
  while (start > 0 && seen <= lines) {
    --start;
    if (log[start] == '\n') ++seen;
  }
  std::string tail(log.substr(start == 0 ? 0 : start + 1));
  return tail;
}

}  // namespace twincal
