#pragma once
// Private to the experiments module: the episode loop over any controller type and the
// filter-based episodes for one sigma-point scheme, instantiated per scheme in
// episodes_<scheme>.cpp (declared extern in episode_runner.cpp).

#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/default_controller.hpp"
#include "twincal/controllers/expected_quality.hpp"
#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/lookahead_controller.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/controllers/sensitivity_weights.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/stopwatch.hpp"
#include "twincal/experiments/any_exploration_loss.hpp"
#include "twincal/experiments/any_sampler.hpp"
#include "twincal/experiments/case_twin.hpp"
#include "twincal/experiments/controller_spec.hpp"
#include "twincal/experiments/episode_result.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/filters/sigma_point_filter.hpp"
#include "twincal/filters/sigma_point_scheme.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/models/quality_feedback.hpp"
#include "twincal/models/random_walk.hpp"

namespace twincal::detail {

/// What every controller of a run shares.
struct EpisodeSetup {
  const CaseTwin* twin = nullptr;
  const ExperimentConfig* config = nullptr;
  RandomStream run{0};
  std::vector<AssemblyId> order;  ///< the episode's assemblies, in production order
};

/// The episode loop (episode_runner.hpp): `result` is sized for setup.order and filled.
template <int N, Controller C>
void simulate(C& controller, const EpisodeSetup& setup, EpisodeResult& result) {
  const CaseTwin& twin = *setup.twin;
  const ExperimentConfig& config = *setup.config;
  const Index d = twin.control_dimension();
  const Index planned = std::ssize(setup.order);
  RandomStream drift_stream = setup.run.substream("drift");
  BouncingDrift<N> drift =
      BouncingDrift<N>::random(d, drift_stream, config.drift_step, config.drift_bound);
  RandomStream noise = setup.run.substream("measurement_noise");
  const double noise_sd = std::sqrt(config.plant_noise_variance);
  Vector<N> shifted(d);
  Vector<N> error(d);

  double residuals = 0.0;
  double errors = 0.0;
  double seconds = 0.0;
  double evaluations = 0.0;
  Index t = 0;
  for (; t < planned; ++t) {
    const AssemblyId& x = setup.order[static_cast<std::size_t>(t)];
    drift.advance();
    // Drawn whatever the noise level, so every controller's step t meets the same draw.
    const double v = noise.normal();
    try {
      const std::uint64_t evaluations_before = CaseTwin::evaluations_on_this_thread();
      Stopwatch watch;
      const typename C::ControlVector u = controller.propose(x);
      double elapsed = watch.seconds();
      shifted = u - drift.offset();
      const double z = twin.plant_quality(x, shifted) + noise_sd * v;
      watch.restart();
      controller.observe(x, u, z);
      elapsed += watch.seconds();

      result.z(t) = z;
      result.z_star(t) = twin.optimal_quality(x);
      result.control.col(t) = u;
      result.offset.col(t) = drift.offset();
      if constexpr (EstimatingController<C>) {
        result.estimate.col(t) = controller.offset_estimate();
        result.trace_p(t) = controller.offset_covariance().trace();
      } else {
        result.estimate.col(t).setZero();
        result.trace_p(t) = std::numeric_limits<double>::quiet_NaN();
      }
      result.q_evaluations(t) =
          static_cast<double>(CaseTwin::evaluations_on_this_thread() - evaluations_before);
      result.seconds(t) = elapsed;
    } catch (const std::exception& failure) {
      // A controller that cannot go on (a non-finite estimate, a covariance that cannot be
      // factored) has lost the offset as surely as a diverged one.
      result.failure = failure.what();
      if (result.diverged_at < 0) result.diverged_at = t;
      break;
    }
    error = result.estimate.col(t) - result.offset.col(t);
    const double distance = error.norm();
    residuals += (result.z(t) - result.z_star(t)) / result.z_star(t);
    errors += distance;
    seconds += result.seconds(t);
    evaluations += result.q_evaluations(t);
    if (distance > config.divergence_threshold && result.diverged_at < 0) {
      result.diverged_at = t;
      if (config.stop_on_divergence) {
        ++t;
        break;
      }
    }
  }
  result.steps = t;
  const double steps = static_cast<double>(t);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  result.relative_residual = t > 0 ? residuals / steps : nan;
  result.estimation_error = t > 0 ? errors / steps : nan;
  result.seconds_per_assembly = t > 0 ? seconds / steps : nan;
  result.q_evaluations_per_assembly = t > 0 ? evaluations / steps : nan;
}

/// The exploration loss of the config; the weighted trace's W from the twin's sensitivity
/// (sensitivity_weights.hpp) over all its assemblies.
inline AnyExplorationLoss make_exploration_loss(ExplorationKind kind, const CaseTwin& twin) {
  switch (kind) {
    case ExplorationKind::weighted_trace:
      return AnyExplorationLoss(WeightedTraceLoss(
          sensitivity_weights(IndividualOptimum<CaseTwin>(twin), twin.assemblies())));
    case ExplorationKind::log_det:
      return AnyExplorationLoss(LogDetLoss{});
    case ExplorationKind::max_eigenvalue:
      return AnyExplorationLoss(MaxEigenvalueLoss{});
    case ExplorationKind::trace:
      break;
  }
  return AnyExplorationLoss(TraceLoss{});
}

/// The filter numbers of the config (eq. 5 and the sigma points).
inline PaperSettings paper_settings(const ExperimentConfig& config) {
  return {.process_variance = config.process_variance,
          .measurement_variance = config.filter_measurement_variance(),
          .initial_variance = config.initial_variance,
          .alpha = config.alpha,
          .beta = config.beta,
          .kappa = config.kappa};
}

/// A w-controller's options over d locators (eqs. 13–14): the spec's w, the config's box and
/// candidates.
inline LookaheadOptions lookahead_options(const ExperimentConfig& config,
                                          const ControllerSpec& spec, Index d) {
  return {.w = spec.w,
          .box_half_width = config.box_half_width,
          .candidates = config.candidate_count(d),
          .keep_drawing = config.keep_drawing};
}

/// The active controller (instantiated in episodes_active.cpp).
template <int N>
void run_active(const EpisodeSetup& setup, EpisodeResult& result);

/// One w-controller per locator (instantiated in episodes_per_component.cpp).
template <int N>
void run_per_component(const EpisodeSetup& setup, const ControllerSpec& spec,
                       EpisodeResult& result);

/// The default controller or a w-controller with a `Scheme` filter of dimension N.
template <int N, SigmaPointScheme Scheme>
void run_filtered(const EpisodeSetup& setup, const ControllerSpec& spec, const Scheme& scheme,
                  EpisodeResult& result) {
  using Filter = SigmaPointFilter<RandomWalk<N>, QualityFeedback<CaseTwin, N>, Scheme>;
  const CaseTwin& twin = *setup.twin;
  const ExperimentConfig& config = *setup.config;
  Filter filter = make_quality_filter<Filter>(twin, setup.run.substream("filter"), scheme,
                                              paper_settings(config));
  if (spec.kind == ControllerSpec::Kind::default_control) {
    DefaultController<Filter> controller(std::move(filter));
    simulate<N>(controller, setup, result);
    return;
  }
  const LookaheadOptions options = lookahead_options(config, spec, twin.control_dimension());
  LookaheadController<Filter, AnySampler, ExpectedQuality, AnyExplorationLoss> controller(
      std::move(filter),
      AnySampler(config.sampler, twin.control_dimension(),
                 setup.run.substream("candidates").seed()),
      options, ExpectedQuality{}, make_exploration_loss(config.exploration, twin));
  simulate<N>(controller, setup, result);
}

}  // namespace twincal::detail
