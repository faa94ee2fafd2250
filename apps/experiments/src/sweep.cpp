#include "twincal/experiments/sweep.hpp"

#include <algorithm>
#include <string>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"

namespace twincal {
namespace {

using nlohmann::json;

// Applies one axis value to a config's JSON.
void apply(json& config, const std::string& axis, const json& value) {
  if (axis == "w") {
    config["controllers"] = json::array({fmt::format("w={}", value.get<double>())});
  } else if (axis == "controller") {
    config["controllers"] = json::array({value});
  } else if (axis == "dimension") {
    config["analytic_dimension"] = value;
  } else if (axis.find('.') != std::string::npos) {
    // A nested setting, e.g. "active.trajectory.change_gate": the objects on its path are
    // created or kept, so axes on two settings of one object combine.
    std::string pointer = "/" + axis;
    std::replace(pointer.begin(), pointer.end(), '.', '/');
    try {
      config[json::json_pointer(pointer)] = value;
    } catch (const json::exception&) {
      throw InvalidArgumentError(
          axis, fmt::format("axes: key \"{}\" is a path through {}; rule: each name before a "
                            "dot must be an object of the config (e.g. active.trajectory)",
                            axis, config.dump()));
    }
  } else {
    config[axis] = value;
  }
}

// The value as it reads in a group name: commas and quotes would break the CSV's group column.
std::string value_text(const json& value) {
  std::string text = value.is_string() ? value.get<std::string>() : value.dump();
  std::string clean;
  for (const char c : text) {
    if (c == ',') {
      clean += '+';
    } else if (c != '"' && c != '\n') {
      clean += c;
    }
  }
  return clean;
}

}  // namespace

namespace {

// Studies that name their own groups refuse a named base.
void require_unnamed(const ExperimentConfig& base) {
  if (!base.name.empty()) {
    throw InvalidArgumentError(
        "base.name", fmt::format("base.name: is \"{}\"; rule: must be empty (the study names "
                                 "its groups)",
                                 base.name));
  }
}

}  // namespace

std::vector<ExperimentGroup> paper_study(std::span<const TwinCase> cases,
                                         const ExperimentConfig& base) {
  require_unnamed(base);
  std::vector<ExperimentGroup> groups;
  for (const TwinCase twin_case : cases) {
    for (const char* locators : {"A", "B", "C", "ABC"}) {
      ExperimentGroup group{base, json{{"case", to_string(twin_case)}, {"locators", locators}}};
      group.config.twin_case = twin_case;
      group.config.locators = locators;
      groups.push_back(std::move(group));
    }
  }
  return groups;
}

std::vector<ExperimentGroup> scaling_study(TwinCase twin_case, std::span<const Index> dimensions,
                                           const ExperimentConfig& base) {
  require_unnamed(base);
  std::vector<ExperimentGroup> groups;
  if (twin_case != TwinCase::analytic) {
    if (!dimensions.empty()) {
      throw InvalidArgumentError(
          "dimensions", fmt::format("dimensions: are given for case {}; rule: only the analytic "
                                    "twin's d is free (body and door run locator sets A, ABC, all)",
                                    to_string(twin_case)));
    }
    for (const char* locators : {"A", "ABC", "all"}) {
      ExperimentGroup group{base, json{{"study", "scaling"}, {"locators", locators}}};
      group.config.twin_case = twin_case;
      group.config.locators = locators;
      groups.push_back(std::move(group));
    }
    return groups;
  }
  for (const Index d : dimensions) {
    if (d < 1) {
      throw InvalidArgumentError(
          "dimensions", fmt::format("dimensions: holds {}; rule: every d must be >= 1", d));
    }
    ExperimentGroup group{base, json{{"study", "scaling"}, {"dimension", d}}};
    group.config.twin_case = twin_case;
    group.config.locators = "all";
    group.config.analytic_dimension = d;
    group.config.name = fmt::format("analytic/all/d={}", d);
    groups.push_back(std::move(group));
  }
  return groups;
}

std::vector<ExperimentGroup> nonlinearity_study(std::span<const Index> dimensions,
                                                std::span<const double> strengths,
                                                const ExperimentConfig& base) {
  require_unnamed(base);
  if (base.nonlinearity == Nonlinearity::none) {
    throw InvalidArgumentError("nonlinearity",
                               "nonlinearity: is none; rule: the study varies the strength of "
                               "contact, stiffening or kink");
  }
  if (dimensions.empty() || strengths.empty()) {
    throw InvalidArgumentError("dimensions, strengths",
                               fmt::format("dimensions, strengths: {} and {} values; rule: both "
                                           "need at least one",
                                           dimensions.size(), strengths.size()));
  }
  std::vector<ExperimentGroup> groups;
  const std::string_view kind = to_string(base.nonlinearity);
  for (const Index d : dimensions) {
    for (const double s : strengths) {
      ExperimentGroup group{base, json{{"study", "nonlinearity"},
                                       {"nonlinearity", kind},
                                       {"dimension", d},
                                       {"strength", s}}};
      group.config.twin_case = TwinCase::analytic;
      group.config.locators = "all";
      group.config.analytic_dimension = d;
      group.config.strength = s;
      group.config.name = fmt::format("analytic/all/{}/d={}/s={}", kind, d, s);
      require_valid("config", group.config);
      groups.push_back(std::move(group));
    }
  }
  return groups;
}

std::vector<ExperimentGroup> expand_sweep(const json& sweep) {
  if (!sweep.is_object() || !sweep.contains("base") || !sweep.at("base").is_object()) {
    throw InvalidArgumentError("sweep",
                               "sweep: has no \"base\" object; rule: a sweep is "
                               "{\"base\": {config}, \"axes\": {key: [values]}}");
  }
  for (const auto& [key, value] : sweep.items()) {
    if (key != "base" && key != "axes") {
      throw InvalidArgumentError(
          "sweep", fmt::format("sweep: key \"{}\" is unknown; rule: must be base or axes", key));
    }
  }
  const json base = sweep.at("base");
  ExperimentConfig base_config = base;  // validates the base's keys
  const std::string base_name = base_config.group_name();
  const json axes = sweep.value("axes", json::object());
  std::vector<std::pair<std::string, json>> axis_list;
  for (const auto& [key, values] : axes.items()) {
    if (!values.is_array() || values.empty()) {
      throw InvalidArgumentError(
          "axes." + key, fmt::format("axes.{}: is {}; rule: must be a non-empty list of values",
                                     key, values.dump()));
    }
    axis_list.emplace_back(key, values);
  }

  std::vector<ExperimentGroup> groups;
  std::vector<std::size_t> index(axis_list.size(), 0);
  while (true) {
    json config = base;
    json tags = json::object();
    std::string suffix;
    for (std::size_t a = 0; a < axis_list.size(); ++a) {
      const auto& [key, values] = axis_list[a];
      const json& value = values.at(index[a]);
      apply(config, key, value);
      tags[key] = value;
      suffix += fmt::format("{}{}={}", suffix.empty() ? "" : " ", key, value_text(value));
    }
    ExperimentGroup group{config.get<ExperimentConfig>(), tags};
    group.config.name = suffix.empty() ? base_name : base_name + "/" + suffix;
    require_valid(fmt::format("sweep point \"{}\"", group.config.name), group.config);
    groups.push_back(std::move(group));
    // Odometer over the axes, the last fastest.
    std::size_t a = axis_list.size();
    while (a > 0) {
      --a;
      if (++index[a] < axis_list[a].second.size()) break;
      index[a] = 0;
      if (a == 0) return groups;
    }
    if (axis_list.empty()) return groups;
  }
}

}  // namespace twincal
