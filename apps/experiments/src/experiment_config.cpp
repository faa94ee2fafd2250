#include "twincal/experiments/experiment_config.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <string_view>
#include <type_traits>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/core/named_enum.hpp"
#include "twincal/core/options.hpp"
#include "twincal/experiments/active_options_json.hpp"
#include "twincal/experiments/strict_json.hpp"

namespace twincal {

std::string ExperimentConfig::group_name() const {
  return name.empty() ? fmt::format("{}/{}", to_string(twin_case), locators) : name;
}

double ExperimentConfig::filter_measurement_variance() const {
  if (measurement_variance) return *measurement_variance;
  // The paper's σz², Sec. 2.4; the door with contact is the door.
  return twin_case == TwinCase::door || twin_case == TwinCase::door_contact
             ? PaperSettings::door_measurement_variance
             : PaperSettings{}.measurement_variance;
}

Index ExperimentConfig::candidate_count(Index d) const {
  constexpr Index largest_exponent = 62;  // 2^62 still fits an Index
  const Index count = candidates.value_or(Index{1} << std::min(Index{2} + d, largest_exponent));
  return candidate_cap ? std::min(count, *candidate_cap) : count;
}

namespace {

// A nonlinearity's strength: contact's is the fraction of a gap's push that it passes on.
std::optional<std::string> strength_problem(std::string_view field, double strength,
                                            Nonlinearity nonlinearity) {
  return rule::check(std::isfinite(strength) && strength >= 0.0 &&
                         (nonlinearity != Nonlinearity::contact || strength <= 1.0),
                     field, strength,
                     "must be finite and >= 0, and <= 1 with the contact nonlinearity");
}

// Each controller once, each w in [0, 1].
std::optional<std::string> controllers_problem(const std::vector<ControllerSpec>& controllers) {
  for (std::size_t i = 0; i < controllers.size(); ++i) {
    const ControllerSpec& c = controllers[i];
    if (c.uses_w() && !(c.w >= 0.0 && c.w <= 1.0)) {
      return fmt::format("controllers[{}].w: value is {}; rule: must lie in [0, 1]", i, c.w);
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (controllers[j].label() == c.label()) {
        return fmt::format("controllers[{}]: value is \"{}\"; rule: each controller at most once",
                           i, c.label());
      }
    }
  }
  return std::nullopt;
}

// The plant program measures the same cell as the twin's: the same locators, box and parts.
std::optional<std::string> same_cell_problem(const ExternalTwinSettings& twin,
                                             const ExternalTwinSettings& plant) {
  return rule::check(plant.locators == twin.locators && plant.lower_bounds == twin.lower_bounds &&
                         plant.upper_bounds == twin.upper_bounds &&
                         plant.upper_parts == twin.upper_parts &&
                         plant.lower_parts == twin.lower_parts,
                     "plant_external_twin", "another cell than external_twin's",
                     "the plant is the same cell (the same locators, box and assemblies) "
                     "measured by another program");
}

}  // namespace

std::optional<std::string> ExperimentConfig::validate() const {
  const bool external = twin_case == TwinCase::external;
  return first_problem(
      {rule::positive_finite("process_variance", process_variance),
       rule::positive_finite("initial_variance", initial_variance),
       rule::positive_finite("box_half_width", box_half_width),
       rule::positive_finite("drift_step", drift_step),
       rule::positive_finite("divergence_threshold", divergence_threshold),
       rule::positive_finite("alpha", alpha),
       rule::positive_finite("measurement_variance", filter_measurement_variance()),
       rule::non_negative_finite("plant_noise_variance", plant_noise_variance),
       rule::non_negative_finite("drift_bound", drift_bound),
       rule::check_fields(std::isfinite(beta) && std::isfinite(kappa), "beta and kappa",
                          std::array{beta, kappa}, "must be finite"),
       rule::check(analytic_dimension >= 1 && analytic_dimension <= max_analytic_dimension,
                   "analytic_dimension", analytic_dimension,
                   "must lie in [1, {}] (the analytic twin holds and factors a d x d curvature)",
                   max_analytic_dimension),
       strength_problem("strength", strength, nonlinearity),
       rule::check_fields(nonlinearity == Nonlinearity::none || twin_case == TwinCase::analytic,
                          "nonlinearity and case",
                          std::array{to_string(nonlinearity), to_string(twin_case)},
                          "only the analytic case takes a nonlinearity"),
       rule::check(!(plant_case && plant_nonlinearity), "plant_case and plant_nonlinearity",
                   "both set",
                   "the plant is another case or the analytic twin with a nonlinearity, not both"),
       rule::check_fields(
           !plant_case || (twin_case != TwinCase::external && twin_case != TwinCase::analytic &&
                           *plant_case != TwinCase::external && *plant_case != TwinCase::analytic),
           "plant_case and case",
           std::array{plant_case ? to_string(*plant_case) : std::string_view{"unset"},
                      to_string(twin_case)},
           "a separate plant case is for the FEM cases (the analytic case takes "
           "plant_nonlinearity, the external case plant_external_twin)"),
       rule::check_fields(
           !plant_nonlinearity || twin_case == TwinCase::analytic, "plant_nonlinearity and case",
           std::array{plant_nonlinearity ? to_string(*plant_nonlinearity) : std::string_view{},
                      to_string(twin_case)},
           "only the analytic case takes a plant nonlinearity"),
       rule::check(!plant_strength || plant_nonlinearity.has_value(), "plant_strength",
                   plant_strength.value_or(0.0),
                   "only with plant_nonlinearity (it is that nonlinearity's strength)"),
       plant_strength && plant_nonlinearity
           ? strength_problem("plant_strength", *plant_strength, *plant_nonlinearity)
           : std::nullopt,
       rule::check_fields(
           external == external_twin.has_value(), "case and external_twin",
           std::array<std::string_view, 2>{to_string(twin_case), external_twin ? "set" : "unset"},
           "external_twin is given with the external case and only with it"),
       external_twin ? rule::nested("external_twin", *external_twin) : std::nullopt,
       rule::check(!plant_external_twin || external_twin.has_value(), "plant_external_twin", "set",
                   "only with the external case (case is {}): it is that case's plant",
                   to_string(twin_case)),
       plant_external_twin ? rule::nested("plant_external_twin", *plant_external_twin)
                           : std::nullopt,
       plant_external_twin && external_twin
           ? same_cell_problem(*external_twin, *plant_external_twin)
           : std::nullopt,
       rule::check(!locators.empty(), "locators", "empty", "must name >= 1 locator"),
       rule::check(!controllers.empty(), "controllers", "empty", "must name >= 1 controller"),
       controllers_problem(controllers),
       rule::check(!candidates || *candidates >= 1, "candidates", candidates.value_or(0),
                   "must be >= 1 (unset: 2^(2+d))"),
       rule::check(!candidate_cap || *candidate_cap >= 1, "candidate_cap",
                   candidate_cap.value_or(0), "must be >= 1 (unset: no cap)"),
       rule::check(runs >= 1 && runs <= max_runs, "runs", runs, "must lie in [1, {}]", max_runs),
       rule::at_least("assemblies", assemblies, Index{1}),
       rule::at_least("twin_failure_streak", twin_failure_streak, Index{1}),
       rule::nested("active", active),
       rule::check(name.find_first_of(",\n\"") == std::string::npos, "name", name,
                   "must not contain commas, quotes or newlines")});
}

namespace {

using nlohmann::json;

// One entry per field: how to write it and how to read it, so the two directions cannot drift.
struct Field {
  std::function<void(json&, const ExperimentConfig&)> write;
  std::function<void(const json&, ExperimentConfig&)> read;
};

template <typename T>
Field plain(T ExperimentConfig::*member, std::string_view key) {
  return {
      [member, key](json& j, const ExperimentConfig& c) { j[std::string(key)] = c.*member; },
      [member, key](const json& v, ExperimentConfig& c) { c.*member = strict_value<T>(v, key); }};
}

// A setting that may be unset (JSON null: the paper's default applies).
template <typename T>
Field optional(std::optional<T> ExperimentConfig::*member, std::string_view key) {
  return {[member, key](json& j, const ExperimentConfig& c) {
            j[std::string(key)] = c.*member ? json(*(c.*member)) : json(nullptr);
          },
          [member, key](const json& v, ExperimentConfig& c) {
            c.*member = v.is_null() ? std::nullopt : std::optional<T>(strict_value<T>(v, key));
          }};
}

template <NamedEnum Enum>
Field choice(Enum ExperimentConfig::*member, std::string_view key) {
  return {[member, key](json& j, const ExperimentConfig& c) {
            j[std::string(key)] = std::string(to_string(c.*member));
          },
          [member, key](const json& v, ExperimentConfig& c) {
            c.*member = parse_enum<Enum>(strict_value<std::string>(v, key), key);
          }};
}

template <NamedEnum Enum>
Field optional_choice(std::optional<Enum> ExperimentConfig::*member, std::string_view key) {
  return {[member, key](json& j, const ExperimentConfig& c) {
            j[std::string(key)] =
                c.*member ? json(std::string(to_string(*(c.*member)))) : json(nullptr);
          },
          [member, key](const json& v, ExperimentConfig& c) {
            c.*member =
                v.is_null()
                    ? std::nullopt
                    : std::optional<Enum>(parse_enum<Enum>(strict_value<std::string>(v, key), key));
          }};
}

const std::map<std::string, Field, std::less<>>& fields() {
  static const std::map<std::string, Field, std::less<>> table = [] {
    std::map<std::string, Field, std::less<>> t;
    t["name"] = plain(&ExperimentConfig::name, "name");
    t["case"] = choice(&ExperimentConfig::twin_case, "case");
    t["twin_seed"] = plain(&ExperimentConfig::twin_seed, "twin_seed");
    t["analytic_dimension"] = plain(&ExperimentConfig::analytic_dimension, "analytic_dimension");
    t["nonlinearity"] = choice(&ExperimentConfig::nonlinearity, "nonlinearity");
    t["strength"] = plain(&ExperimentConfig::strength, "strength");
    t["plant_case"] = optional_choice(&ExperimentConfig::plant_case, "plant_case");
    t["plant_nonlinearity"] =
        optional_choice(&ExperimentConfig::plant_nonlinearity, "plant_nonlinearity");
    t["plant_strength"] = optional(&ExperimentConfig::plant_strength, "plant_strength");
    t["external_twin"] = optional(&ExperimentConfig::external_twin, "external_twin");
    t["plant_external_twin"] =
        optional(&ExperimentConfig::plant_external_twin, "plant_external_twin");
    t["locators"] = {[](json& j, const ExperimentConfig& c) { j["locators"] = c.locators; },
                     [](const json& v, ExperimentConfig& c) {
                       // Also a JSON list of names or indices, joined into the comma-separated
                       // form.
                       if (!v.is_array()) {
                         c.locators = strict_value<std::string>(v, "locators");
                         return;
                       }
                       std::string joined;
                       for (const json& entry : v) {
                         if (!joined.empty()) joined += ',';
                         joined += entry.is_number_integer()
                                       ? std::to_string(entry.get<long long>())
                                       : strict_value<std::string>(entry, "locators");
                       }
                       c.locators = joined;
                     }};
    t["controllers"] = {
        [](json& j, const ExperimentConfig& c) {
          json list = json::array();
          for (const ControllerSpec& s : c.controllers) list.push_back(s.label());
          j["controllers"] = list;
        },
        [](const json& v, ExperimentConfig& c) {
          if (v.is_string() && v.get<std::string>() == "paper") {
            c.controllers = ControllerSpec::paper();
            return;
          }
          c.controllers.clear();
          for (const auto& label : strict_value<std::vector<std::string>>(v, "controllers")) {
            c.controllers.push_back(ControllerSpec::parse(label));
          }
        }};
    t["filter"] = choice(&ExperimentConfig::filter, "filter");
    t["alpha"] = plain(&ExperimentConfig::alpha, "alpha");
    t["beta"] = plain(&ExperimentConfig::beta, "beta");
    t["kappa"] = plain(&ExperimentConfig::kappa, "kappa");
    t["sampler"] = choice(&ExperimentConfig::sampler, "sampler");
    t["exploration"] = choice(&ExperimentConfig::exploration, "exploration");
    t["candidates"] = optional(&ExperimentConfig::candidates, "candidates");
    t["candidate_cap"] = optional(&ExperimentConfig::candidate_cap, "candidate_cap");
    t["keep_drawing"] = plain(&ExperimentConfig::keep_drawing, "keep_drawing");
    t["box_half_width"] = plain(&ExperimentConfig::box_half_width, "box_half_width");
    // Only the settings changed from their defaults, and no key at all when none is: a config
    // that leaves the active controller alone writes what it wrote before the key existed, so
    // results stored under it stay reusable (episode_defining_json).
    t["active"] = {[](json& j, const ExperimentConfig& c) {
                     json changed = active_overrides(c.active);
                     if (!changed.empty()) j["active"] = std::move(changed);
                   },
                   [](const json& v, ExperimentConfig& c) {
                     if (v.is_null()) {
                       c.active = ActiveOptions{};
                     } else {
                       apply_active_overrides(v, c.active);
                     }
                   }};
    t["measurement_variance"] =
        optional(&ExperimentConfig::measurement_variance, "measurement_variance");
    t["process_variance"] = plain(&ExperimentConfig::process_variance, "process_variance");
    t["initial_variance"] = plain(&ExperimentConfig::initial_variance, "initial_variance");
    t["plant_noise_variance"] =
        plain(&ExperimentConfig::plant_noise_variance, "plant_noise_variance");
    t["drift_step"] = plain(&ExperimentConfig::drift_step, "drift_step");
    t["drift_bound"] = plain(&ExperimentConfig::drift_bound, "drift_bound");
    t["runs"] = plain(&ExperimentConfig::runs, "runs");
    t["assemblies"] = plain(&ExperimentConfig::assemblies, "assemblies");
    t["seed"] = plain(&ExperimentConfig::seed, "seed");
    t["divergence_threshold"] =
        plain(&ExperimentConfig::divergence_threshold, "divergence_threshold");
    t["stop_on_divergence"] = plain(&ExperimentConfig::stop_on_divergence, "stop_on_divergence");
    t["twin_failure_streak"] = plain(&ExperimentConfig::twin_failure_streak, "twin_failure_streak");
    return t;
  }();
  return table;
}

}  // namespace

void to_json(nlohmann::json& json, const ExperimentConfig& config) {
  json = nlohmann::json::object();
  for (const auto& [key, field] : fields()) field.write(json, config);
}

void from_json(const nlohmann::json& json, ExperimentConfig& config) {
  if (!json.is_object()) {
    throw InvalidArgumentError(
        "config", fmt::format("config: is {}; rule: must be a JSON object", json.dump()));
  }
  ExperimentConfig read = config;  // untouched on error
  for (const auto& [key, value] : json.items()) {
    const auto it = fields().find(key);
    if (it == fields().end()) {
      std::string known;
      for (const auto& entry : fields()) known += (known.empty() ? "" : ", ") + entry.first;
      throw InvalidArgumentError(
          key, fmt::format("config: key \"{}\" is unknown; rule: must be one of [{}]", key, known));
    }
    it->second.read(value, read);
  }
  config = std::move(read);
}

std::optional<std::string> episode_assemblies_problem(const ExperimentConfig& config) {
  if (config.external_twin &&
      config.assemblies > config.external_twin->upper_parts * config.external_twin->lower_parts) {
    return fmt::format(
        "assemblies: value is {}; rule: must be <= the external twin's upper_parts × lower_parts "
        "= {}",
        config.assemblies, config.external_twin->upper_parts * config.external_twin->lower_parts);
  }
  return std::nullopt;
}

void require_episodes_fit(const ExperimentConfig& config) {
  if (auto problem = episode_assemblies_problem(config)) {
    throw InvalidArgumentError("assemblies",
                               fmt::format("group \"{}\": {}", config.group_name(), *problem));
  }
}

nlohmann::json episode_defining_json(const ExperimentConfig& config) {
  nlohmann::json json = config;
  json.erase("name");
  json.erase("runs");
  json.erase("controllers");
  // Whether an episode that lost its twin is stored, not what a stored one holds.
  json.erase("twin_failure_streak");
  // The pool's size and patience, and where searched optima are kept, change no episode.
  if (config.external_twin) json["external_twin"] = result_defining_json(*config.external_twin);
  if (config.plant_external_twin) {
    json["plant_external_twin"] = result_defining_json(*config.plant_external_twin);
  }
  // An unset σz² and its case default give the same episodes.
  json["measurement_variance"] = config.filter_measurement_variance();
  return json;
}

}  // namespace twincal
