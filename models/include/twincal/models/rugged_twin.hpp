#pragma once
/// @file
/// `RuggedTwin`: a non-smooth, multi-modal analytic twin with an exactly known optimum, to stress
/// controllers and optimizers that assume a smooth, unimodal Q:
///   Q(x, u) = z*(x) + Σ_k [ s |e_k| + c (1 − cos(2π e_k / λ)) ],   e = u − a(x),
/// with z*(x) = sqrt(q0(x)) and q0, a from an AnalyticAssemblySet. Both terms are ≥ 0 and vanish
/// only at e = 0, so u0(x) = a(x) and z*(x) are exact. The |e_k| kink makes Q non-differentiable
/// at the optimum; the ripple adds local minima near e_k ≈ mλ whenever 2πc/λ > s.

#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/analytic_assembly_set.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/exact_optimum_twin.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

struct RuggedTwinOptions {
  AnalyticAssemblyOptions assemblies;
  double slope = 1.0;       ///< s: the |e_k| kink
  double ripple = 0.05;     ///< c: amplitude of the ripple
  double wavelength = 0.1;  ///< λ: period of the ripple

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem({rule::nested("assemblies", assemblies),
                          rule::non_negative_finite("slope", slope),
                          rule::non_negative_finite("ripple", ripple),
                          rule::positive_finite("wavelength", wavelength)});
  }
};

/// Q(x, u) = sqrt(q0(x)) + Σ_k [ s |e_k| + c (1 − cos(2π e_k / λ)) ]: RuggedTwin's shape.
struct RuggedShape {
  double slope;       ///< s
  double ripple;      ///< c
  double wavenumber;  ///< 2π / λ

  template <typename A, typename U>
  [[nodiscard]] double quality(double q0, const A& a, const U& control) const {
    double q = std::sqrt(q0);  // z*(x)
    for (Index k = 0; k < control.size(); ++k) {
      const double e = control(k) - a(k);
      q += slope * std::abs(e) + ripple * (1.0 - std::cos(wavenumber * e));
    }
    return q;
  }
};

/// The rugged twin (see the file comment): an ExactOptimumTwin, Q(x, u), the batch and the
/// optimum u0(x) = a(x) with z*(x) = sqrt(q0(x)) included.
class RuggedTwin : public ExactOptimumTwin<RuggedShape> {
 public:
  /// Draws the assemblies from `stream` (substream "assemblies").
  /// @throws InvalidArgumentError when the options are inconsistent.
  RuggedTwin(const RuggedTwinOptions& options, const RandomStream& stream)
      : ExactOptimumTwin{draw_assemblies(options, stream),
                         RuggedShape{.slope = options.slope,
                                     .ripple = options.ripple,
                                     .wavenumber = 2.0 * std::numbers::pi / options.wavelength}} {}
};

static_assert(TwinWithOptimum<RuggedTwin>);

}  // namespace twincal
