#include "twincal/experiments/result_store.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <optional>
#include <sstream>
#include <utility>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/experiments/controller_spec.hpp"

namespace twincal {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr const char* csv_header =
    "group,controller,run,t,upper,lower,z,z_star,relative_residual,control,estimate,offset,"
    "estimation_error,trace_p,q_evaluations,seconds";

json number_json(double value) { return std::isnan(value) ? json(nullptr) : json(value); }

template <typename Column>
std::string joined(const Column& column) {
  std::string out;
  for (Index i = 0; i < column.size(); ++i) {
    if (i > 0) out += ' ';
    out += csv_number(column(i));
  }
  return out;
}

std::ofstream open_append(const fs::path& path) {
  std::ofstream out(path, std::ios::app);
  if (!out) throw file_error(path, "cannot be opened for appending");
  return out;
}

// What searching u0 cost `model` per assembly (null where it knows its optima without a search),
// and whether its optima were read from the file that search wrote.
json optimum_search_json(const AnyTwin& model) {
  const std::optional<OptimumSearchCost> cost = model.optimum_search();
  if (!cost) return nullptr;
  const auto searched = static_cast<double>(std::max<Index>(cost->assemblies, 1));
  json search = {{"evaluations_per_assembly", static_cast<double>(cost->evaluations) / searched},
                 {"requests_per_assembly", static_cast<double>(cost->requests) / searched}};
  if (cost->read) search["read_from_file"] = true;
  return search;
}

}  // namespace

std::string csv_number(double value) {
  return std::isnan(value) ? std::string("nan") : fmt::format("{}", value);
}

Error file_error(const fs::path& path, std::string_view what) {
  return Error(path.string(), fmt::format("{}: {}", path.string(), what));
}

