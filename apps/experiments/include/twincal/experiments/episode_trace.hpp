#pragma once
/// @file
/// `write_episode_trace`: one episode of run_episode as CSV, one row per assembly — what the
/// plant and the controller did, and why (the controller's step_report(): for the active
/// controller its model's error, its probe, the change gate's reading and the misfit scales,
/// whether it corrected). `twincal trace` prints it; a user tracing a lost run reads it
/// instead of adding prints to the controller.

#include <ostream>

#include "twincal/core/eigen.hpp"
#include "twincal/experiments/case_twin.hpp"
#include "twincal/experiments/controller_spec.hpp"
#include "twincal/experiments/episode_result.hpp"
#include "twincal/experiments/experiment_config.hpp"

namespace twincal {

/// The columns every trace starts with; the controller's step report follows, one column per
/// key (in the key order of its JSON object), none for a controller that reports nothing more.
inline constexpr const char* episode_trace_columns =
    "t,upper,lower,z,z_star,relative_residual,estimation_error,offset_norm,trace_p,"
    "q_evaluations,fell_back,dropped_measurement";

/// Runs episode (`controller`, `run`) of `config` on `twin` as run_episode does — the same
/// result, digit for digit — and writes its trace to `out`: a header line, then after each
/// assembly t its row: t, the assembly's parts, z_t, z*_t, (z_t − z*_t)/z*_t, ‖δû_t − δu*_t‖,
/// ‖δu*_t‖, tr P_t, the twin evaluations, whether the proposal fell back to the default
/// control (AnyController::fallback) and whether the measurement was dropped
/// (AnyController::dropped_measurement; the episode's first reason is in the result), then the
/// step report's values (numbers in their
/// shortest exact form, NaN as `nan`, ±∞ as `inf` / `-inf`, booleans as `true` / `false`).
/// Each row is written when its assembly is done, so a long episode can be followed as it runs.
/// @throws as run_episode; Error when `out` fails.
EpisodeResult write_episode_trace(const CaseTwin& twin, const ExperimentConfig& config,
                                  const ControllerSpec& controller, Index run, std::ostream& out);

}  // namespace twincal
