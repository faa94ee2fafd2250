#pragma once
/// @file
/// `ExperimentConfig`: one experiment group — a twin case and locator set, the controllers to
/// compare, the filter, sampler and loss of the w-controllers, the paper's numbers (Sec. 2.4)
/// and the protocol: runs × episodes of `assemblies` assemblies under the bouncing drift of
/// eq. (15). Defaults are the paper's; `validate()` names the field that breaks a rule. JSON
/// round-trips through nlohmann-json (`to_json`/`from_json`, unknown keys rejected).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "twincal/controllers/active/active_options.hpp"
#include "twincal/controllers/exploration_kind.hpp"
#include "twincal/controllers/lookahead_options.hpp"
#include "twincal/controllers/paper_settings.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/experiments/controller_spec.hpp"
#include "twincal/experiments/experiment_choices.hpp"
#include "twincal/experiments/external_twin_settings.hpp"
#include "twincal/filters/filter_scheme.hpp"
#include "twincal/samplers/candidate_sampler.hpp"

namespace twincal {

struct ExperimentConfig {
  /// Largest analytic_dimension: the analytic twin holds and factors a d × d curvature, and the
  /// active controller a 2d × 2d fit, per assembly.
  static constexpr Index max_analytic_dimension = 1024;
  /// Largest candidate count per assembly of a w-controller (2^22; the paper's 2^(2+d) passes
  /// it beyond d = 20): more must be capped with `candidate_cap`.
  static constexpr Index max_candidates = Index{1} << 22;

  /// Name of the group in the results; empty: "<case>/<locators>".
  std::string name;

  // --- the twin ------------------------------------------------------------------------------
  TwinCase twin_case = TwinCase::body;
  /// Seed of the twin itself (parts, fields); the same for every run.
  std::uint64_t twin_seed = 2023;
  /// The program of the external case (required by it, refused by the others).
  std::optional<ExternalTwinSettings> external_twin{};
  /// Number of locators of the analytic twin (ignored by body and door).
  Index analytic_dimension = 3;
  /// The analytic twin's nonlinearity: none is the RMS-quadratic twin (Q² a quadratic in u);
  /// contact, stiffening and kink are key-point twins whose Q² is not (docs/models.md).
  Nonlinearity nonlinearity = Nonlinearity::none;
  /// Its strength s (contact: in [0, 1]; stiffening, kink: >= 0); 1 departs Q² from a quadratic
  /// by 10–30 % (docs/models.md). Ignored with none.
  double strength = 1.0;
  /// The plant, when it is not the twin (Assumption 1 broken): another case (e.g. the contact
  /// FEM behind the linear twin: case body, plant_case body-contact) or, for the analytic case,
  /// the same key-point twin with a nonlinearity the controllers' twin lacks. Unset: the plant
  /// is the twin.
  std::optional<TwinCase> plant_case{};
  std::optional<Nonlinearity> plant_nonlinearity{};
  /// Strength of plant_nonlinearity (unset: `strength`).
  std::optional<double> plant_strength{};
  /// The plant of the external case when it is another program than the twin (e.g. the
  /// CalculiX contact solve behind its linear influence-coefficient twin, docs/calculix.md):
  /// the same locators, bounds and parts as `external_twin`. Unset: the twin is the plant.
  std::optional<ExternalTwinSettings> plant_external_twin{};
  /// Controlled (and drifting) locators: "A", "B", "C" (the twin's significant locators),
  /// "ABC", "all", or a comma-separated list of locator names or 0-based indices.
  std::string locators = "A";

  // --- controllers ---------------------------------------------------------------------------
  std::vector<ControllerSpec> controllers = ControllerSpec::paper();
  FilterScheme filter = FilterScheme::merwe;
  /// Merwe's scaled points (α, β, κ); Julier's points use κ. The paper's are not stated
  /// (PaperSettings says why these).
  double alpha = PaperSettings{}.alpha;
  double beta = PaperSettings{}.beta;
  double kappa = PaperSettings{}.kappa;
  CandidateSampler sampler = CandidateSampler::sobol;
  ExplorationKind exploration = ExplorationKind::trace;
  /// Candidates per assembly, eq. (14); unset: the paper's 2^(2+d).
  std::optional<Index> candidates{};
  /// Largest candidate count per assembly: caps `candidates` (or 2^(2+d)) so that a study over d
  /// can keep the paper's controllers where they are feasible; unset: no cap.
  std::optional<Index> candidate_cap{};
  /// Draw further batches until `candidates` survive U_t (the paper draws one).
  bool keep_drawing = LookaheadOptions{}.keep_drawing;
  /// Half-width of U_t around u0 + δû, eq. (14).
  double box_half_width = LookaheadOptions{}.box_half_width;
  /// The active controller's settings (docs/controllers.md); the JSON key `active` holds the
  /// ones changed from their defaults (active_options_json.hpp). Its measurement_variance and
  /// initial_variance are not read: the controller takes this config's.
  ActiveOptions active{};

