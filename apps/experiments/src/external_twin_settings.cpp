// ExternalTwinSettings (external_twin_settings.hpp): checks and JSON.
#include "twincal/experiments/external_twin_settings.hpp"

#include <cmath>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/experiments/strict_json.hpp"

namespace twincal {

std::optional<std::string> ExternalTwinSettings::validate() const {
  if (command.empty() || command.front().empty()) {
    return "external_twin.command is empty; rule: must name the twin's program";
  }
  if (locators.empty()) return "external_twin.locators is empty; rule: must name >= 1 locator";
  const std::size_t d = locators.size();
  if (lower_bounds.size() != d || upper_bounds.size() != d) {
    return fmt::format(
        "external_twin.lower_bounds and upper_bounds have {} and {} entries; rule: one per "
        "locator ({})",
        lower_bounds.size(), upper_bounds.size(), d);
  }
  for (std::size_t i = 0; i < d; ++i) {
    if (!std::isfinite(lower_bounds[i]) || !std::isfinite(upper_bounds[i]) ||
        !(lower_bounds[i] < upper_bounds[i])) {
      return fmt::format(
          "external_twin bounds of {} are [{}, {}]; rule: finite, lower < upper (u0 is searched "
          "from the centre of the box)",
          locators[i], lower_bounds[i], upper_bounds[i]);
    }
  }
  if (upper_parts < 1 || upper_parts > max_parts || lower_parts < 1 || lower_parts > max_parts) {
    return fmt::format(
        "external_twin.upper_parts and lower_parts are {} and {}; rule: each in "
        "[1, {}]",
        upper_parts, lower_parts, max_parts);
  }
  if (workers < 1 || workers > 256) {
    return fmt::format("external_twin.workers is {}; rule: must lie in [1, 256]", workers);
  }
  if (optimum_global_evaluations < 0 || optimum_local_evaluations < 1) {
    return fmt::format(
        "external_twin.optimum_global_evaluations and optimum_local_evaluations "
        "are {} and {}; rule: >= 0 and >= 1",
        optimum_global_evaluations, optimum_local_evaluations);
  }
  if (optimum_budget < 0 || optimum_budget > 1000000) {
    return fmt::format(
        "external_twin.optimum_budget is {}; rule: must lie in [0, 1000000] "
        "(0: the full search)",
        optimum_budget);
  }
  if (optimum_budget > 0 && optimum_budget < 2 * static_cast<Index>(locators.size()) + 2) {
    return fmt::format(
        "external_twin.optimum_budget is {}; rule: 0 or >= 2d + 2 = {} (BOBYQA's "
        "first model needs 2d + 1 evaluations)",
        optimum_budget, 2 * locators.size() + 2);
  }
  if (timeout_ms < 1) {
    return fmt::format("external_twin.timeout_ms is {}; rule: must be >= 1", timeout_ms);
  }
  if (startup_grace_ms < 0) {
    return fmt::format("external_twin.startup_grace_ms is {}; rule: must be >= 0",
                       startup_grace_ms);
  }
  return std::nullopt;
}

void to_json(nlohmann::json& json, const ExternalTwinSettings& settings) {
  json = {{"command", settings.command},
          {"locators", settings.locators},
          {"lower_bounds", settings.lower_bounds},
          {"upper_bounds", settings.upper_bounds},
          {"upper_parts", settings.upper_parts},
          {"lower_parts", settings.lower_parts},
          {"workers", settings.workers},
          {"timeout_ms", settings.timeout_ms},
          {"startup_grace_ms", settings.startup_grace_ms},
          {"optimum_global_evaluations", settings.optimum_global_evaluations},
          {"optimum_local_evaluations", settings.optimum_local_evaluations},
          {"optimum_budget", settings.optimum_budget}};
}

void from_json(const nlohmann::json& json, ExternalTwinSettings& settings) {
  if (!json.is_object()) {
    throw InvalidArgumentError(
        "external_twin",
        fmt::format("external_twin: is {}; rule: must be a JSON object", json.dump()));
  }
  ExternalTwinSettings read = settings;  // untouched on error
  for (const auto& [key, value] : json.items()) {
    const std::string field = "external_twin." + key;
    try {
      if (key == "command") {
        // Also one string, split at blanks (no quoting: use the list form for arguments with
        // blanks).
        if (value.is_string()) {
          read.command.clear();
          const std::string text = value.get<std::string>();
          std::size_t begin = text.find_first_not_of(' ');
          while (begin != std::string::npos) {
            const std::size_t end = text.find(' ', begin);
            read.command.push_back(text.substr(begin, end - begin));
            begin = text.find_first_not_of(' ', end);
          }
        } else {
          read.command = value.get<std::vector<std::string>>();
        }
      } else if (key == "locators") {
        read.locators = value.get<std::vector<std::string>>();
      } else if (key == "lower_bounds") {
        read.lower_bounds = value.get<std::vector<double>>();
      } else if (key == "upper_bounds") {
        read.upper_bounds = value.get<std::vector<double>>();
      } else if (key == "upper_parts") {
        read.upper_parts = strict_value<Index>(value, field);
      } else if (key == "lower_parts") {
        read.lower_parts = strict_value<Index>(value, field);
      } else if (key == "workers") {
        read.workers = strict_value<Index>(value, field);
      } else if (key == "timeout_ms") {
        read.timeout_ms = strict_value<Index>(value, field);
      } else if (key == "startup_grace_ms") {
        read.startup_grace_ms = strict_value<Index>(value, field);
      } else if (key == "optimum_global_evaluations") {
        read.optimum_global_evaluations = strict_value<Index>(value, field);
      } else if (key == "optimum_local_evaluations") {
        read.optimum_local_evaluations = strict_value<Index>(value, field);
      } else if (key == "optimum_budget") {
        read.optimum_budget = strict_value<Index>(value, field);
      } else {
        throw InvalidArgumentError(
            field, fmt::format("config: key \"{}\" is unknown; rule: must be one of [command, "
                               "locators, lower_bounds, upper_bounds, upper_parts, lower_parts, "
                               "workers, timeout_ms, startup_grace_ms, optimum_global_evaluations, "
                               "optimum_local_evaluations, optimum_budget]",
                               field));
      }
    } catch (const nlohmann::json::exception& error) {
      throw InvalidArgumentError(
          field, fmt::format("{}: is {}; rule: {}", field, value.dump(), error.what()));
    }
  }
  settings = std::move(read);
}

}  // namespace twincal
