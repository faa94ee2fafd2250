#include "twincal/experiments/active_options_json.hpp"

#include <algorithm>
#include <array>
#include <span>
#include <string>
#include <type_traits>
#include <variant>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/experiments/strict_json.hpp"

namespace twincal {
namespace {

// One row per setting, its JSON key the member's name: one table writes, reads and lists them.
template <typename Options>
struct OptionField {
  std::string_view key;
  std::variant<double Options::*, Index Options::*, int Options::*, bool Options::*> member;
};

constexpr std::array<OptionField<ActiveOptions>, 28> active_fields{{
    {"process_variance", &ActiveOptions::process_variance},
    {"min_process_variance", &ActiveOptions::min_process_variance},
    {"max_process_variance", &ActiveOptions::max_process_variance},
    {"adaptation_rate", &ActiveOptions::adaptation_rate},
    {"max_horizon", &ActiveOptions::max_horizon},
    {"max_probe_fraction", &ActiveOptions::max_probe_fraction},
    {"max_offset_fraction", &ActiveOptions::max_offset_fraction},
    {"clamp_beyond_reach", &ActiveOptions::clamp_beyond_reach},
    {"correction_step_fraction", &ActiveOptions::correction_step_fraction},
    {"surprise_step_fraction", &ActiveOptions::surprise_step_fraction},
    {"hold_after_surprises", &ActiveOptions::hold_after_surprises},
    {"trial_innovations", &ActiveOptions::trial_innovations},
    {"audit_after_failed_trial", &ActiveOptions::audit_after_failed_trial},
    {"innovation_gate", &ActiveOptions::innovation_gate},
    {"covariance_floor", &ActiveOptions::covariance_floor},
    {"covariance_ceiling_fraction", &ActiveOptions::covariance_ceiling_fraction},
    {"quadratic_retry", &ActiveOptions::quadratic_retry},
    {"weigh_model_error", &ActiveOptions::weigh_model_error},
    {"relinearization_budget", &ActiveOptions::relinearization_budget},
    {"relinearization_reach", &ActiveOptions::relinearization_reach},
    {"regret_probe", &ActiveOptions::regret_probe},
    {"regret_window", &ActiveOptions::regret_window},
    {"erring_probe_gain", &ActiveOptions::erring_probe_gain},
    {"audit_period", &ActiveOptions::audit_period},
    {"audit_window", &ActiveOptions::audit_window},
    {"audit_misfit", &ActiveOptions::audit_misfit},
    {"fit_at_audited_arm", &ActiveOptions::fit_at_audited_arm},
    {"change_test_after_refit", &ActiveOptions::change_test_after_refit},
}};

constexpr std::array<OptionField<ConstantVelocityOptions>, 21> trajectory_fields{{
    {"initial_position_fraction", &ConstantVelocityOptions::initial_position_fraction},
    {"position_fraction", &ConstantVelocityOptions::position_fraction},
    {"max_position_fraction", &ConstantVelocityOptions::max_position_fraction},
    {"velocity_fraction", &ConstantVelocityOptions::velocity_fraction},
    {"change_gate", &ConstantVelocityOptions::change_gate},
    {"change_window", &ConstantVelocityOptions::change_window},
    {"innovation_window", &ConstantVelocityOptions::innovation_window},
    {"misfit_window", &ConstantVelocityOptions::misfit_window},
    {"max_misfit_scale", &ConstantVelocityOptions::max_misfit_scale},
    {"min_gate_unit", &ConstantVelocityOptions::min_gate_unit},
    {"min_erring_gate_unit", &ConstantVelocityOptions::min_erring_gate_unit},
    {"min_erring_fit_unit", &ConstantVelocityOptions::min_erring_fit_unit},
    {"change_lag", &ConstantVelocityOptions::change_lag},
    {"change_position_spread", &ConstantVelocityOptions::change_position_spread},
    {"change_velocity_spread", &ConstantVelocityOptions::change_velocity_spread},
    {"change_velocity_floor_fraction", &ConstantVelocityOptions::change_velocity_floor_fraction},
    {"change_position_floor_fraction", &ConstantVelocityOptions::change_position_floor_fraction},
    {"significance", &ConstantVelocityOptions::significance},
    {"max_history", &ConstantVelocityOptions::max_history},
    {"max_iterations", &ConstantVelocityOptions::max_iterations},
    {"step_tolerance", &ConstantVelocityOptions::step_tolerance},
}};

constexpr std::array<OptionField<QuadraticSurrogateOptions>, 5> surrogate_fields{{
    {"step_fraction", &QuadraticSurrogateOptions::step_fraction},
    {"quality_step_fraction", &QuadraticSurrogateOptions::quality_step_fraction},
    {"hessian_refresh", &QuadraticSurrogateOptions::hessian_refresh},
    {"tolerance", &QuadraticSurrogateOptions::tolerance},
    {"from_deviations", &QuadraticSurrogateOptions::from_deviations},
}};

// The settings that are the config's own keys, not the active object's.
constexpr std::array<std::string_view, 2> config_owned{"measurement_variance", "initial_variance"};

template <typename Options, std::size_t Size>
void write_changed(nlohmann::json& out, const Options& options,
                   const std::array<OptionField<Options>, Size>& table) {
  const Options defaults{};
  for (const OptionField<Options>& field : table) {
    std::visit(
        [&](auto member) {
          if (options.*member != defaults.*member) out[std::string(field.key)] = options.*member;
        },
        field.member);
  }
}

template <typename Options, std::size_t Size>
std::string known_keys(const std::array<OptionField<Options>, Size>& table,
                       std::span<const std::string_view> sections) {
  std::string known;
  for (const OptionField<Options>& field : table) {
    known += (known.empty() ? "" : ", ") + std::string(field.key);
  }
  for (std::string_view section : sections) known += ", " + std::string(section);
  return known;
}

void require_object(const nlohmann::json& value, const std::string& path) {
  if (!value.is_object()) {
    throw InvalidArgumentError(
        path, fmt::format("{}: is {}; rule: must be a JSON object", path, value.dump()));
  }
}

// Reads one key of `table` into `options`; false when the table has no such key.
template <typename Options, std::size_t Size>
bool read_field(const std::string& key, const nlohmann::json& value, const std::string& path,
                Options& options, const std::array<OptionField<Options>, Size>& table) {
  for (const OptionField<Options>& field : table) {
    if (field.key != key) continue;
    std::visit(
        [&](auto member) {
          using Value = std::remove_reference_t<decltype(options.*member)>;
          if constexpr (std::is_same_v<Value, bool>) {
            if (!value.is_boolean()) {
              throw InvalidArgumentError(
                  path, fmt::format("{}: is {}; rule: true or false", path, value.dump()));
            }
          }
          options.*member = strict_value<Value>(value, path);
        },
        field.member);
    return true;
  }
  return false;
}

template <typename Options, std::size_t Size>
void read_section(const nlohmann::json& section, const std::string& path, Options& options,
                  const std::array<OptionField<Options>, Size>& table) {
  require_object(section, path);
  for (const auto& [key, value] : section.items()) {
    const std::string field = path + "." + key;
    if (!read_field(key, value, field, options, table)) {
      throw InvalidArgumentError(
          field, fmt::format("{}: key \"{}\" is unknown; rule: must be one of [{}]", field, key,
                             known_keys(table, {})));
    }
  }
}

}  // namespace

nlohmann::json active_overrides(const ActiveOptions& options) {
  nlohmann::json out = nlohmann::json::object();
  write_changed(out, options, active_fields);
  nlohmann::json trajectory = nlohmann::json::object();
  write_changed(trajectory, options.trajectory, trajectory_fields);
  if (!trajectory.empty()) out["trajectory"] = std::move(trajectory);
  nlohmann::json surrogate = nlohmann::json::object();
  write_changed(surrogate, options.surrogate, surrogate_fields);
  if (!surrogate.empty()) out["surrogate"] = std::move(surrogate);
  return out;
}

void apply_active_overrides(const nlohmann::json& overrides, ActiveOptions& options,
                            std::string_view path) {
  const std::string root(path);
  require_object(overrides, root);
  ActiveOptions read = options;  // untouched on error
  for (const auto& [key, value] : overrides.items()) {
    const std::string field = root + "." + key;
    if (key == "trajectory") {
      read_section(value, field, read.trajectory, trajectory_fields);
    } else if (key == "surrogate") {
      read_section(value, field, read.surrogate, surrogate_fields);
    } else if (std::find(config_owned.begin(), config_owned.end(), key) != config_owned.end()) {
      throw InvalidArgumentError(
          field, fmt::format("{}: is {}; rule: not a key of {}: it has its own, \"{}\", beside "
                             "it (every controller shares it)",
                             field, value.dump(), root, key));
    } else if (!read_field(key, value, field, read, active_fields)) {
      constexpr std::array<std::string_view, 2> sections{"trajectory", "surrogate"};
      throw InvalidArgumentError(
          field, fmt::format("{}: key \"{}\" is unknown; rule: must be one of [{}]", field, key,
                             known_keys(active_fields, sections)));
    }
  }
  options = std::move(read);
}

}  // namespace twincal
