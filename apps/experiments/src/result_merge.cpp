#include "twincal/experiments/result_merge.hpp"

#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/experiments/result_store.hpp"

namespace twincal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Key = std::tuple<std::string, std::string, Index>;

struct StoredEpisode {
  std::string line;  // as in episodes.jsonl
  json metrics;
  std::string rows;  // its assemblies.csv rows, each ending in '\n'
  std::size_t shard = 0;
};

// One shard's directory, read only (what ResultStore would keep on opening it: episodes with
// their episodes.jsonl line, the CSV rows of those).
struct Shard {
  json groups;
  std::string csv_header;
  std::map<Key, StoredEpisode> episodes;
};

// The groups without the builds that ran them and their commits (merge tells a build that
// differs from settings that do; commits that differ only in the docs are one build).
json without_builds(json groups) {
  for (json& group : groups) {
    group.erase("build");
    group.erase("commit");
  }
  return groups;
}

json builds(const json& groups) {
  json out = json::array();
  for (const json& group : groups) out.push_back(group.value("build", json()));
  return out;
}

Shard read_shard(const fs::path& directory, std::size_t number) {
  const fs::path summary_path = directory / ResultStore::summary_name;
  if (!fs::exists(summary_path)) {
    throw InvalidArgumentError(
        "shards", fmt::format("shards: \"{}\" holds no {}; rule: each shard must be a results "
                              "directory",
                              directory.string(), ResultStore::summary_name));
  }
  Shard shard;
  {
    std::ifstream in(summary_path);
    try {
      const json summary = json::parse(in);
      if (summary.value("format", std::string()) != "twincal.results") {
        throw file_error(summary_path, "is not a twincal results summary");
      }
      shard.groups = summary.at("groups");
    } catch (const json::exception& error) {
      throw file_error(summary_path, fmt::format("is not valid JSON ({})", error.what()));
    }
  }
  std::ifstream jsonl(directory / ResultStore::episodes_name);
  std::string line;
  while (std::getline(jsonl, line)) {
    if (line.empty()) continue;
    try {
      json metrics = json::parse(line);
      Key key{metrics.at("group").get<std::string>(), metrics.at("controller").get<std::string>(),
              metrics.at("run").get<Index>()};
      shard.episodes.emplace(std::move(key),
                             StoredEpisode{line, std::move(metrics), std::string(), number});
    } catch (const json::exception&) {
      // A torn last line: that episode is not finished (as ResultStore reads it).
    }
  }
  std::ifstream csv(directory / ResultStore::csv_name);
  if (!std::getline(csv, shard.csv_header)) {
    throw file_error(directory / ResultStore::csv_name, "cannot be read (no header)");
  }
  while (std::getline(csv, line)) {
    std::string group;
    std::string controller;
    Index run = 0;
    if (!csv_row_key(line, group, controller, run)) continue;
    const auto episode = shard.episodes.find(Key{group, controller, run});
    if (episode != shard.episodes.end()) episode->second.rows += line + '\n';
  }
  return shard;
}

// The metrics without the wall time, which differs between two runs of one episode.
json without_wall_time(json metrics) {
  metrics.erase("seconds_per_assembly");
  return metrics;
}

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::trunc | std::ios::binary);
  out << text;
  if (!out) throw file_error(path, "cannot be written");
}

}  // namespace

MergeReport merge_results(std::span<const fs::path> shards, const fs::path& out) {
  if (shards.empty()) {
    throw InvalidArgumentError("shards",
                               "shards: none given; rule: merge needs at least one shard");
  }
  if (fs::exists(out / ResultStore::summary_name)) {
    throw InvalidArgumentError(
        "out", fmt::format("out: \"{}\" already holds results; rule: merge writes a new results "
                           "directory",
                           out.string()));
  }
  std::vector<Shard> read;
  for (std::size_t s = 0; s < shards.size(); ++s) {
    read.push_back(read_shard(shards[s], s));
    if (without_builds(read[s].groups) != without_builds(read[0].groups)) {
      throw InvalidArgumentError(
          "shards", fmt::format("shards: \"{}\" was run with other groups or settings than "
                                "\"{}\"; rule: the shards of a merge are one study (the same "
                                "command with --shard i/N)",
                                shards[s].string(), shards[0].string()));
    }
    if (builds(read[s].groups) != builds(read[0].groups)) {
      throw InvalidArgumentError(
          "shards", fmt::format("shards: \"{}\" was run by another twincal build than \"{}\" "
                                "({} against {}); rule: the shards of a merge are one build's "
                                "episodes (build every shard's twincal from the same sources)",
                                shards[s].string(), shards[0].string(),
                                builds(read[s].groups).dump(), builds(read[0].groups).dump()));
    }
    if (read[s].csv_header != read[0].csv_header) {
      throw file_error(shards[s] / ResultStore::csv_name,
                       "has another header than the first shard's (another twincal version?)");
    }
  }

  // Every shard's episodes by key, the first one kept; a second copy must agree.
  MergeReport report;
  std::map<Key, StoredEpisode> found;
  for (Shard& shard : read) {
    for (auto& [key, episode] : shard.episodes) {
      const auto [kept, inserted] = found.try_emplace(key, std::move(episode));
      if (inserted) continue;
      ++report.duplicates;
      if (without_wall_time(kept->second.metrics) != without_wall_time(episode.metrics)) {
        throw InvalidArgumentError(
            "shards",
            fmt::format("shards: episode (group \"{}\", controller \"{}\", run {}) is in \"{}\" "
                        "and \"{}\" with different results; rule: a study's episodes are "
                        "deterministic, so two copies of one must agree",
                        std::get<0>(key), std::get<1>(key), std::get<2>(key),
                        shards[kept->second.shard].string(), shards[episode.shard].string()));
      }
    }
  }

  // The study's order: groups as registered, then runs, then the config's controllers.
  std::string csv = read[0].csv_header + '\n';
  std::string jsonl;
  for (const json& group : read[0].groups) {
    ExperimentConfig config;
    from_json(group.at("config"), config);
    const std::string name = group.at("name").get<std::string>();
    for (Index run = 0; run < config.runs; ++run) {
      for (const ControllerSpec& controller : config.controllers) {
        ++report.planned;
        const auto episode = found.find(Key{name, controller.label(), run});
        if (episode == found.end()) continue;
        csv += episode->second.rows;
        jsonl += episode->second.line + '\n';
        ++report.merged;
        found.erase(episode);
      }
    }
  }
  if (!found.empty()) {
    const auto& [key, episode] = *found.begin();
    throw InvalidArgumentError(
        "shards", fmt::format("shards: \"{}\" holds episode (group \"{}\", controller \"{}\", "
                              "run {}), which its study does not plan; rule: a results "
                              "directory holds only its study's episodes",
                              shards[episode.shard].string(), std::get<0>(key), std::get<1>(key),
                              std::get<2>(key)));
  }

  std::error_code error;
  fs::create_directories(out, error);
  if (error) throw file_error(out, fmt::format("cannot be created ({})", error.message()));
  write_file(out / ResultStore::csv_name, csv);
  write_file(out / ResultStore::episodes_name, jsonl);
  // summary.json last, written as every run writes it: the store reads the groups from a
  // summary and the episodes from episodes.jsonl.
  write_file(
      out / ResultStore::summary_name,
      json{{"format", "twincal.results"}, {"version", 1}, {"groups", read[0].groups}}.dump());
  ResultStore(out).write_summary();
  return report;
}

}  // namespace twincal
