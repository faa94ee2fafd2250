#include "twincal/experiments/episode_runner.hpp"

#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "episode_simulation.hpp"
#include "twincal/controllers/individualized_controller.hpp"
#include "twincal/controllers/nominal_controller.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/stopwatch.hpp"
#include "twincal/external/external_twin.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/julier_sigma_points.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/simplex_sigma_points.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"
#include "twincal/models/bouncing_drift.hpp"

namespace twincal {
namespace detail {

// Instantiated in episodes_merwe.cpp, episodes_cubature.cpp and episodes_other_schemes.cpp.
TWINCAL_MERWE_EPISODES(TWINCAL_DECLARE_EPISODES)
TWINCAL_CUBATURE_EPISODES(TWINCAL_DECLARE_EPISODES)
TWINCAL_OTHER_SCHEME_EPISODES(TWINCAL_DECLARE_EPISODES)

namespace {

// Fisher–Yates with the stream's own integer distribution (std::shuffle's algorithm is
// implementation-defined), so the order is the same on every platform.
std::vector<AssemblyId> production_order(const std::vector<AssemblyId>& all, Index count,
                                         RandomStream stream) {
  std::vector<AssemblyId> order = all;
  for (std::size_t i = order.size(); i > 1; --i) {
    std::swap(order[i - 1], order[stream.uniform_int<std::size_t>(0, i - 1)]);
  }
  order.resize(static_cast<std::size_t>(count));
  return order;
}

void size_result(EpisodeResult& result, Index d, Index steps) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  result.z = VectorX::Constant(steps, nan);
  result.z_star = VectorX::Constant(steps, nan);
  result.control = MatrixX::Constant(d, steps, nan);
  result.estimate = MatrixX::Constant(d, steps, nan);
  result.offset = MatrixX::Constant(d, steps, nan);
  result.trace_p = VectorX::Constant(steps, nan);
  result.q_evaluations = VectorX::Constant(steps, nan);
  result.seconds = VectorX::Constant(steps, nan);
}

// The controllers that need no filter.
AnyController make_unfiltered(const CaseTwin& twin, const ControllerSpec& spec) {
  const Index d = twin.control_dimension();
  if (spec.kind == ControllerSpec::Kind::nominal) {
    // u⁰ for the reference assembly x⁰: the twin's first assembly.
    return AnyController(NominalController<CaseTwin>(twin, twin.assemblies().front()), d);
  }
  return AnyController(IndividualizedController<CaseTwin>(twin), d);
}

// The controller of `spec`, its filter (if any) of dimension N.
template <int N>
AnyController make_with_dimension(const EpisodeSetup& setup, const ControllerSpec& spec) {
  if (!spec.estimates()) return make_unfiltered(*setup.twin, spec);
  if (spec.kind == ControllerSpec::Kind::active) return make_active(setup);
  if (spec.kind == ControllerSpec::Kind::per_component) return make_per_component(setup, spec);
  const ExperimentConfig& config = *setup.config;
  switch (config.filter) {
    case FilterScheme::merwe:
      return make_filtered<N>(setup, spec,
                              MerweScaledSigmaPoints(config.alpha, config.beta, config.kappa));
    case FilterScheme::cubature:
      return make_filtered<N>(setup, spec, SphericalRadialSigmaPoints{});
    case FilterScheme::julier:
    case FilterScheme::fifth_degree:
    case FilterScheme::simplex:
      break;
  }
  // The ablation-only schemes exist for dynamic d; their fixed-size twins would only cost build
  // time.
  switch (config.filter) {
    case FilterScheme::julier:
      return make_filtered<Dynamic>(setup, spec, JulierSigmaPoints(config.kappa));
    case FilterScheme::fifth_degree:
      return make_filtered<Dynamic>(setup, spec, FifthDegreeCubatureSigmaPoints{});
    case FilterScheme::simplex:
      return make_filtered<Dynamic>(setup, spec, SimplexSigmaPoints{});
    default:
      break;
  }
  throw InvalidArgumentError(
      "filter", fmt::format("filter: {} is not a known scheme", static_cast<int>(config.filter)));
}

AnyController make_controller(const EpisodeSetup& setup, const ControllerSpec& spec) {
  const Index d = setup.twin->control_dimension();
  if (d == 1) return make_with_dimension<1>(setup, spec);
  if (d == 3) return make_with_dimension<3>(setup, spec);
  return make_with_dimension<Dynamic>(setup, spec);
}

// Keeps the episode's first fallback or dropped measurement (EpisodeResult::first_fallback).
void note_first_fallback(EpisodeResult& result, Index t, std::string_view what,
                         std::string_view why) {
  if (result.first_fallback_at >= 0) return;
  result.first_fallback_at = t;
  result.first_fallback = fmt::format("{}: {}", what, why);
}

// The episode loop (episode_runner.hpp) over `order`; `result` is sized for it and filled. N
// selects the drift's vector type, so that every controller of a run computes δu*_t with the
// same arithmetic.
template <int N>
void simulate(AnyController& controller, const EpisodeSetup& setup,
              const std::vector<AssemblyId>& order, EpisodeResult& result,
              const EpisodeStepObserver& observer) {
  const CaseTwin& twin = *setup.twin;
  const ExperimentConfig& config = *setup.config;
  const Index d = twin.control_dimension();
  const Index planned = std::ssize(order);
  RandomStream drift_stream = setup.run.substream("drift");
  BouncingDrift<N> drift =
      BouncingDrift<N>::random(d, drift_stream, config.drift_step, config.drift_bound);
  RandomStream noise = setup.run.substream("measurement_noise");
  const double noise_sd = std::sqrt(config.plant_noise_variance);
  Vector<N> u(d);
  Vector<N> shifted(d);
  Vector<N> error(d);

  Index without_twin = 0;    // assemblies in a row that fell back or dropped their measurement
  std::string_view trouble;  // the last one's reason (valid until the next propose)
  double residuals = 0.0;
  double errors = 0.0;
  double seconds = 0.0;
  double evaluations = 0.0;
  Index t = 0;
  for (; t < planned; ++t) {
    const AssemblyId& x = order[static_cast<std::size_t>(t)];
    drift.advance();
    // Drawn whatever the noise level, so every controller's step t meets the same draw.
    const double v = noise.normal();
    try {
      const std::uint64_t evaluations_before = CaseTwin::evaluations_on_this_thread();
      Stopwatch watch;
      controller.propose(x, u);
      double elapsed = watch.seconds();
      const std::string_view fell_back = controller.fallback();
      if (!fell_back.empty()) {
        ++result.fallbacks;
        note_first_fallback(result, t, "proposal", fell_back);
      }
      shifted = u - drift.offset();
      const double z = twin.plant_quality(x, shifted) + noise_sd * v;
      watch.restart();
      controller.observe(x, u, z);
      elapsed += watch.seconds();
      const std::string_view dropped = controller.dropped_measurement();
      if (!dropped.empty()) {
        ++result.dropped_measurements;
        note_first_fallback(result, t, "measurement dropped", dropped);
      }
      without_twin = fell_back.empty() && dropped.empty() ? 0 : without_twin + 1;
      trouble = dropped.empty() ? fell_back : dropped;

      result.z(t) = z;
      result.z_star(t) = twin.plant_optimal_quality(x);
      result.control.col(t) = u;
      result.offset.col(t) = drift.offset();
      controller.offset_estimate(result.estimate.col(t));
      result.trace_p(t) = controller.offset_covariance_trace();
      result.q_evaluations(t) =
          static_cast<double>(CaseTwin::evaluations_on_this_thread() - evaluations_before);
      result.seconds(t) = elapsed;
    } catch (const std::exception& failure) {
      if (caused_by_twin_failure(failure)) {
        // Not the controller's doing: no result (the study runs the episode again later).
        throw TwinFailureError("twin", fmt::format("{} run {} step {}: {}", result.controller,
                                                   result.run, t, failure.what()));
      }
      // A controller that cannot go on (a non-finite estimate, a covariance that cannot be
      // factored) has lost the offset as surely as a diverged one.
      result.failure = failure.what();
      if (result.diverged_at < 0) result.diverged_at = t;
      break;
    }
    if (without_twin >= config.twin_failure_streak) {
      throw TwinFailureError(
          "twin", fmt::format("{} run {} step {}: the controller could not use its twin at {} "
                              "assemblies in a row (twin_failure_streak); the last: {}",
                              result.controller, result.run, t, without_twin, trouble));
    }
    if (observer) observer(t, result, controller);
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

// Checks what run_episode and make_episode_controller share.
void require_runnable(const CaseTwin& twin, const ExperimentConfig& config,
                      const ControllerSpec& controller, Index run) {
  require_valid("config", config);
  if (run < 0) {
    throw InvalidArgumentError("run", fmt::format("run: is {}; rule: must be >= 0", run));
  }
  const Index d = twin.control_dimension();
  const Index candidates =
      config.candidate_count(controller.kind == ControllerSpec::Kind::per_component ? 1 : d);
  if (controller.uses_w() && candidates > ExperimentConfig::max_candidates) {
    throw InvalidArgumentError(
        "candidates",
        fmt::format("candidates: {} per assembly for {} at d = {}; rule: must be <= {} (set "
                    "candidate_cap, or --candidates)",
                    candidates, controller.label(), d, ExperimentConfig::max_candidates));
  }
}

EpisodeSetup episode_setup(const CaseTwin& twin, const ExperimentConfig& config, Index run) {
  return {
      .twin = &twin,
      .config = &config,
      .run = RandomStream(config.seed).substream("run").substream(static_cast<std::uint64_t>(run))};
}

}  // namespace
}  // namespace detail

AnyController make_episode_controller(const CaseTwin& twin, const ExperimentConfig& config,
                                      const ControllerSpec& controller, Index run) {
  detail::require_runnable(twin, config, controller, run);
  return detail::make_controller(detail::episode_setup(twin, config, run), controller);
}

bool caused_by_twin_failure(const std::exception& error) {
  if (dynamic_cast<const ExternalTwinError*>(&error) != nullptr) return true;
  try {
    std::rethrow_if_nested(error);
  } catch (const std::exception& nested) {
    return caused_by_twin_failure(nested);
  } catch (...) {
  }
  return false;
}

EpisodeResult run_episode(const CaseTwin& twin, const ExperimentConfig& config,
                          const ControllerSpec& controller, Index run) {
  return run_episode(twin, config, controller, run, EpisodeStepObserver{});
}

EpisodeResult run_episode(const CaseTwin& twin, const ExperimentConfig& config,
                          const ControllerSpec& controller, Index run,
                          const EpisodeStepObserver& observer) {
  detail::require_runnable(twin, config, controller, run);
  const Index available = std::ssize(twin.assemblies());
  if (config.assemblies > available) {
    throw InvalidArgumentError(
        "assemblies", fmt::format("assemblies: is {}; rule: must be <= the twin's {} assemblies",
                                  config.assemblies, available));
  }
  const Index d = twin.control_dimension();
  const detail::EpisodeSetup setup = detail::episode_setup(twin, config, run);
  const std::vector<AssemblyId> order = detail::production_order(
      twin.assemblies(), config.assemblies, setup.run.substream("assembly_order"));

  EpisodeResult result;
  result.group = config.group_name();
  result.controller = controller.label();
  result.run = run;
  result.run_seed = setup.run.seed();
  result.assemblies = order;
  detail::size_result(result, d, config.assemblies);
  AnyController episode_controller = detail::make_controller(setup, controller);
  if (d == 1) {
    detail::simulate<1>(episode_controller, setup, order, result, observer);
  } else if (d == 3) {
    detail::simulate<3>(episode_controller, setup, order, result, observer);
  } else {
    detail::simulate<Dynamic>(episode_controller, setup, order, result, observer);
  }
  assess_lost(result);
  return result;
}

}  // namespace twincal
