#pragma once
/// @file
/// `AnalyticTwinBase`: what the analytic twins (ExactOptimumTwin, so RmsQuadraticTwin and
/// RuggedTwin, and KeyPointTwin) share, written once: their AnalyticAssemblySet, the Twin members
/// it answers (dimension, locator names, bounds, assemblies), and the options check and assembly
/// draw that start their construction. Each twin adds its Q.

#include <concepts>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/analytic_assembly_set.hpp"
#include "twincal/models/assembly_id.hpp"

namespace twincal {

/// The assemblies of an analytic twin and the Twin members they answer (see the file comment).
class AnalyticTwinBase {
 public:
  using Assembly = AssemblyId;

  [[nodiscard]] Index control_dimension() const noexcept { return assemblies_.dimension(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept {
    return assemblies_.locator_names();
  }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return assemblies_.lower_bounds(); }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return assemblies_.upper_bounds(); }
  [[nodiscard]] const AnalyticAssemblySet& assembly_set() const noexcept { return assemblies_; }
  [[nodiscard]] std::vector<AssemblyId> assemblies() const { return assemblies_.assemblies(); }

 protected:
  explicit AnalyticTwinBase(AnalyticAssemblySet assemblies) : assemblies_(std::move(assemblies)) {}

  /// Checks a twin's `options` (named "options" in the error), then draws its assemblies from
  /// `options.assemblies` and the substream "assemblies" of `stream`.
  /// @throws InvalidArgumentError when the options are inconsistent.
  template <ValidatableOptions Options>
  requires requires(const Options& options) {
    { options.assemblies } -> std::convertible_to<const AnalyticAssemblyOptions&>;
  }
  [[nodiscard]] static AnalyticAssemblySet draw_assemblies(const Options& options,
                                                           const RandomStream& stream) {
    require_valid("options", options);
    return {options.assemblies, stream.substream("assemblies")};
  }

 private:
  AnalyticAssemblySet assemblies_;
};

}  // namespace twincal
