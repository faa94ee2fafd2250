#include "twincal/experiments/episode_runner.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "episode_simulation.hpp"
#include "twincal/controllers/individualized_controller.hpp"
#include "twincal/controllers/nominal_controller.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/julier_sigma_points.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/simplex_sigma_points.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"

namespace twincal {
namespace detail {

// Instantiated in episodes_merwe.cpp, episodes_cubature.cpp and episodes_other_schemes.cpp.
extern template void run_filtered<1, MerweScaledSigmaPoints>(const EpisodeSetup&,
                                                             const ControllerSpec&,
                                                             const MerweScaledSigmaPoints&,
                                                             EpisodeResult&);
extern template void run_filtered<3, MerweScaledSigmaPoints>(const EpisodeSetup&,
                                                             const ControllerSpec&,
                                                             const MerweScaledSigmaPoints&,
                                                             EpisodeResult&);
extern template void run_filtered<Dynamic, MerweScaledSigmaPoints>(const EpisodeSetup&,
                                                                   const ControllerSpec&,
                                                                   const MerweScaledSigmaPoints&,
                                                                   EpisodeResult&);
extern template void run_filtered<1, SphericalRadialSigmaPoints>(const EpisodeSetup&,
                                                                 const ControllerSpec&,
                                                                 const SphericalRadialSigmaPoints&,
                                                                 EpisodeResult&);
extern template void run_filtered<3, SphericalRadialSigmaPoints>(const EpisodeSetup&,
                                                                 const ControllerSpec&,
                                                                 const SphericalRadialSigmaPoints&,
                                                                 EpisodeResult&);
extern template void run_filtered<Dynamic, SphericalRadialSigmaPoints>(
    const EpisodeSetup&, const ControllerSpec&, const SphericalRadialSigmaPoints&, EpisodeResult&);
extern template void run_filtered<Dynamic, JulierSigmaPoints>(const EpisodeSetup&,
                                                              const ControllerSpec&,
                                                              const JulierSigmaPoints&,
                                                              EpisodeResult&);
extern template void run_filtered<Dynamic, FifthDegreeCubatureSigmaPoints>(
    const EpisodeSetup&, const ControllerSpec&, const FifthDegreeCubatureSigmaPoints&,
    EpisodeResult&);
extern template void run_filtered<Dynamic, SimplexSigmaPoints>(const EpisodeSetup&,
                                                               const ControllerSpec&,
                                                               const SimplexSigmaPoints&,
                                                               EpisodeResult&);

extern template void run_active<1>(const EpisodeSetup&, EpisodeResult&);
extern template void run_active<3>(const EpisodeSetup&, EpisodeResult&);
extern template void run_active<Dynamic>(const EpisodeSetup&, EpisodeResult&);
extern template void run_per_component<1>(const EpisodeSetup&, const ControllerSpec&,
                                          EpisodeResult&);
extern template void run_per_component<3>(const EpisodeSetup&, const ControllerSpec&,
                                          EpisodeResult&);
extern template void run_per_component<Dynamic>(const EpisodeSetup&, const ControllerSpec&,
                                                EpisodeResult&);

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

// Episodes whose controller needs no filter; N only selects the drift's vector type, so that
// every controller of a run computes δu*_t with the same arithmetic.
template <int N>
void run_unfiltered(const EpisodeSetup& setup, const ControllerSpec& spec, EpisodeResult& result) {
  if (spec.kind == ControllerSpec::Kind::nominal) {
    // u⁰ for the reference assembly x⁰: the twin's first assembly.
    NominalController<CaseTwin> controller(*setup.twin, setup.twin->assemblies().front());
    simulate<N>(controller, setup, result);
  } else {
    IndividualizedController<CaseTwin> controller(*setup.twin);
    simulate<N>(controller, setup, result);
  }
}

template <int N>
void run_with_dimension(const EpisodeSetup& setup, const ControllerSpec& spec,
                        EpisodeResult& result) {
  if (!spec.estimates()) {
    run_unfiltered<N>(setup, spec, result);
    return;
  }
  if (spec.kind == ControllerSpec::Kind::active) {
    run_active<N>(setup, result);
    return;
  }
  if (spec.kind == ControllerSpec::Kind::per_component) {
    run_per_component<N>(setup, spec, result);
    return;
  }
  const ExperimentConfig& config = *setup.config;
  switch (config.filter) {
    case FilterScheme::merwe:
      run_filtered<N>(setup, spec, MerweScaledSigmaPoints(config.alpha, config.beta, config.kappa),
                      result);
      return;
    case FilterScheme::cubature:
      run_filtered<N>(setup, spec, SphericalRadialSigmaPoints{}, result);
      return;
    default:
      break;
  }
  // The ablation-only schemes exist for dynamic d; their fixed-size twins would only cost build
  // time.
  if constexpr (N == Dynamic) {
    switch (config.filter) {
      case FilterScheme::julier:
        run_filtered<Dynamic>(setup, spec, JulierSigmaPoints(config.kappa), result);
        return;
      case FilterScheme::fifth_degree:
        run_filtered<Dynamic>(setup, spec, FifthDegreeCubatureSigmaPoints{}, result);
        return;
      case FilterScheme::simplex:
        run_filtered<Dynamic>(setup, spec, SimplexSigmaPoints{}, result);
        return;
      default:
        break;
    }
  } else {
    // Same dispatch, at dynamic size.
    if (config.filter == FilterScheme::julier || config.filter == FilterScheme::fifth_degree ||
        config.filter == FilterScheme::simplex) {
      run_with_dimension<Dynamic>(setup, spec, result);
    }
  }
}

}  // namespace
}  // namespace detail

EpisodeResult run_episode(const CaseTwin& twin, const ExperimentConfig& config,
                          const ControllerSpec& controller, Index run) {
  require_valid("config", config);
  if (run < 0) {
    throw InvalidArgumentError("run", fmt::format("run: is {}; rule: must be >= 0", run));
  }
  const Index available = std::ssize(twin.assemblies());
  if (config.assemblies > available) {
    throw InvalidArgumentError(
        "assemblies", fmt::format("assemblies: is {}; rule: must be <= the twin's {} assemblies",
                                  config.assemblies, available));
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
  detail::EpisodeSetup setup;
  setup.twin = &twin;
  setup.config = &config;
  setup.run = RandomStream(config.seed).substream("run").substream(static_cast<std::uint64_t>(run));
  setup.order = detail::production_order(twin.assemblies(), config.assemblies,
                                         setup.run.substream("assembly_order"));

  EpisodeResult result;
  result.group = config.group_name();
  result.controller = controller.label();
  result.run = run;
  result.run_seed = setup.run.seed();
  result.assemblies = setup.order;
  detail::size_result(result, d, config.assemblies);
  if (d == 1) {
    detail::run_with_dimension<1>(setup, controller, result);
  } else if (d == 3) {
    detail::run_with_dimension<3>(setup, controller, result);
  } else {
    detail::run_with_dimension<Dynamic>(setup, controller, result);
  }
  return result;
}

}  // namespace twincal
