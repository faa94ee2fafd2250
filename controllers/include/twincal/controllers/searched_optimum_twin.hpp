#pragma once
/// @file
/// `SearchedOptimumTwin<Twin>`: a twin whose optimum is not known (a real twin, a key-point twin
/// with contact) made a TwinWithOptimum by searching u0(x) = argmin_u Q(x, u) (eq. 3) and
/// z*(x) = Q(x, u0) once per assembly, at construction, with the Optimizer policy (NLopt's
/// global search and local polish by default). The paper does the same: u0 "by a global
/// optimizer that have run an extensive number of iterations". A twin that offers
/// `search_start(x)` (a good guess, e.g. the optimum of its affine part) has the search polished
/// from there; otherwise from the centre of its box. The evaluations the searches took are kept.

#include <concepts>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/models/kept_assemblies.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

/// A twin with a guess at each assembly's optimum.
template <typename T>
concept TwinWithSearchStart = Twin<T> &&
    requires(const T& twin, const typename T::Assembly& assembly) {
  { twin.search_start(assembly) } -> std::convertible_to<VectorX>;
};

template <Twin T, Optimizer O = NloptOptimizer>
class SearchedOptimumTwin {
 public:
  using Assembly = typename T::Assembly;
  static constexpr bool borrows_assemblies = borrows_assemblies_v<T>;

  /// Takes `twin` and searches the optimum of each of `assemblies` (in order) with `optimizer`.
  /// @throws InvalidArgumentError when `assemblies` is empty; the twin's and the optimizer's
  ///         errors (naming the assembly's position) propagate.
  SearchedOptimumTwin(T twin, std::vector<Assembly> assemblies, O optimizer = O{})
      : twin_(std::move(twin)), assemblies_(std::move(assemblies)) {
    if (assemblies_.empty()) {
      throw InvalidArgumentError("assemblies",
                                 "assemblies: is empty; rule: needs at least one assembly");
    }
    const IndividualOptimum<T, O> search(twin_, std::move(optimizer));
    const Index n = static_cast<Index>(assemblies_.size());
    optima_.resize(twin_.control_dimension(), n);
    optimal_qualities_.resize(n);
    for (Index k = 0; k < n; ++k) {
      const Assembly& assembly = assemblies_[static_cast<std::size_t>(k)];
      VectorX start = 0.5 * (twin_.lower_bounds() + twin_.upper_bounds());
      if constexpr (TwinWithSearchStart<T>) start = twin_.search_start(assembly);
      const IndividualControl found = search.optimize(assembly, start);
      optima_.col(k) = found.control;
      optimal_qualities_(k) = found.quality;
      search_evaluations_ += found.evaluations;
    }
  }

  [[nodiscard]] const T& twin() const noexcept { return twin_; }
  [[nodiscard]] const std::vector<Assembly>& assemblies() const noexcept { return assemblies_; }
  /// Evaluations the searches took, over all assemblies.
  [[nodiscard]] std::uint64_t search_evaluations() const noexcept { return search_evaluations_; }

  [[nodiscard]] Index control_dimension() const { return twin_.control_dimension(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const {
    return twin_.locator_names();
  }
  [[nodiscard]] const VectorX& lower_bounds() const { return twin_.lower_bounds(); }
  [[nodiscard]] const VectorX& upper_bounds() const { return twin_.upper_bounds(); }
  [[nodiscard]] double quality(const Assembly& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
    return twin_.quality(assembly, control);
  }
  void quality_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    twin_.quality_batch(assembly, controls, out);
  }
  /// The wrapped twin's key points, where it has them (TwinWithDeviations).
  [[nodiscard]] Index key_point_count() const requires TwinWithDeviations<T> {
    return twin_.key_point_count();
  }
  void deviations_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const requires TwinWithDeviations<T> {
    twin_.deviations_batch(assembly, controls, out);
  }

  /// u0(x) as searched.
  /// @throws InvalidArgumentError for an assembly that was not searched.
  [[nodiscard]] VectorX optimum(const Assembly& assembly) const {
    return optima_.col(position(assembly));
  }
  /// z*(x) = Q(x, u0(x)) as searched.
  [[nodiscard]] double optimal_quality(const Assembly& assembly) const {
    return optimal_qualities_(position(assembly));
  }

 private:
  [[nodiscard]] Index position(const Assembly& assembly) const {
    for (std::size_t k = 0; k < assemblies_.size(); ++k) {
      if (assemblies_[k] == assembly) return static_cast<Index>(k);
    }
    throw InvalidArgumentError(
        "assembly", "assembly: was not among the assemblies searched; rule: must be one of them");
  }

  T twin_;
  std::vector<Assembly> assemblies_;
  MatrixX optima_;
  VectorX optimal_qualities_;
  std::uint64_t search_evaluations_ = 0;
};

}  // namespace twincal
