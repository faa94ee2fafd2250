#pragma once
/// @file
/// `ResultStore`: a results directory, append-only and resumable.
///
/// Files (docs/cli.md has the columns):
/// - assemblies.csv — one row per assembly of every finished episode;
/// - episodes.jsonl — one JSON line per finished episode (metrics, seeds): the record of what is
///   done, written after the episode's CSV rows;
/// - summary.json — the groups (config, tags, resolved locators) and all episode metrics,
///   rewritten by write_summary().
/// On opening, an episode without its episodes.jsonl line (a run killed while writing) is
/// dropped from assemblies.csv, so a rerun redoes exactly the unfinished episodes. A group that
/// is already stored must have the same episode-defining config (episode_defining_json) and have
/// been run by the same build (build_id(): a rebuilt twincal may compute other episodes from the
/// same settings); its runs and controllers may grow.

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/experiments/build_id.hpp"
#include "twincal/experiments/case_twin.hpp"
#include "twincal/experiments/episode_result.hpp"
#include "twincal/experiments/experiment_group.hpp"

namespace twincal {

/// A number as the results' CSV files write it: the shortest form that reads back to the same
/// double; "nan" for a missing value.
[[nodiscard]] std::string csv_number(double value);

/// The error of a results file or directory: Error("<path>: <what>"), keyed by the path.
[[nodiscard]] Error file_error(const std::filesystem::path& path, std::string_view what);

class ResultStore {
 public:
  static constexpr const char* csv_name = "assemblies.csv";
  static constexpr const char* episodes_name = "episodes.jsonl";
  static constexpr const char* summary_name = "summary.json";

  /// Opens (creating it if needed) `directory` and loads what it holds; the groups it adds are
  /// recorded as run by `build` from `commit` (twincal/experiments/build_id.hpp; a test may name
  /// others).
  /// @throws Error when a file cannot be read or written or summary.json is not ours.
  explicit ResultStore(std::filesystem::path directory, std::string build = std::string(build_id()),
                       std::string commit = std::string(build_commit()));

  [[nodiscard]] const std::filesystem::path& directory() const noexcept { return directory_; }

  /// Registers a group run on `twin` (its resolved locators, the build and its commit are
  /// recorded), or checks it against the stored one (settings and build; the commit may differ
  /// where only the docs changed) and extends its runs and controllers. A group stored without a
  /// build (by a twincal before 2026-11-28) is not checked for one.
  /// @throws InvalidArgumentError naming the group and the settings that differ, or both builds.
  void add_group(const ExperimentGroup& group, const CaseTwin& twin);

  [[nodiscard]] bool contains(const std::string& group, const std::string& controller,
                              Index run) const;

  /// Appends the episode's rows to assemblies.csv and its line to episodes.jsonl (flushed).
  void append(const EpisodeResult& result);

  /// Rewrites summary.json (atomically: a temporary file renamed over it).
  void write_summary() const;

  /// The groups in registration order: {"name", "config", "tags", "twin", "build", "commit"}.
  [[nodiscard]] const nlohmann::json& groups() const noexcept { return groups_; }
  /// The finished episodes' metrics in the order they were stored.
  [[nodiscard]] const std::vector<nlohmann::json>& episodes() const noexcept { return episodes_; }

 private:
  using Key = std::tuple<std::string, std::string, Index>;

  void load();
  void reconcile_csv();

  std::filesystem::path directory_;
  std::string build_;
  std::string commit_;
  nlohmann::json groups_ = nlohmann::json::array();
  std::vector<nlohmann::json> episodes_;
  std::set<Key> done_;
  std::ofstream csv_;
  std::ofstream jsonl_;
};

/// The episode key of an assemblies.csv row: its first three fields (group, controller, run).
/// False for a row that has no such key (a torn line).
bool csv_row_key(const std::string& line, std::string& group, std::string& controller, Index& run);

/// The JSON line of an episode's metrics (what episodes.jsonl and summary.json hold).
[[nodiscard]] nlohmann::json episode_metrics_json(const EpisodeResult& result);

}  // namespace twincal
