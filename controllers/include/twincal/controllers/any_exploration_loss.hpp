#pragma once
/// @file
/// `AnyExplorationLoss`: the exploration loss of eq. (12) chosen at run time — the paper's
/// trace, the weighted trace of Sec. 4, log-det (D-optimal) or the largest eigenvalue
/// (E-optimal) — one type for the w-controller, so a loss ablation does not multiply its
/// instantiations. All share the scale σ/√d for P⁺ = σ²I (exploration_loss.hpp).
/// `make_exploration_loss` builds the loss an ExplorationKind names.

#include <concepts>
#include <type_traits>
#include <utility>
#include <variant>

#include <Eigen/Core>

#include "twincal/controllers/exploration_kind.hpp"
#include "twincal/controllers/log_det_loss.hpp"
#include "twincal/controllers/max_eigenvalue_loss.hpp"
#include "twincal/controllers/trace_loss.hpp"
#include "twincal/controllers/weighted_trace_loss.hpp"
#include "twincal/core/eigen.hpp"

namespace twincal {

class AnyExplorationLoss {
 public:
  using Variant = std::variant<TraceLoss, WeightedTraceLoss, LogDetLoss, MaxEigenvalueLoss>;

  /// The paper's trace loss.
  AnyExplorationLoss() = default;
  explicit AnyExplorationLoss(Variant loss) : loss_(std::move(loss)) {}

  template <typename Derived>
  [[nodiscard]] double operator()(const Eigen::MatrixBase<Derived>& posterior_covariance) const {
    return std::visit([&](const auto& loss) { return loss(posterior_covariance); }, loss_);
  }

  [[nodiscard]] const Variant& loss() const noexcept { return loss_; }

 private:
  Variant loss_{TraceLoss{}};
};

/// The `kind` loss. `weights()` gives the weighted trace's diagonal of W and is called for that
/// kind only: where W comes from (the user, or a sweep of the twin's sensitivity over its
/// assemblies, sensitivity_weights.hpp) is the caller's, and costs nothing for the other kinds.
/// @throws what `weights()` throws; WeightedTraceLoss's errors for its W.
template <typename Weights>
requires std::invocable<Weights&> && std::convertible_to<std::invoke_result_t<Weights&>, VectorX>
[[nodiscard]] AnyExplorationLoss make_exploration_loss(ExplorationKind kind, Weights&& weights) {
  switch (kind) {
    case ExplorationKind::weighted_trace:
      return AnyExplorationLoss(WeightedTraceLoss(weights()));
    case ExplorationKind::log_det:
      return AnyExplorationLoss(LogDetLoss{});
    case ExplorationKind::max_eigenvalue:
      return AnyExplorationLoss(MaxEigenvalueLoss{});
    case ExplorationKind::trace:
      break;
  }
  return AnyExplorationLoss(TraceLoss{});
}

}  // namespace twincal
