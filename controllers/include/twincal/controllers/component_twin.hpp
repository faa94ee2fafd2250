#pragma once
/// @file
/// `ComponentTwin<T>`: a one-locator view of a twin for per-component control (the
/// simplification the paper proposes as future work, Sec. 4): Q_i(x, v) = Q(x, c with c_i = v),
/// where c — the controls of all locators as the twin sees them — is a context that the owner
/// (PerComponentController) sets before each use. Its optimum is the i-th entry of the full
/// optimum u0(x), which the owner places in the context with the assembly it belongs to.
///
/// The context is shared (one per owner) and heap-allocated, so views and the filters that refer
/// to them stay valid when the owner moves.

#include <concepts>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/kept_assemblies.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

/// What the components of one PerComponentController share.
template <Twin T>
struct ComponentContext {
  const T* twin = nullptr;
  VectorX controls;                              ///< c: every locator's control in the twin's frame
  std::optional<typename T::Assembly> assembly;  ///< the assembly `optimum` belongs to
  VectorX optimum;                               ///< u0(assembly)
  double optimal_quality = 0.0;                  ///< z*(assembly)
};

template <Twin T>
class ComponentTwin {
 public:
  using Assembly = typename T::Assembly;
  static constexpr bool borrows_assemblies = borrows_assemblies_v<T>;

  /// Locator `index` of the context's twin.
  /// @throws InvalidArgumentError when the index is not a locator of the twin.
  ComponentTwin(std::shared_ptr<ComponentContext<T>> context, Index index)
      : context_(std::move(context)), index_(index) {
    const T& twin = *context_->twin;
    const Index d = twin.control_dimension();
    if (index < 0 || index >= d) {
      throw InvalidArgumentError(
          "index", fmt::format("index: value is {}; rule: must lie in [0, {})", index, d));
    }
    names_ = {twin.locator_names()[static_cast<std::size_t>(index)]};
    lower_ = VectorX::Constant(1, twin.lower_bounds()(index));
    upper_ = VectorX::Constant(1, twin.upper_bounds()(index));
  }

  [[nodiscard]] Index index() const noexcept { return index_; }
  [[nodiscard]] Index control_dimension() const noexcept { return 1; }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept { return names_; }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return lower_; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return upper_; }

  /// Q(x, c with c_i = v).
  [[nodiscard]] double quality(const Assembly& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
    require_control(control, 1);
    VectorX full = context_->controls;
    full(index_) = control(0);
    return context_->twin->quality(assembly, full);
  }

  /// out(j) = Q(x, c with c_i = controls(0, j)), one batch call of the twin.
  void quality_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    require_control_batch(controls, out, 1);
    MatrixX full = context_->controls.replicate(1, controls.cols());
    full.row(index_) = controls.row(0);
    context_->twin->quality_batch(assembly, full, out);
  }

  /// u0(x)_i, from the context.
  /// @throws InvalidArgumentError when the context holds the optimum of another assembly.
  [[nodiscard]] VectorX optimum(const Assembly& assembly) const {
    require_current(assembly);
    return VectorX::Constant(1, context_->optimum(index_));
  }

  /// z*(x), from the context.
  [[nodiscard]] double optimal_quality(const Assembly& assembly) const {
    require_current(assembly);
    return context_->optimal_quality;
  }

 private:
  void require_current(const Assembly& assembly) const {
    bool current = context_->assembly.has_value();
    if constexpr (std::equality_comparable<Assembly>) {
      current = current && assembly == *context_->assembly;
    }
    {
      if (!current) {
        throw InvalidArgumentError(
            "assembly",
            "assembly: is not the one whose optimum the per-component controller "
            "set; rule: components propose only inside their owner's propose");
      }
    }
  }

  std::shared_ptr<ComponentContext<T>> context_;
  Index index_;
  std::vector<std::string> names_;
  VectorX lower_;
  VectorX upper_;
};

}  // namespace twincal
