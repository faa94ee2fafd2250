#include "twincal/experiments/episode_trace.hpp"

#include <cstdint>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/result_store.hpp"

namespace twincal {
namespace {

// A step report's value as a CSV field (its JSON encodes NaN as null and ±∞ as strings).
std::string field(const nlohmann::json& value) {
  if (value.is_null()) return "nan";
  if (value.is_boolean()) return value.get<bool>() ? "true" : "false";
  if (value.is_number_integer()) return fmt::format("{}", value.get<std::int64_t>());
  if (value.is_number()) return csv_number(value.get<double>());
  if (value.is_string()) return value.get<std::string>();
  throw InvalidArgumentError("step_report",
                             fmt::format("step_report: holds {}; rule: a step report's values "
                                         "are numbers, booleans, null or \"inf\" / \"-inf\"",
                                         value.dump()));
}

}  // namespace

EpisodeResult write_episode_trace(const CaseTwin& twin, const ExperimentConfig& config,
                                  const ControllerSpec& controller, Index run, std::ostream& out) {
  std::string report_keys;
  std::string line;
  const auto write_row = [&](Index t, const EpisodeResult& result,
                             const AnyController& episode_controller) {
    const nlohmann::json report = episode_controller.step_report();
    if (t == 0) {
      for (const auto& item : report.items()) report_keys += "," + item.key();
      out << episode_trace_columns << report_keys << '\n';
    }
    const AssemblyId& x = result.assemblies[static_cast<std::size_t>(t)];
    line = fmt::format("{},{},{},{},{},{},{},{},{},{}", t, x.upper, x.lower,
                       csv_number(result.z(t)), csv_number(result.z_star(t)),
                       csv_number((result.z(t) - result.z_star(t)) / result.z_star(t)),
                       csv_number((result.estimate.col(t) - result.offset.col(t)).norm()),
                       csv_number(result.offset.col(t).norm()), csv_number(result.trace_p(t)),
                       csv_number(result.q_evaluations(t)));
    for (const auto& item : report.items()) line += "," + field(item.value());
    out << line << '\n' << std::flush;
    if (!out) throw Error("trace", "trace: the output cannot be written");
  };
  EpisodeResult result = run_episode(twin, config, controller, run, write_row);
  // An episode that failed at its first assembly still gets its header.
  if (result.steps == 0) out << episode_trace_columns << '\n' << std::flush;
  return result;
}

}  // namespace twincal
