#pragma once
/// @file
/// `LocatorSubset<T>`: a twin restricted to chosen locators, the others held at their optimum.
///
/// The paper's experiments let one locator (A, B or C) or three (ABC) drift and be controlled,
/// while the other locators stay at the individualized optimum u0(x) (eq. 3). For a control
/// v ∈ R^k of the chosen locators S, the restricted twin evaluates
///   Q_S(x, v) = Q(x, u),   u_S = v,   u_j = u0_j(x) for j ∉ S,
/// so its optimum is u0_S(x) with the same z*(x) (the full optimum is feasible for it). Of a
/// TwinWithDeviations it passes the key points' deviations on the same way.
/// The subset refers to the full twin, which must outlive it.

#include <algorithm>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/models/kept_assemblies.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

/// Checks a choice of locators of a twin with `dimension` locators: not empty, each index in
/// [0, dimension), none repeated.
/// @throws InvalidArgumentError naming the offending entry and the rule.
inline void require_locator_indices(std::span<const Index> locators, Index dimension) {
  if (locators.empty()) {
    throw InvalidArgumentError("locators", "locators: is empty; rule: must name >= 1 locator");
  }
  for (std::size_t i = 0; i < locators.size(); ++i) {
    const Index k = locators[i];
    if (k < 0 || k >= dimension) {
      throw InvalidArgumentError(
          "locators",
          fmt::format("locators: entry {} is {}; rule: must lie in [0, {}]", i, k, dimension - 1));
    }
    if (std::find(locators.begin(), locators.begin() + static_cast<std::ptrdiff_t>(i), k) !=
        locators.begin() + static_cast<std::ptrdiff_t>(i)) {
      throw InvalidArgumentError(
          "locators",
          fmt::format("locators: entry {} repeats locator {}; rule: each locator at most once", i,
                      k));
    }
  }
}

template <TwinWithOptimum T>
class LocatorSubset {
 public:
  using Assembly = typename T::Assembly;
  static constexpr bool borrows_assemblies = borrows_assemblies_v<T>;

  /// Restricts `twin` to the locators with the given indices (in that order).
  /// @throws InvalidArgumentError when `locators` is empty, repeats an index or names an index
  ///         outside [0, d).
  LocatorSubset(const T& twin, std::vector<Index> locators)
      : twin_(&twin), locators_(std::move(locators)) {
    require_locator_indices(locators_, twin.control_dimension());
    const auto& names = twin.locator_names();
    lower_bounds_.resize(size());
    upper_bounds_.resize(size());
    for (Index i = 0; i < size(); ++i) {
      const Index k = locators_[static_cast<std::size_t>(i)];
      names_.push_back(names[static_cast<std::size_t>(k)]);
      lower_bounds_(i) = twin.lower_bounds()(k);
      upper_bounds_(i) = twin.upper_bounds()(k);
    }
  }

  /// Restricts `twin` to the locators named `names` (e.g. {"A", "B", "C"}).
  /// @throws InvalidArgumentError naming a locator the twin does not have.
  [[nodiscard]] static LocatorSubset by_name(const T& twin, std::span<const std::string> names) {
    const auto& all = twin.locator_names();
    std::vector<Index> locators;
    for (const std::string& name : names) {
      const auto it = std::find(all.begin(), all.end(), name);
      if (it == all.end()) {
        throw InvalidArgumentError(
            "names", fmt::format("names: locator \"{}\" is unknown; rule: must be one of [{}]",
                                 name, fmt::join(all, ", ")));
      }
      locators.push_back(static_cast<Index>(it - all.begin()));
    }
    return LocatorSubset(twin, std::move(locators));
  }

  [[nodiscard]] Index control_dimension() const noexcept { return size(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept { return names_; }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return lower_bounds_; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return upper_bounds_; }
  /// Indices of the chosen locators in the full twin.
  [[nodiscard]] const std::vector<Index>& locators() const noexcept { return locators_; }
  [[nodiscard]] const T& full_twin() const noexcept { return *twin_; }

  /// The full control: u0(x) with the chosen locators set to `control`.
  [[nodiscard]] VectorX embed(const Assembly& assembly,
                              const Eigen::Ref<const VectorX>& control) const {
    require_control(control, size());
    VectorX full = twin_->optimum(assembly);
    for (Index i = 0; i < size(); ++i) full(locator(i)) = control(i);
    return full;
  }

  /// Q_S(x, v) = Q(x, embed(x, v)).
  [[nodiscard]] double quality(const Assembly& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
    return twin_->quality(assembly, embed(assembly, control));
  }

  /// One batch call of the full twin for all columns.
  void quality_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    require_control_batch(controls, out, size());
    twin_->quality_batch(assembly, embed_batch(assembly, controls), out);
  }

  /// m, the full twin's key points, where it answers their deviations.
  [[nodiscard]] Index key_point_count() const requires TwinWithDeviations<T> {
    return twin_->key_point_count();
  }

  /// out.col(j) = r(x, embed(x, controls.col(j))): one batch call of the full twin.
  void deviations_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const requires TwinWithDeviations<T> {
    require_deviations_batch(controls, out, size(), twin_->key_point_count());
    twin_->deviations_batch(assembly, embed_batch(assembly, controls), out);
  }

  /// u0_S(x).
  [[nodiscard]] VectorX optimum(const Assembly& assembly) const {
    const VectorX full = twin_->optimum(assembly);
    VectorX restricted(size());
    for (Index i = 0; i < size(); ++i) restricted(i) = full(locator(i));
    return restricted;
  }

  /// z*(x), unchanged by the restriction.
  [[nodiscard]] double optimal_quality(const Assembly& assembly) const {
    return twin_->optimal_quality(assembly);
  }

 private:
  // The full controls: u0(x) in every column, the chosen locators set from `controls`.
  [[nodiscard]] MatrixX embed_batch(const Assembly& assembly,
                                    const Eigen::Ref<const MatrixX>& controls) const {
    MatrixX full = twin_->optimum(assembly).replicate(1, controls.cols());
    for (Index i = 0; i < size(); ++i) full.row(locator(i)) = controls.row(i);
    return full;
  }

  [[nodiscard]] Index size() const noexcept { return std::ssize(locators_); }
  [[nodiscard]] Index locator(Index i) const noexcept {
    return locators_[static_cast<std::size_t>(i)];
  }

  const T* twin_;
  std::vector<Index> locators_;
  std::vector<std::string> names_;
  VectorX lower_bounds_;
  VectorX upper_bounds_;
};

}  // namespace twincal
