#include "twincal/experiments/summary_table.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>

#include <fmt/format.h>

namespace twincal {
namespace {

using nlohmann::json;

double value_or_nan(const json& episode, const char* key) {
  const json& value = episode.at(key);
  return value.is_null() ? std::numeric_limits<double>::quiet_NaN() : value.get<double>();
}

double median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double mean(const std::vector<double>& values) {
  double sum = 0.0;
  Index count = 0;
  for (const double v : values) {
    if (!std::isnan(v)) {
      sum += v;
      ++count;
    }
  }
  return count > 0 ? sum / static_cast<double>(count) : std::numeric_limits<double>::quiet_NaN();
}

std::string cell(double value, int precision) {
  return std::isnan(value) ? std::string("-") : fmt::format("{:.{}f}", value, precision);
}

// One line per group whose twin records `field` (not null), as line(group name, value) writes it.
template <typename Line>
std::string lines_of_twin_field(const json& groups, const char* field, const Line& line) {
  std::string out;
  for (const json& group : groups) {
    if (!group.contains("twin") || !group.at("twin").contains(field)) continue;
    const json& value = group.at("twin").at(field);
    if (!value.is_null()) out += line(group.at("name").get<std::string>(), value);
  }
  return out;
}

}  // namespace

std::vector<SummaryRow> summarize(const json& groups, const std::vector<json>& episodes) {
  struct Collected {
    std::vector<double> residuals, errors, seconds, evaluations;
    Index runs = 0;
    Index divergences = 0;
    Index lost = 0;
    bool lost_known = true;
    Index fallbacks = 0;
    Index dropped = 0;
    bool fallbacks_known = true;
  };
  std::map<std::pair<std::string, std::string>, Collected> collected;
  for (const json& episode : episodes) {
    Collected& c = collected[{episode.at("group").get<std::string>(),
                              episode.at("controller").get<std::string>()}];
    ++c.runs;
    if (!episode.at("diverged_at").is_null()) {
      ++c.divergences;
    } else {
      c.residuals.push_back(value_or_nan(episode, "relative_residual"));
      c.errors.push_back(value_or_nan(episode, "estimation_error"));
    }
    const auto lost = episode.find("lost");
    if (lost == episode.end()) {
      c.lost_known = false;
    } else if (lost->get<bool>()) {
      ++c.lost;
    }
    const auto fallbacks = episode.find("fallbacks");
    const auto dropped = episode.find("dropped_measurements");
    if (fallbacks == episode.end() || dropped == episode.end()) {
      c.fallbacks_known = false;
    } else {
      c.fallbacks += fallbacks->get<Index>();
      c.dropped += dropped->get<Index>();
    }
    c.seconds.push_back(value_or_nan(episode, "seconds_per_assembly"));
    c.evaluations.push_back(value_or_nan(episode, "q_evaluations_per_assembly"));
  }
  std::vector<SummaryRow> rows;
  for (const json& group : groups) {
    const std::string name = group.at("name").get<std::string>();
    for (const json& label : group.at("config").at("controllers")) {
      const auto it = collected.find({name, label.get<std::string>()});
      if (it == collected.end()) continue;
      const Collected& c = it->second;
      rows.push_back({name, label.get<std::string>(), c.runs, c.divergences,
                      c.lost_known ? std::optional<Index>(c.lost) : std::nullopt,
                      c.fallbacks_known ? std::optional<Index>(c.fallbacks) : std::nullopt,
                      c.fallbacks_known ? std::optional<Index>(c.dropped) : std::nullopt,
                      median(c.residuals), median(c.errors), mean(c.seconds), mean(c.evaluations)});
    }
  }
  return rows;
}

std::string format_summary(const std::vector<SummaryRow>& rows) {
  std::size_t group_width = 5;
  std::size_t controller_width = 10;
  for (const SummaryRow& row : rows) {
    group_width = std::max(group_width, row.group.size());
    controller_width = std::max(controller_width, row.controller.size());
  }
  const auto count = [](const std::optional<Index>& value) {
    return value ? fmt::format("{}", *value) : std::string("-");
  };
  std::string out = fmt::format(
      "{:<{}}  {:<{}} {:>5} {:>9} {:>5} {:>9} {:>7} {:>12} {:>12} {:>12} {:>10}\n", "group",
      group_width, "controller", controller_width, "runs", "diverged", "lost", "fallbacks",
      "dropped", "med (z-z*)/z*", "med |du-du*|", "us/assembly", "Q/assembly");
  for (const SummaryRow& row : rows) {
    out += fmt::format(
        "{:<{}}  {:<{}} {:>5} {:>9} {:>5} {:>9} {:>7} {:>12} {:>12} {:>12} {:>10}\n", row.group,
        group_width, row.controller, controller_width, row.runs, row.divergences, count(row.lost),
        count(row.fallbacks), count(row.dropped_measurements),
        cell(row.median_relative_residual, 4), cell(row.median_estimation_error, 4),
        cell(1e6 * row.seconds_per_assembly, 1), cell(row.q_evaluations_per_assembly, 1));
  }
  return out;
}

std::string format_departures(const json& groups) {
  return lines_of_twin_field(groups, "quadratic_departure",
                             [](const std::string& name, const json& departure) {
                               return fmt::format(
                                   "{}: Q² departs {:.3f} from a quadratic (RMS residual of its "
                                   "best quadratic fit over u0 "
                                   "± ¼ box, / its sd; median of 10 assemblies)\n",
                                   name, departure.get<double>());
                             });
}

std::string format_active_models(const json& groups) {
  return lines_of_twin_field(
      groups, "active_models", [](const std::string& name, const json& models) {
        const auto key_points = models.at("key_points").get<Index>();
        if (models.at("from").get<std::string>() == "deviations") {
          return fmt::format(
              "{}: the active controller models Q² from the twin's {} key points' deviations\n",
              name, key_points);
        }
        return fmt::format("{}: the active controller models Q² from the quality alone ({})\n",
                           name,
                           key_points == 0 ? "the twin answers no key points: docs/external.md, "
                                             "key_points"
                                           : "surrogate.from_deviations is off");
      });
}

std::string format_optimum_searches(const json& groups) {
  const auto line = [](const std::string& name, const char* whose, const json& search) {
    return fmt::format(
        "{}: {}u0 searched in {:.1f} twin evaluations per assembly ({:.1f} requests){}\n", name,
        whose, search.at("evaluations_per_assembly").get<double>(),
        search.at("requests_per_assembly").get<double>(),
        search.value("read_from_file", false) ? ", read from its optima_file" : "");
  };
  std::string out;
  for (const json& group : groups) {
    if (!group.contains("twin")) continue;
    const json& twin = group.at("twin");
    const std::string name = group.at("name").get<std::string>();
    if (const json search = twin.value("optimum_search", json()); !search.is_null()) {
      out += line(name, "", search);
    }
    if (const json search = twin.value("plant_optimum_search", json()); !search.is_null()) {
      out += line(name, "the plant's ", search);
    }
  }
  return out;
}

}  // namespace twincal
