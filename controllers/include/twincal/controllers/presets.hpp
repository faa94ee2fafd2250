#pragma once
/// @file
/// Ready-made configurations, one line each, under the names users search for. The paper's
/// w-controller (Sjöberg et al. 2023, Sec. 2.3–2.4) is `PaperController`; an ablation swaps one
/// policy: `CubatureController` (CKF for UKF), `HaltonController` (Halton for Sobol),
/// `LogDetController` (D-optimal for trace), or any LookaheadController<...> you compose.
/// `ActiveController` is the project's own controller, beyond the paper.
///
/// `make_paper_filter` and `make_paper_controller` build them with the paper's settings
/// (Sec. 2.4): Σu = 1e-3·I, σz² = 1e-4 (car body; 1e-6 for the door), δû0 ~ N(0, 1e-3·I),
/// Sobol candidates with QMCPy's default randomization (linear matrix scramble + digital shift),
/// 2^(2+d) of them in a box of half-width 0.1.

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "twincal/controllers/active_controller.hpp"
#include "twincal/controllers/default_controller.hpp"
#include "twincal/controllers/expected_quality.hpp"
#include "twincal/controllers/log_det_loss.hpp"
#include "twincal/controllers/lookahead_controller.hpp"
#include "twincal/controllers/paper_settings.hpp"
#include "twincal/controllers/per_component_controller.hpp"
#include "twincal/controllers/trace_loss.hpp"
#include "twincal/controllers/weighted_trace_loss.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/filters/cubature_kalman_filter.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"
#include "twincal/filters/unscented_kalman_filter.hpp"
#include "twincal/models/quality_feedback.hpp"
#include "twincal/models/random_walk.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/sobol.hpp"

namespace twincal {

/// The paper's estimator: a UKF (van der Merwe's scaled points) over the random-walk offset
/// (eq. 5c) with quality feedback h(δu; x, u) = Q(x, u − δu) (eq. 5b).
template <Twin T, int N = Dynamic>
using PaperFilter = UnscentedKalmanFilter<RandomWalk<N>, QualityFeedback<T, N>>;

/// The same model with the spherical-radial cubature rule (CKF).
template <Twin T, int N = Dynamic>
using CubatureFilter = CubatureKalmanFilter<RandomWalk<N>, QualityFeedback<T, N>>;

/// The paper's w-controller, eqs. (11)–(14): UKF + Sobol + expected quality + trace loss.
template <Twin T, int N = Dynamic>
using PaperController = LookaheadController<PaperFilter<T, N>, Sobol, ExpectedQuality, TraceLoss>;

/// The default controller of eq. (9) with the paper's filter.
template <Twin T, int N = Dynamic>
using PaperDefaultController = DefaultController<PaperFilter<T, N>>;

/// Ablation: CKF instead of UKF.
template <Twin T, int N = Dynamic>
using CubatureController =
    LookaheadController<CubatureFilter<T, N>, Sobol, ExpectedQuality, TraceLoss>;

/// Ablation: Halton instead of Sobol candidates.
template <Twin T, int N = Dynamic>
using HaltonController = LookaheadController<PaperFilter<T, N>, Halton, ExpectedQuality, TraceLoss>;

/// Ablation: D-optimal (log-det) instead of trace exploration.
template <Twin T, int N = Dynamic>
using LogDetController = LookaheadController<PaperFilter<T, N>, Sobol, ExpectedQuality, LogDetLoss>;

/// Ablation: the weighted trace of Sec. 4 instead of the plain trace.
template <Twin T, int N = Dynamic>
using WeightedTraceController =
    LookaheadController<PaperFilter<T, N>, Sobol, ExpectedQuality, WeightedTraceLoss>;

/// Beyond the paper: the active controller (docs/controllers.md) with its default policies —
/// ThompsonProbe, cubature sigma points for a twin that is not quadratic, NLopt for a twin
/// without a known optimum. The CLI's and Python's `active`.
template <Twin T, int N = Dynamic>
using ActiveController = ActiveCalibrationController<T, N>;

/// A filter F (any sigma-point filter over RandomWalk<N> and QualityFeedback<T, N>) for `twin`
/// (which must outlive it) with the paper's settings and the given scheme; δû0 is drawn from
/// `stream.substream("initial_offset")`, so filters made from one stream start alike.
template <typename F, Twin T, typename Scheme>
[[nodiscard]] F make_quality_filter(const T& twin, const RandomStream& stream, Scheme scheme,
                                    const PaperSettings& settings = {}) {
  constexpr int N = F::dimension_at_compile_time;
  require_valid("PaperSettings", settings);
  const Index d = twin.control_dimension();
  RandomStream initial = stream.substream("initial_offset");
  Vector<N> offset(d);
  initial.fill_normal(offset);
  offset *= std::sqrt(settings.initial_variance);
  return F(RandomWalk<N>::isotropic(d, settings.process_variance),
           QualityFeedback<T, N>(twin, settings.measurement_variance), std::move(scheme), offset,
           SquareMatrix<N>::Identity(d, d) * settings.initial_variance);
}

/// The paper's UKF (make_quality_filter with Merwe points α, β, κ from the settings).
template <int N = Dynamic, Twin T>
[[nodiscard]] PaperFilter<T, N> make_paper_filter(const T& twin, const RandomStream& stream,
                                                  const PaperSettings& settings = {}) {
  require_valid("PaperSettings", settings);
  return make_quality_filter<PaperFilter<T, N>>(
      twin, stream, MerweScaledSigmaPoints(settings.alpha, settings.beta, settings.kappa),
      settings);
}

/// The CKF with the paper's settings.
template <int N = Dynamic, Twin T>
[[nodiscard]] CubatureFilter<T, N> make_cubature_filter(const T& twin, const RandomStream& stream,
                                                        const PaperSettings& settings = {}) {
  return make_quality_filter<CubatureFilter<T, N>>(twin, stream, SphericalRadialSigmaPoints{},
                                                   settings);
}

/// The paper's w-controller for `twin`: make_paper_filter plus a Sobol sampler randomized from
/// `stream.substream("candidates")`.
template <int N = Dynamic, Twin T>
[[nodiscard]] PaperController<T, N> make_paper_controller(const T& twin, const RandomStream& stream,
                                                          const LookaheadOptions& options = {},
                                                          const PaperSettings& settings = {}) {
  const std::uint64_t sampler_seed = stream.substream("candidates").seed();
  return PaperController<T, N>(
      make_paper_filter<N>(twin, stream, settings),
      Sobol(twin.control_dimension(),
            {.randomization = SobolRandomization::linear_matrix_scramble, .seed = sampler_seed}),
      options);
}

/// The per-component simplification of Sec. 4 with the paper's w-controller on every locator.
template <Twin T>
using PerComponentPaperController = PerComponentController<T, PaperController<ComponentTwin<T>, 1>>;

/// d one-locator paper controllers for `twin`; component i draws its randomness from
/// `stream.substream("component").substream(i)`.
template <Twin T>
[[nodiscard]] PerComponentPaperController<T> make_per_component_paper_controller(
    const T& twin, const RandomStream& stream, const LookaheadOptions& options = {},
    const PaperSettings& settings = {}) {
  const RandomStream components = stream.substream("component");
  return PerComponentPaperController<T>(twin, [&](const ComponentTwin<T>& view, Index i) {
    return make_paper_controller<1>(view, components.substream(static_cast<std::uint64_t>(i)),
                                    options, settings);
  });
}

}  // namespace twincal
