#include "twincal/experiments/experiment_runner.hpp"

#include <exception>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/stopwatch.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/study_schedule.hpp"
#include "twincal/experiments/twin_cases.hpp"

namespace twincal {

Index require_study_fits(std::span<const ExperimentGroup> groups) {
  std::set<std::string> names;
  Index episodes = 0;
  for (const ExperimentGroup& group : groups) {
    const std::string name = group.config.group_name();
    require_valid(fmt::format("group \"{}\"", name), group.config);
    require_episodes_fit(group.config);
    if (!names.insert(name).second) {
      throw InvalidArgumentError(
          "groups",
          fmt::format("groups: \"{}\" appears twice; rule: group names are unique", name));
    }
    // runs <= max_runs and the controllers a config can list keep each product far below 2^63;
    // the sum is checked against the limit before it can grow past it.
    const Index count = group.config.runs * std::ssize(group.config.controllers);
    if (count > max_study_episodes - episodes) {
      throw InvalidArgumentError(
          "episodes",
          fmt::format("episodes: the study plans {} or more (group \"{}\": {} runs x {} "
                      "controllers); rule: at most max_study_episodes = {} per study (each "
                      "episode's metrics stay in memory, about 3 KB) — split it into studies",
                      episodes + count, name, group.config.runs, group.config.controllers.size(),
                      max_study_episodes));
    }
    episodes += count;
  }
  return episodes;
}

void require_twin_has_assemblies(const ExperimentConfig& config, const CaseTwin& twin) {
  if (config.assemblies > std::ssize(twin.assemblies())) {
    throw InvalidArgumentError(
        "assemblies",
        fmt::format("assemblies: is {} in group \"{}\"; rule: must be <= the twin's {} "
                    "assemblies",
                    config.assemblies, config.group_name(), twin.assemblies().size()));
  }
}

std::vector<CaseTwin> make_study_twins(std::span<const ExperimentGroup> groups,
                                       const ExternalTwinBackendFactory& backend) {
  (void)require_study_fits(groups);
  // u0(x), z*(x) once per group for all its episodes.
  std::vector<CaseTwin> twins = make_case_twins(groups, backend);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    require_twin_has_assemblies(groups[g].config, twins[g]);
  }
  return twins;
}

RunReport run_experiments(std::span<const ExperimentGroup> groups, ResultStore& store,
                          const RunOptions& options, const ExternalTwinBackendFactory& backend) {
  require_valid("RunOptions", options);
  const Stopwatch watch;
  const std::vector<CaseTwin> twins = make_study_twins(groups, backend);
  const double setup_seconds = watch.seconds();
  StudySchedule schedule(groups, twins, store, options.shard, options.progress);

  const Index hardware = static_cast<Index>(std::thread::hardware_concurrency());
  const Index threads = std::max<Index>(
      1, std::min<Index>(options.threads > 0 ? options.threads : std::max<Index>(hardware, 1),
                         schedule.planned_now()));
  const auto worker = [&] { schedule.run_episodes(groups, twins); };
  {
    std::vector<std::jthread> pool;
    for (Index k = 1; k < threads; ++k) pool.emplace_back(worker);
    worker();
  }
  RunReport report = schedule.conclude();
  report.seconds = watch.seconds();
  report.setup_seconds = setup_seconds;
  return report;
}

}  // namespace twincal
