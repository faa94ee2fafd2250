#pragma once
/// @file
/// `ActiveStepReport`: what the active controller did for one assembly beyond its
/// ProposalReport — its model, its probe, its estimator's view of the data and whether the
/// control was corrected. `active_step_report_to_json` and `read_active_step_report` write and
/// read it as a flat JSON object: the controller's snapshot carries it, AnyController's
/// step_report() returns it and `twincal trace` prints one row of it per assembly.

#include <limits>

#include <nlohmann/json.hpp>

#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/core/eigen.hpp"

namespace twincal {

struct ActiveStepReport {
  bool quadratic = false;              ///< estimated with the twin's quadratic model
  double model_error = 0.0;            ///< largest relative error of the model at the check points
  double model_variance = 0.0;         ///< τ², the variance of the model's error in Q (estimator)
  bool hessian_refitted = false;       ///< this assembly paid for a full fit of H
  double probe_norm = 0.0;             ///< |p|
  double plant_regret = 0.0;           ///< the plant's regret that priced p (regret_probe)
  double horizon = 0.0;                ///< T of the probe design
  double process_variance = 0.0;       ///< q of the random-walk filter (sigma-point mode)
  double normalized_innovation = 0.0;  ///< ν²/S of z against its prediction (after observe)
  /// (z − m)²/(σz² + τ²): z against its model at the offset of the fit that took it in (after
  /// observe). NaN in sigma-point mode.
  double normalized_residual = std::numeric_limits<double>::quiet_NaN();
  bool gated = false;  ///< the sigma-point update inflated P at the gate
  /// The estimator declared a change of velocity in one of this assembly's fits (a refit after
  /// relinearization fits again).
  bool velocity_change = false;
  /// The change gate's largest reading over this assembly's fits: the recent entries' mean
  /// squared normalized residual over what the gate allows (change_gate² · min(s²,
  /// max_misfit_scale)); above 1 the estimator declared a change. NaN where the history was too
  /// short to consult the gate, or the estimator did not run (sigma-point mode).
  double change_ratio = std::numeric_limits<double>::quiet_NaN();
  /// s², the history's misfit scale (ConstantVelocityEstimator::misfit_scale(), unbounded): the
  /// significance test's unit, and the gate's up to max_misfit_scale. NaN in sigma-point mode.
  double misfit_scale = std::numeric_limits<double>::quiet_NaN();
  /// How badly the estimator predicts the plant (ConstantVelocityEstimator::prediction_scale()):
  /// the do-no-harm audit doubts the estimate from audit_misfit on. NaN in sigma-point mode.
  double prediction_scale = std::numeric_limits<double>::quiet_NaN();
  /// s, the unit of σz² in the fit's weights 1/(s·σz² + τ²) (ConstantVelocityEstimator::
  /// fit_unit()): 1 unless recent models erred, the plant's innovations run below σz and none of
  /// the last change_lag was beyond what the fit predicted. NaN in sigma-point mode.
  double fit_unit = std::numeric_limits<double>::quiet_NaN();
  Index history = 0;  ///< assemblies in the estimator's history
  /// The controller meant to apply δû: always in sigma-point mode; with the twin's model, where
  /// the estimator's history shows the offset significantly or a restart set it.
  bool correction_wanted = false;
  // Why δû was not applied: one flag per do-no-harm rule (docs/controllers.md, "do no harm"),
  // set with the twin's model whether or not δû was wanted, and one for the audit. A wanted δû
  // is applied exactly when none of the four is set.
  /// The plant keeps surprising the estimate: innovations beyond the gate in at least
  /// change_window + 2 of the last change_window + 3 assemblies.
  bool held_by_innovations = false;
  /// Surprises that the refit did not explain (ActiveOptions::hold_after_surprises), or one
  /// among the episode's first innovations (ActiveOptions::trial_innovations).
  bool held_by_surprises = false;
  /// The estimate lies beyond the correction's reach (ActiveOptions::clamp_beyond_reach).
  bool held_beyond_reach = false;
  /// No rule held a wanted δû back, but the audit counted the assembly in its uncorrected arm.
  bool held_by_audit = false;
  bool corrected = false;  ///< the control applied δû
  bool audited = false;    ///< this assembly counts in the do-no-harm audit
};

/// `step` as a flat JSON object, one key per field (NaN as null, ±∞ as "inf" / "-inf").
[[nodiscard]] inline nlohmann::json active_step_report_to_json(const ActiveStepReport& step) {
  using json_state::number_to_json;
  return {{"quadratic", step.quadratic},
          {"model_error", number_to_json(step.model_error)},
          {"model_variance", number_to_json(step.model_variance)},
          {"hessian_refitted", step.hessian_refitted},
          {"probe_norm", number_to_json(step.probe_norm)},
          {"plant_regret", number_to_json(step.plant_regret)},
          {"horizon", number_to_json(step.horizon)},
          {"process_variance", number_to_json(step.process_variance)},
          {"normalized_innovation", number_to_json(step.normalized_innovation)},
          {"normalized_residual", number_to_json(step.normalized_residual)},
          {"gated", step.gated},
          {"velocity_change", step.velocity_change},
          {"change_ratio", number_to_json(step.change_ratio)},
          {"misfit_scale", number_to_json(step.misfit_scale)},
          {"prediction_scale", number_to_json(step.prediction_scale)},
          {"fit_unit", number_to_json(step.fit_unit)},
          {"history", step.history},
          {"correction_wanted", step.correction_wanted},
          {"held_by_innovations", step.held_by_innovations},
          {"held_by_surprises", step.held_by_surprises},
          {"held_beyond_reach", step.held_beyond_reach},
          {"held_by_audit", step.held_by_audit},
          {"corrected", step.corrected},
          {"audited", step.audited}};
}

/// The inverse of active_step_report_to_json. @throws InvalidArgumentError naming the field
/// that is missing or of the wrong type.
[[nodiscard]] inline ActiveStepReport read_active_step_report(const nlohmann::json& saved) {
  using json_state::read_bool;
  using json_state::read_double_field;
  using json_state::Values;
  ActiveStepReport step;
  step.quadratic = read_bool(saved, "quadratic");
  step.model_error = read_double_field(saved, "model_error", Values::any);
  step.model_variance = read_double_field(saved, "model_variance", Values::any);
  step.hessian_refitted = read_bool(saved, "hessian_refitted");
  step.probe_norm = read_double_field(saved, "probe_norm", Values::any);
  step.plant_regret = read_double_field(saved, "plant_regret", Values::any);
  step.horizon = read_double_field(saved, "horizon", Values::any);
  step.process_variance = read_double_field(saved, "process_variance", Values::any);
  step.normalized_innovation = read_double_field(saved, "normalized_innovation", Values::any);
  step.normalized_residual = read_double_field(saved, "normalized_residual", Values::any);
  step.gated = read_bool(saved, "gated");
  step.velocity_change = read_bool(saved, "velocity_change");
  step.change_ratio = read_double_field(saved, "change_ratio", Values::any);
  step.misfit_scale = read_double_field(saved, "misfit_scale", Values::any);
  step.prediction_scale = read_double_field(saved, "prediction_scale", Values::any);
  step.fit_unit = read_double_field(saved, "fit_unit", Values::any);
  step.history = json_state::read_integer_field(saved, "history", 0);
  step.correction_wanted = read_bool(saved, "correction_wanted");
  step.held_by_innovations = read_bool(saved, "held_by_innovations");
  step.held_by_surprises = read_bool(saved, "held_by_surprises");
  step.held_beyond_reach = read_bool(saved, "held_beyond_reach");
  step.held_by_audit = read_bool(saved, "held_by_audit");
  step.corrected = read_bool(saved, "corrected");
  step.audited = read_bool(saved, "audited");
  return step;
}

}  // namespace twincal
