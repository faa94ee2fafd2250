#pragma once
// Private to the experiments module: the construction of an episode's controller, the
// filter-based ones instantiated per sigma-point scheme in episodes_<scheme>.cpp (declared
// extern in episode_runner.cpp), both from the one table at the end of this file.

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "twincal/controllers/any_controller.hpp"
#include "twincal/controllers/any_exploration_loss.hpp"
#include "twincal/controllers/default_controller.hpp"
#include "twincal/controllers/expected_quality.hpp"
#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/lookahead_controller.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/controllers/sensitivity_weights.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/experiments/case_twin.hpp"
#include "twincal/experiments/controller_spec.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/filters/sigma_point_filter.hpp"
#include "twincal/filters/sigma_point_scheme.hpp"
#include "twincal/models/quality_feedback.hpp"
#include "twincal/models/random_walk.hpp"
#include "twincal/samplers/any_sampler.hpp"

namespace twincal::detail {

/// What every controller of a run shares.
struct EpisodeSetup {
  const CaseTwin* twin = nullptr;
  const ExperimentConfig* config = nullptr;
  RandomStream run{0};
};

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

/// The active controller (episodes_active.cpp).
AnyController make_active(const EpisodeSetup& setup);

/// One w-controller per locator (episodes_per_component.cpp).
AnyController make_per_component(const EpisodeSetup& setup, const ControllerSpec& spec);

/// The default controller or a w-controller with a `Scheme` filter of dimension N.
template <int N, SigmaPointScheme Scheme>
AnyController make_filtered(const EpisodeSetup& setup, const ControllerSpec& spec,
                            const Scheme& scheme) {
  using Filter = SigmaPointFilter<RandomWalk<N>, QualityFeedback<CaseTwin, N>, Scheme>;
  const CaseTwin& twin = *setup.twin;
  const ExperimentConfig& config = *setup.config;
  Filter filter = make_quality_filter<Filter>(twin, setup.run.substream("filter"), scheme,
                                              paper_settings(config));
  const Index d = twin.control_dimension();
  if (spec.kind == ControllerSpec::Kind::default_control) {
    return AnyController(DefaultController<Filter>(std::move(filter)), d);
  }
  // The weighted trace's W, if the config's loss is that: the twin's sensitivity
  // (sensitivity_weights.hpp) over all its assemblies.
  const auto sensitivity = [&twin] {
    return sensitivity_weights(IndividualOptimum<CaseTwin>(twin), twin.assemblies());
  };
  return AnyController(LookaheadController<Filter, AnySampler, ExpectedQuality, AnyExplorationLoss>(
                           std::move(filter),
                           AnySampler(config.sampler, d, setup.run.substream("candidates").seed()),
                           lookahead_options(config, spec, d), ExpectedQuality{},
                           make_exploration_loss(config.exploration, sensitivity)),
                       d);
}

}  // namespace twincal::detail

// The table of make_filtered's instantiations, one row (N, Scheme) each, grouped by the file
// that instantiates them (episodes_<group>.cpp applies TWINCAL_INSTANTIATE_EPISODES to its
// group; episode_runner.cpp applies TWINCAL_DECLARE_EPISODES to all three). The paper's UKF
// and the CKF at the fixed sizes of the paper's cases and at run-time size; the ablation-only
// schemes at run-time size, one instantiation each.
#define TWINCAL_MERWE_EPISODES(ROW) \
  ROW(1, MerweScaledSigmaPoints)    \
  ROW(3, MerweScaledSigmaPoints)    \
  ROW(Dynamic, MerweScaledSigmaPoints)
#define TWINCAL_CUBATURE_EPISODES(ROW) \
  ROW(1, SphericalRadialSigmaPoints)   \
  ROW(3, SphericalRadialSigmaPoints)   \
  ROW(Dynamic, SphericalRadialSigmaPoints)
#define TWINCAL_OTHER_SCHEME_EPISODES(ROW)     \
  ROW(Dynamic, JulierSigmaPoints)              \
  ROW(Dynamic, FifthDegreeCubatureSigmaPoints) \
  ROW(Dynamic, SimplexSigmaPoints)
#define TWINCAL_INSTANTIATE_EPISODES(N, Scheme)                                               \
  template AnyController make_filtered<N, Scheme>(const EpisodeSetup&, const ControllerSpec&, \
                                                  const Scheme&);
#define TWINCAL_DECLARE_EPISODES(N, Scheme) extern TWINCAL_INSTANTIATE_EPISODES(N, Scheme)
