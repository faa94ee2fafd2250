#pragma once
/// @file
/// `AnyExplorationLoss`: the exploration loss of eq. (12) chosen at run time — the paper's
/// trace, the weighted trace of Sec. 4, log-det (D-optimal) or the largest eigenvalue
/// (E-optimal) — one type for the w-controller, so a loss ablation does not multiply its
/// instantiations. All share the scale σ/√d for P⁺ = σ²I (exploration_loss.hpp).

#include <utility>
#include <variant>

#include <Eigen/Core>

#include "twincal/controllers/log_det_loss.hpp"
#include "twincal/controllers/max_eigenvalue_loss.hpp"
#include "twincal/controllers/trace_loss.hpp"
#include "twincal/controllers/weighted_trace_loss.hpp"

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

}  // namespace twincal
