#include "twincal/experiments/episode_trace.hpp"

#include <cstdint>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/core/error.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/result_store.hpp"

namespace twincal {
namespace {

// A step report's value as a CSV field: booleans and counts as themselves, numbers decoded as
// the report wrote them (null: NaN, "inf" / "-inf": ±∞; json_state::read_double refuses others).
std::string field(const std::string& key, const nlohmann::json& value) {
  if (value.is_boolean()) return value.get<bool>() ? "true" : "false";
  if (value.is_number_integer()) return fmt::format("{}", value.get<std::int64_t>());
  return csv_number(json_state::read_double(value, key, json_state::Values::any));
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
    line = fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}", t, x.upper, x.lower,
                       csv_number(result.z(t)), csv_number(result.z_star(t)),
                       csv_number((result.z(t) - result.z_star(t)) / result.z_star(t)),
                       csv_number((result.estimate.col(t) - result.offset.col(t)).norm()),
                       csv_number(result.offset.col(t).norm()), csv_number(result.trace_p(t)),
                       csv_number(result.q_evaluations(t)),
                       episode_controller.fallback().empty() ? "false" : "true",
                       episode_controller.dropped_measurement().empty() ? "false" : "true");
    for (const auto& item : report.items()) line += "," + field(item.key(), item.value());
    out << line << '\n' << std::flush;
    if (!out) throw Error("trace", "trace: the output cannot be written");
  };
  EpisodeResult result = run_episode(twin, config, controller, run, write_row);
  // An episode that failed at its first assembly still gets its header.
  if (result.steps == 0) out << episode_trace_columns << '\n' << std::flush;
  return result;
}

}  // namespace twincal
