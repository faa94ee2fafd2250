// ExternalTwinSettings (external_twin_settings.hpp): checks and JSON.
#include "twincal/experiments/external_twin_settings.hpp"

#include <array>
#include <cmath>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "twincal/controllers/least_squares_search.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/experiments/strict_json.hpp"

namespace twincal {

namespace {

// Each locator's box is finite and not empty: u0 is searched from its centre.
std::optional<std::string> box_problem(const std::vector<std::string>& locators,
                                       const std::vector<double>& lower,
                                       const std::vector<double>& upper) {
  for (std::size_t i = 0; i < locators.size(); ++i) {
    if (!std::isfinite(lower[i]) || !std::isfinite(upper[i]) || !(lower[i] < upper[i])) {
      return fmt::format(
          "bounds of {}: value is [{}, {}]; rule: finite, lower < upper (u0 is searched from the "
          "centre of the box)",
          locators[i], lower[i], upper[i]);
    }
  }
  return std::nullopt;
}

// A command: a list of arguments, or one string split at blanks (no quoting: the list form
// for arguments with blanks).
std::vector<std::string> command_of(const nlohmann::json& value) {
  if (!value.is_string()) return value.get<std::vector<std::string>>();
  std::vector<std::string> command;
  const std::string text = value.get<std::string>();
  std::size_t begin = text.find_first_not_of(' ');
  while (begin != std::string::npos) {
    const std::size_t end = text.find(' ', begin);
    command.push_back(text.substr(begin, end - begin));
    begin = text.find_first_not_of(' ', end);
  }
  return command;
}

}  // namespace

std::optional<std::string> ExternalTwinSettings::validate() const {
  const auto d = std::ssize(locators);
  const bool sized = std::ssize(lower_bounds) == d && std::ssize(upper_bounds) == d;
  return first_problem(
      {rule::check(!command.empty() && !command.front().empty(), "command", "empty",
                   "must name the twin's program"),
       rule::check(d >= 1, "locators", "empty", "must name >= 1 locator"),
       rule::check_fields(sized, "lower_bounds and upper_bounds",
                          std::array{std::ssize(lower_bounds), std::ssize(upper_bounds)},
                          "one entry per locator ({}) each", d),
       sized ? box_problem(locators, lower_bounds, upper_bounds) : std::nullopt,
       rule::check(upper_parts >= 1 && upper_parts <= max_parts, "upper_parts", upper_parts,
                   "must lie in [1, {}]", max_parts),
       rule::check(lower_parts >= 1 && lower_parts <= max_parts, "lower_parts", lower_parts,
                   "must lie in [1, {}]", max_parts),
       rule::check(workers >= 1 && workers <= 256, "workers", workers, "must lie in [1, 256]"),
       rule::at_least("optimum_global_evaluations", optimum_global_evaluations, Index{0}),
       rule::at_least("optimum_local_evaluations", optimum_local_evaluations, Index{1}),
       rule::check(optimum_budget >= 0 && optimum_budget <= 1000000, "optimum_budget",
                   optimum_budget, "must lie in [0, 1000000] (0: the full search)"),
       rule::check(
           optimum_budget <= 0 || optimum_budget >= 2 * d + 2, "optimum_budget", optimum_budget,
           "0 or >= 2d + 2 = {} (BOBYQA's first model needs 2d + 1 evaluations)", 2 * d + 2),
       rule::check(optimum_method == "bobyqa" || optimum_method == "trust_region" ||
                       least_squares_method(optimum_method),
                   "optimum_method", optimum_method,
                   "must be bobyqa, trust_region, least_squares or least_squares_speculative"),
       rule::check(key_points >= 0 && key_points <= max_key_points, "key_points", key_points,
                   "must lie in [0, {}]", max_key_points),
       rule::check(!least_squares_method(optimum_method) || key_points >= 1, "optimum_method",
                   optimum_method,
                   "least_squares needs a program that answers its key points' deviations "
                   "(key_points >= 1)"),
       rule::check(optimum_start_command.empty() ||
                       (optimum_budget > 0 && !optimum_start_command.front().empty()),
                   "optimum_start_command",
                   fmt::format("[{}]", fmt::join(optimum_start_command, ", ")),
                   "must be empty or name a program, and needs a budgeted search "
                   "(optimum_budget > 0 = {})",
                   optimum_budget),
       rule::at_least("timeout_ms", timeout_ms, Index{1}),
       rule::at_least("startup_grace_ms", startup_grace_ms, Index{0})});
}

bool least_squares_method(const std::string& method) noexcept {
  return method == "least_squares" || method == "least_squares_speculative";
}

LeastSquaresSearchOptions least_squares_options(const std::string& method,
                                                std::uint64_t evaluations) {
  return {.evaluations = evaluations,
          .speculative_jacobian = method == "least_squares_speculative"};
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
          {"optimum_budget", settings.optimum_budget},
          {"optimum_method", settings.optimum_method},
          {"optimum_seed", settings.optimum_seed},
          {"key_points", settings.key_points},
          {"optimum_start_command", settings.optimum_start_command},
          {"optima_file", settings.optima_file}};
}

nlohmann::json result_defining_json(const ExternalTwinSettings& settings) {
  nlohmann::json json = settings;
  json.erase("workers");
  json.erase("timeout_ms");
  json.erase("startup_grace_ms");
  json.erase("optima_file");
  // The deviations and the restarts' seed matter only to a least-squares u0 search (and
  // results stored before they existed stay the same group).
  if (!least_squares_method(settings.optimum_method) || settings.optimum_budget == 0) {
    json.erase("key_points");
    json.erase("optimum_seed");
  }
  if (settings.optimum_start_command.empty()) json.erase("optimum_start_command");
  return json;
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
        read.command = command_of(value);
      } else if (key == "optimum_start_command") {
        read.optimum_start_command = command_of(value);
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
      } else if (key == "optimum_method") {
        read.optimum_method = value.get<std::string>();
      } else if (key == "optimum_seed") {
        read.optimum_seed = strict_value<std::uint64_t>(value, field);
      } else if (key == "key_points") {
        read.key_points = strict_value<Index>(value, field);
      } else if (key == "optima_file") {
        read.optima_file = value.get<std::string>();
      } else {
        throw InvalidArgumentError(
            field, fmt::format("config: key \"{}\" is unknown; rule: must be one of [command, "
                               "locators, lower_bounds, upper_bounds, upper_parts, lower_parts, "
                               "workers, timeout_ms, startup_grace_ms, optimum_global_evaluations, "
                               "optimum_local_evaluations, optimum_budget, optimum_method, "
                               "optimum_seed, key_points, optimum_start_command, optima_file]",
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
