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

class RuggedTwin {
 public:
  using Assembly = AssemblyId;

  /// Draws the assemblies from `stream` (substream "assemblies").
  /// @throws InvalidArgumentError when the options are inconsistent.
  RuggedTwin(const RuggedTwinOptions& options, const RandomStream& stream)
      : assemblies_((require_valid("options", options), options.assemblies),
                    stream.substream("assemblies")),
        slope_(options.slope),
        ripple_(options.ripple),
        wavenumber_(2.0 * std::numbers::pi / options.wavelength) {}

  [[nodiscard]] Index control_dimension() const noexcept { return assemblies_.dimension(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept {
    return assemblies_.locator_names();
  }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return assemblies_.lower_bounds(); }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return assemblies_.upper_bounds(); }
  [[nodiscard]] const AnalyticAssemblySet& assembly_set() const noexcept { return assemblies_; }
  [[nodiscard]] std::vector<AssemblyId> assemblies() const { return assemblies_.assemblies(); }

  /// Q(x, u) = z*(x) + Σ_k [ s |e_k| + c (1 − cos(2π e_k / λ)) ].
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
    require_control(control, control_dimension());
    return evaluate(optimal_quality(assembly), assemblies_.optimum(assembly), control);
  }

  /// out(j) = Q(x, controls.col(j)).
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    require_control_batch(controls, out, control_dimension());
    const double z_star = optimal_quality(assembly);
    const MatrixX::ConstColXpr a = assemblies_.optimum(assembly);
    for (Index j = 0; j < controls.cols(); ++j) out(j) = evaluate(z_star, a, controls.col(j));
  }

  /// u0(x) = a(x).
  [[nodiscard]] VectorX optimum(const AssemblyId& assembly) const {
    return assemblies_.optimum(assembly);
  }

  /// z*(x) = sqrt(q0(x)).
  [[nodiscard]] double optimal_quality(const AssemblyId& assembly) const {
    return std::sqrt(assemblies_.q0(assembly));
  }

 private:
  template <typename A, typename U>
  [[nodiscard]] double evaluate(double z_star, const A& a, const U& control) const {
    double q = z_star;
    for (Index k = 0; k < control.size(); ++k) {
      const double e = control(k) - a(k);
      q += slope_ * std::abs(e) + ripple_ * (1.0 - std::cos(wavenumber_ * e));
    }
    return q;
  }

  AnalyticAssemblySet assemblies_;
  double slope_;
  double ripple_;
  double wavenumber_;
};

static_assert(TwinWithOptimum<RuggedTwin>);

}  // namespace twincal