  // --- filter and plant ------------------------------------------------------------------------
  /// σz² the filter assumes, eq. (5b); unset: PaperSettings' (1e-4 for body and analytic,
  /// 1e-6 for door).
  std::optional<double> measurement_variance{};
  /// Σu = process_variance·I, eq. (5c).
  double process_variance = PaperSettings{}.process_variance;
  /// δû0 ~ N(0, initial_variance·I) and P0 = initial_variance·I.
  double initial_variance = PaperSettings{}.initial_variance;
  /// Variance of the noise the plant adds to z_t (the paper measures without noise: 0).
  double plant_noise_variance = 0.0;
  /// Bouncing drift, eq. (15): |p| per assembly and the bound b on |δu*_i|.
  double drift_step = 0.03;
  double drift_bound = 0.5;

  // --- protocol --------------------------------------------------------------------------------
  /// Episodes per controller and group, at most max_runs (the study lists its episodes before
  /// it runs them; a larger study is split into several results directories).
  Index runs = 10;
  static constexpr Index max_runs = 1'000'000;
  /// Assemblies per episode, taken from the twin's assemblies in a seeded random order.
  Index assemblies = 100;
  std::uint64_t seed = 2023;
  /// An episode diverges when ‖δû_t − δu*_t‖ exceeds this (the paper's 10).
  double divergence_threshold = 10.0;
  /// Stop an episode at its divergence (metrics then cover the steps up to it).
  bool stop_on_divergence = true;
  /// An episode whose controller could not use its twin at this many assemblies in a row — each
  /// proposal on the fallback or each measurement dropped (docs/controllers.md, failure
  /// policies) — has lost its twin: it ends as a twin failure (TwinFailureError: not stored, and
  /// a group whose twin fails two episodes in a row is given up), not as a result made without
  /// the twin. A twin that fails now and then costs those assemblies only, and they are counted
  /// (EpisodeResult::fallbacks, dropped_measurements).
  Index twin_failure_streak = 5;

  /// "<case>/<locators>" unless `name` is set.
  [[nodiscard]] std::string group_name() const;
  /// The σz² the filter uses (measurement_variance or the case's default).
  [[nodiscard]] double filter_measurement_variance() const;
  /// Candidates per assembly of a w-controller over d locators: `candidates` (unset: the
  /// paper's 2^(2+d), saturating at 2^62) capped at `candidate_cap`.
  [[nodiscard]] Index candidate_count(Index d) const;
  [[nodiscard]] std::optional<std::string> validate() const;
};

void to_json(nlohmann::json& json, const ExperimentConfig& config);
/// Reads the keys present over the defaults.
/// @throws InvalidArgumentError naming an unknown key or a value of the wrong type or spelling.
void from_json(const nlohmann::json& json, ExperimentConfig& config);

/// Whether `config`'s episodes fit its twin's assemblies, where that is known without building
/// the twin (the external case: upper_parts × lower_parts), so that a study is refused before
/// any program starts. Not part of `validate()`: `twincal serve` takes the same config and has
/// no episodes.
[[nodiscard]] std::optional<std::string> episode_assemblies_problem(const ExperimentConfig& config);
/// @throws InvalidArgumentError naming the group and the rule when episode_assemblies_problem
///         finds one.
void require_episodes_fit(const ExperimentConfig& config);

/// The JSON of the fields that decide what one episode does: everything but `name`, `runs` and
/// `controllers` (which say which episodes exist). Results are only reused under an equal one.
[[nodiscard]] nlohmann::json episode_defining_json(const ExperimentConfig& config);

}  // namespace twincal
