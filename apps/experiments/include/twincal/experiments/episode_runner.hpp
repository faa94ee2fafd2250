#pragma once
/// @file
/// `run_episode`: one episode of the paper's protocol (Sec. 2.4, 3) for one controller and one
/// run of an experiment group. Per assembly x_t (t = 0, …, T−1):
///   the drift advances to δu*_t (eq. 15, δu*_0 = 0 before the first step);
///   u_t = controller.propose(x_t);  z_t = Q_S(x_t, u_t − δu*_t) + v_t (the plant, eq. 5b);
///   controller.observe(x_t, u_t, z_t);  record; check ‖δû_t − δu*_t‖ > threshold.
/// Randomness is keyed by (seed, run) only, so every controller of a run sees the same assembly
/// order, drift direction, measurement noise, initial estimate δû0 and candidate randomization:
///   run = RandomStream(seed).substream("run").substream(r), and from it the substreams
///   "assembly_order", "drift", "measurement_noise", "filter" (δû0: its "initial_offset") and
///   "candidates" (the sampler's seed).
/// Non-estimating controllers (baseline, nominal) assume a calibrated twin: δû_t = 0.

#include <exception>
#include <functional>

#include "twincal/controllers/any_controller.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/experiments/case_twin.hpp"
#include "twincal/experiments/controller_spec.hpp"
#include "twincal/experiments/episode_result.hpp"
#include "twincal/experiments/experiment_config.hpp"

namespace twincal {

/// An episode that could not go on because its twin (or plant) program failed — it crashed, hung
/// or answered garbage again after the pool's retry (ExternalTwinError, docs/external.md). Not
/// a result of the controller: run_experiments does not store the episode (a rerun runs it
/// again) and stops asking a group's twin after two such episodes in a row.
class TwinFailureError : public Error {
 public:
  using Error::Error;
};

/// Whether `error` is, or nests, an external twin's failure (ExternalTwinError).
[[nodiscard]] bool caused_by_twin_failure(const std::exception& error);

/// Runs episode (`controller`, `run`) of `config` on `twin` (which must be
/// make_case_twin(config) or equivalent). Deterministic: the same arguments give the same result
/// (apart from the wall times) on any thread.
/// @throws InvalidArgumentError for an invalid config or run < 0; TwinFailureError (naming the
///         controller, the run and the step) when the twin's program fails; other errors inside
///         the episode (a controller that cannot go on) are recorded in EpisodeResult::failure.
[[nodiscard]] EpisodeResult run_episode(const CaseTwin& twin, const ExperimentConfig& config,
                                        const ControllerSpec& controller, Index run);

/// Called by run_episode after each assembly t the controller handled: the result's column t
/// is filled (z, z*, u, δû, δu*, tr P, evaluations), and the controller can be asked for its
/// step_report(). What `twincal trace` prints.
using EpisodeStepObserver =
    std::function<void(Index t, const EpisodeResult& result, const AnyController& controller)>;

/// run_episode that calls `observer` after every assembly (an empty observer is never called);
/// the result is the same as without it.
[[nodiscard]] EpisodeResult run_episode(const CaseTwin& twin, const ExperimentConfig& config,
                                        const ControllerSpec& controller, Index run,
                                        const EpisodeStepObserver& observer);

/// The controller that run_episode(twin, config, controller, run) drives — the same
/// construction, seeds and initial estimate δû0 — for an owner that drives it with its own
/// assemblies and measurements (`twincal serve`, serve_session.hpp).
/// @throws InvalidArgumentError as run_episode.
[[nodiscard]] AnyController make_episode_controller(const CaseTwin& twin,
                                                    const ExperimentConfig& config,
                                                    const ControllerSpec& controller, Index run);

}  // namespace twincal
