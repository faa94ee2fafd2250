#pragma once
/// @file
/// The study's summary table: per group and controller, over the stored runs, the median of the
/// episodes' mean relative residual and mean estimation error (over the runs that did not
/// diverge, as the paper's box plots), the number of divergences, the number of lost runs
/// (assess_lost, episode_result.hpp: worse than the baseline over the second half; a run may be
/// both diverged and lost), the assemblies that fell back to the default control (a twin
/// error, a model that could not be fitted) and those whose measurement was dropped (the twin
/// failed in the update), and the mean wall time and Q-evaluations per assembly (over all runs).

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"

namespace twincal {

struct SummaryRow {
  std::string group;
  std::string controller;
  Index runs = 0;
  Index divergences = 0;
  /// Runs recorded as lost; empty when a run's record predates the rule (no "lost" field), as
  /// a count over the others would pass for a count over all.
  std::optional<Index> lost = 0;
  /// Assemblies, over all runs, whose proposal fell back to the controller's default control
  /// (EpisodeResult::fallbacks); empty when a run's record predates the count.
  std::optional<Index> fallbacks = 0;
  /// Assemblies, over all runs, whose measurement was dropped (EpisodeResult::
  /// dropped_measurements); empty when a run's record predates the count.
  std::optional<Index> dropped_measurements = 0;
  double median_relative_residual = 0.0;  ///< NaN when every run diverged
  double median_estimation_error = 0.0;   ///< NaN when every run diverged
  double seconds_per_assembly = 0.0;
  double q_evaluations_per_assembly = 0.0;
};

/// Rows in the groups' order, controllers in each group's config order, from the `groups` and
/// `episodes` of a ResultStore (or of a summary.json).
[[nodiscard]] std::vector<SummaryRow> summarize(const nlohmann::json& groups,
                                                const std::vector<nlohmann::json>& episodes);

/// An aligned plain-text table (one header line, one line per row).
[[nodiscard]] std::string format_summary(const std::vector<SummaryRow>& rows);

/// One line per group whose twin's quadratic departure is recorded (ResultStore::add_group):
/// how far its Q² is from a quadratic, the shape the active controller's local model assumes.
/// Empty when no group has one.
[[nodiscard]] std::string format_departures(const nlohmann::json& groups);

/// One line per group with an active controller (ResultStore::add_group): whether its local
/// models of Q² come from the twin's key points' deviations or from the quality alone (a twin
/// that answers no key points, or QuadraticSurrogateOptions::from_deviations off), which models
/// contact twins less well. Empty when no group has one.
[[nodiscard]] std::string format_active_models(const nlohmann::json& groups);

/// One line per group whose twin searched u0(x) (eq. 3; ResultStore::add_group): its twin
/// evaluations and requests per assembly, what a new assembly costs before the controller's own
/// calls (the Q/assembly column). Empty when no group searched.
[[nodiscard]] std::string format_optimum_searches(const nlohmann::json& groups);

}  // namespace twincal