bool csv_row_key(const std::string& line, std::string& group, std::string& controller, Index& run) {
  const std::size_t first = line.find(',');
  const std::size_t second = first == std::string::npos ? first : line.find(',', first + 1);
  const std::size_t third = second == std::string::npos ? second : line.find(',', second + 1);
  if (third == std::string::npos) return false;
  group = line.substr(0, first);
  controller = line.substr(first + 1, second - first - 1);
  try {
    run = std::stoll(line.substr(second + 1, third - second - 1));
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

json episode_metrics_json(const EpisodeResult& result) {
  return json{{"group", result.group},
              {"controller", result.controller},
              {"run", result.run},
              {"run_seed", result.run_seed},
              {"steps", result.steps},
              {"relative_residual", number_json(result.relative_residual)},
              {"estimation_error", number_json(result.estimation_error)},
              {"diverged_at", result.diverged() ? json(result.diverged_at) : json(nullptr)},
              {"seconds_per_assembly", number_json(result.seconds_per_assembly)},
              {"q_evaluations_per_assembly", number_json(result.q_evaluations_per_assembly)},
              {"failure", result.failure},
              {"fallbacks", result.fallbacks},
              {"dropped_measurements", result.dropped_measurements},
              {"first_fallback_at",
               result.first_fallback_at >= 0 ? json(result.first_fallback_at) : json(nullptr)},
              {"first_fallback", result.first_fallback},
              {"estimate_error_second_half", number_json(result.estimate_error_second_half)},
              {"offset_norm_second_half", number_json(result.offset_norm_second_half)},
              {"lost", result.lost}};
}

ResultStore::ResultStore(fs::path directory, std::string build, std::string commit)
    : directory_(std::move(directory)), build_(std::move(build)), commit_(std::move(commit)) {
  std::error_code error;
  fs::create_directories(directory_, error);
  if (error) throw file_error(directory_, fmt::format("cannot be created ({})", error.message()));
  load();
  reconcile_csv();
  const fs::path csv_path = directory_ / csv_name;
  const bool fresh = !fs::exists(csv_path) || fs::file_size(csv_path) == 0;
  csv_ = open_append(csv_path);
  if (fresh) csv_ << csv_header << '\n' << std::flush;
  jsonl_ = open_append(directory_ / episodes_name);
}

void ResultStore::load() {
  const fs::path summary_path = directory_ / summary_name;
  if (fs::exists(summary_path)) {
    std::ifstream in(summary_path);
    json summary;
    try {
      summary = json::parse(in);
    } catch (const json::exception& error) {
      throw file_error(summary_path, fmt::format("is not valid JSON ({})", error.what()));
    }
    if (summary.value("format", std::string()) != "twincal.results") {
      throw file_error(summary_path,
                       "is not a twincal results summary (format is not "
                       "\"twincal.results\")");
    }
    groups_ = summary.at("groups");
  }
  // episodes.jsonl is the record of finished episodes; a torn last line (a run killed while
  // writing it) is dropped and the file rewritten without it.
  const fs::path jsonl_path = directory_ / episodes_name;
  if (!fs::exists(jsonl_path)) return;
  std::ifstream in(jsonl_path);
  std::string line;
  bool torn = false;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    try {
      json episode = json::parse(line);
      done_.emplace(episode.at("group").get<std::string>(),
                    episode.at("controller").get<std::string>(), episode.at("run").get<Index>());
      episodes_.push_back(std::move(episode));
    } catch (const json::exception&) {
      torn = true;
    }
  }
  in.close();
  if (torn) {
    std::ofstream out(jsonl_path, std::ios::trunc);
    for (const json& episode : episodes_) out << episode.dump() << '\n';
    if (!out) throw file_error(jsonl_path, "cannot be rewritten");
  }
}

void ResultStore::reconcile_csv() {
  const fs::path csv_path = directory_ / csv_name;
  if (!fs::exists(csv_path)) return;
  std::ifstream in(csv_path);
  std::vector<std::string> kept;
  std::string line;
  bool dropped = false;
  std::string group;
  std::string controller;
  Index run = 0;
  while (std::getline(in, line)) {
    if (kept.empty() && line == csv_header) {
      kept.push_back(line);
      continue;
    }
    if (csv_row_key(line, group, controller, run) && done_.contains(Key{group, controller, run})) {
      kept.push_back(line);
    } else {
      dropped = true;
    }
  }
  in.close();
  if (!dropped) return;
  const fs::path temporary = directory_ / (std::string(csv_name) + ".tmp");
  {
    std::ofstream out(temporary, std::ios::trunc);
    if (kept.empty()) out << csv_header << '\n';
    for (const std::string& row : kept) out << row << '\n';
    if (!out) throw file_error(temporary, "cannot be written");
  }
  fs::rename(temporary, csv_path);
}

void ResultStore::add_group(const ExperimentGroup& group, const CaseTwin& twin) {
  const ExperimentConfig& config = group.config;
  const std::string name = config.group_name();
  std::vector<Index> indices = twin.locators();
  json twin_json{{"dimension", twin.control_dimension()},
                 {"locator_names", twin.locator_names()},
                 {"locator_indices", indices}};
  for (json& stored : groups_) {
    if (stored.at("name").get<std::string>() != name) continue;
    ExperimentConfig previous;
    from_json(stored.at("config"), previous);
    const json before = episode_defining_json(previous);
    const json now = episode_defining_json(config);
    if (before != now) {
      // Both ways: a key written only when set (`active`) may be in either.
      std::string differences;
      const auto shown = [](const json& settings, const std::string& key) {
        return settings.contains(key) ? settings.at(key).dump() : std::string("unset");
      };
      json keys = now;
      keys.update(before);
      for (const auto& [key, unused] : keys.items()) {
        if (before.contains(key) && now.contains(key) && before.at(key) == now.at(key)) continue;
        differences += fmt::format("{}{} was {}, is now {}", differences.empty() ? "" : "; ", key,
                                   shown(before, key), shown(now, key));
      }
      throw InvalidArgumentError(
          "config",
          fmt::format("config: group \"{}\" in {} was run with other settings ({}); rule: a "
                      "results directory holds one configuration per group — use another --out "
                      "or another group name",
                      name, directory_.string(), differences));
    }
    if (stored.contains("build") && stored.at("build") != build_) {
      throw InvalidArgumentError(
          "build",
          fmt::format("build: group \"{}\" in {} was run by twincal build {}, this is build {}; "
                      "rule: a results directory holds one build's episodes per group (a rebuilt "
                      "twincal may compute other episodes from the same settings) — use another "
                      "--out or another group name",
                      name, directory_.string(), stored.at("build").dump(), json(build_).dump()));
    }
    // Same episodes: let the study grow by runs and controllers.
    previous.runs = std::max(previous.runs, config.runs);
    for (const ControllerSpec& spec : config.controllers) {
      if (std::find(previous.controllers.begin(), previous.controllers.end(), spec) ==
          previous.controllers.end()) {
        previous.controllers.push_back(spec);
      }
    }
    stored["config"] = previous;
    if (!group.tags.empty()) stored["tags"] = group.tags;
    return;
  }
  // A new group: how far its Q² is from a quadratic (an external twin's evaluations are its
  // cost, so it is not measured there).
  twin_json["quadratic_departure"] = config.twin_case == TwinCase::external
                                         ? json(nullptr)
                                         : json(median_quadratic_departure(twin));
  // What u0 cost where it is searched (the budget a real twin pays before the controller), and
  // what the plant's z* cost where the plant is another program.
  twin_json["optimum_search"] = optimum_search_json(twin.full_twin());
  twin_json["plant_optimum_search"] =
      twin.plant() ? optimum_search_json(*twin.plant()) : json(nullptr);
  // What the active controller's local models come from: the twin's key points' deviations
  // where it answers them, or Q² alone, which models contact twins less well
  // (docs/reproduction.md, "Black-box twins that answer only Q").
  const bool active = std::any_of(
      config.controllers.begin(), config.controllers.end(),
      [](const ControllerSpec& spec) { return spec.kind == ControllerSpec::Kind::active; });
  const Index key_points = twin.key_point_count();
  const char* source =
      config.active.surrogate.fits_from_deviations(key_points) ? "deviations" : "quality";
  twin_json["active_models"] =
      active ? json{{"from", source}, {"key_points", key_points}} : json(nullptr);
  groups_.push_back(json{{"name", name},
                         {"config", config},
                         {"tags", group.tags},
                         {"twin", twin_json},
                         {"build", build_},
                         {"commit", commit_}});
}

bool ResultStore::contains(const std::string& group, const std::string& controller,
                           Index run) const {
  return done_.contains(Key{group, controller, run});
}

void ResultStore::append(const EpisodeResult& result) {
  std::string rows;
  for (Index t = 0; t < result.steps; ++t) {
    const double distance = (result.estimate.col(t) - result.offset.col(t)).norm();
    const AssemblyId& x = result.assemblies[static_cast<std::size_t>(t)];
    rows += fmt::format(
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", result.group, result.controller,
        result.run, t, x.upper, x.lower, csv_number(result.z(t)), csv_number(result.z_star(t)),
        csv_number((result.z(t) - result.z_star(t)) / result.z_star(t)),
        joined(result.control.col(t)), joined(result.estimate.col(t)), joined(result.offset.col(t)),
        csv_number(distance), csv_number(result.trace_p(t)), csv_number(result.q_evaluations(t)),
        csv_number(result.seconds(t)));
  }
  csv_ << rows << std::flush;
  if (!csv_) throw file_error(directory_ / csv_name, "cannot be written");
  json metrics = episode_metrics_json(result);
  jsonl_ << metrics.dump() << '\n' << std::flush;
  if (!jsonl_) throw file_error(directory_ / episodes_name, "cannot be written");
  done_.emplace(result.group, result.controller, result.run);
  episodes_.push_back(std::move(metrics));
}

void ResultStore::write_summary() const {
  const json summary{
      {"format", "twincal.results"}, {"version", 1}, {"groups", groups_}, {"episodes", episodes_}};
  const fs::path path = directory_ / summary_name;
  const fs::path temporary = directory_ / (std::string(summary_name) + ".tmp");
  {
    std::ofstream out(temporary, std::ios::trunc);
    out << summary.dump(1) << '\n';
    if (!out) throw file_error(temporary, "cannot be written");
  }
  fs::rename(temporary, path);
}

}  // namespace twincal
