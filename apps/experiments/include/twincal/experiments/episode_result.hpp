#pragma once
/// @file
/// `EpisodeResult`: what one episode (one controller, one run) produced — per assembly the
/// trace (z_t, z*_t, u_t, δû_t, δu*_t, tr P_t, Q-evaluations, wall time), the assemblies that
/// fell back to the default control, and the paper's
/// metrics (Sec. 3): the mean relative residual (1/T) Σ (z_t − z*_t)/z*_t, the mean estimation
/// error (1/T) Σ ‖δû_t − δu*_t‖ and the divergence ‖δû_t − δu*_t‖ > 10 with its step — and,
/// beyond the paper, whether the controller ended up lost (assess_lost).
/// The trace's storage is sized once, before the episode, so recording does not allocate.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/models/assembly_id.hpp"

namespace twincal {

struct EpisodeResult {
  // --- identity ----------------------------------------------------------------------------
  std::string group;       ///< the experiment group (ExperimentConfig::group_name())
  std::string controller;  ///< ControllerSpec::label()
  Index run = 0;
  std::uint64_t run_seed = 0;  ///< seed of the run's stream (order, drift, noise, δû0)

  // --- trace: column/entry t is assembly t of the episode; `steps` are filled ----------------
  Index steps = 0;  ///< assemblies produced (fewer than planned after a stop on divergence)
  std::vector<AssemblyId> assemblies;
  VectorX z;              ///< measured quality z_t
  VectorX z_star;         ///< z*(x_t), the individualized optimum's quality
  MatrixX control;        ///< u_t (d × T)
  MatrixX estimate;       ///< δû_t after the update with z_t (0 for non-estimating controllers)
  MatrixX offset;         ///< δu*_t the assembly was produced with
  VectorX trace_p;        ///< tr P_t after the update (NaN for non-estimating controllers)
  VectorX q_evaluations;  ///< twin evaluations of the controller for assembly t
  VectorX seconds;        ///< wall time of propose + observe

  // --- metrics over the `steps` assemblies ---------------------------------------------------
  double relative_residual = 0.0;  ///< mean (z_t − z*_t)/z*_t
  double estimation_error = 0.0;   ///< mean ‖δû_t − δu*_t‖
  Index diverged_at = -1;  ///< first t with ‖δû_t − δu*_t‖ > threshold, −1 if none
  double seconds_per_assembly = 0.0;
  double q_evaluations_per_assembly = 0.0;
  /// Why the episode stopped early other than by divergence (a controller error), else empty.
  /// An error also counts as a divergence at its step.
  std::string failure;
  /// Assemblies whose proposal fell back to the controller's default control
  /// (AnyController::fallback: a twin error, a model that could not be fitted); a controller
  /// without a fallback records 0.
  Index fallbacks = 0;
  /// Assemblies whose measurement the estimate could not be updated with and dropped
  /// (AnyController::dropped_measurement: the twin failed at the update's sigma points).
  Index dropped_measurements = 0;
  /// The first assembly that fell back or dropped its measurement, −1 if none.
  Index first_fallback_at = -1;
  /// What happened there: "proposal: <why>" or "measurement dropped: <why>"; empty if none.
  std::string first_fallback;

  // --- the lost rule (assess_lost) over the second half of the `steps` assemblies ------------
  double estimate_error_second_half = 0.0;  ///< mean ‖δû_t − δu*_t‖ there, NaN if no steps
  double offset_norm_second_half = 0.0;     ///< mean ‖δu*_t‖ there: the baseline's error
  bool lost = false;  ///< estimate_error_second_half > offset_norm_second_half

  [[nodiscard]] bool diverged() const noexcept { return diverged_at >= 0; }
};

/// The lost rule: an episode is lost when, over the second half of its `steps` assemblies
/// (t = ⌊steps/2⌋, …, steps − 1), its mean estimation error ‖δû_t − δu*_t‖ exceeds, strictly,
/// the mean ‖δu*_t‖ — the error of the baseline, which applies no correction (δû = 0). Such a
/// controller would do better by ignoring its own estimate, yet it need never cross the
/// divergence threshold: a filter that stalls while the offset drifts on, or that wanders at a
/// few times ‖δu*‖, is lost without diverging, and the paper's divergence count misses it.
/// Only the second half counts, so that a random δû0 still converging in the first assemblies
/// is not mistaken for a lost one. The rule is strict so that the baseline (and any controller
/// with δû = 0) is never lost: its error is ‖0 − δu*_t‖ = ‖δu*_t‖, summed here in the same
/// order, so the two means are equal to the bit. δû_t is the recorded estimate (after the
/// update with z_t, as in the paper's estimation error), both over the controlled locators.
/// Sets estimate_error_second_half, offset_norm_second_half and lost from `result`'s trace;
/// an episode without any step has NaN means and is not lost (it has diverged at step 0).
void assess_lost(EpisodeResult& result);

}  // namespace twincal
