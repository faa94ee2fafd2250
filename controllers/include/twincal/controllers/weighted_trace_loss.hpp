#pragma once
/// @file
/// `WeightedTraceLoss`: the weighted exploration loss the paper proposes in Sec. 4,
/// L_explore(u) = (1/d)·sqrt(tr(W P⁺(u))) with a diagonal W ≥ 0, so that the uncertainty of
/// locators that matter more to Q counts more. W comes from the user or from the twin's
/// sensitivity (see sensitivity_weights.hpp). With W = I it is TraceLoss.

#include <cmath>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

class WeightedTraceLoss {
 public:
  /// The diagonal of W: finite, >= 0, not all zero.
  /// @throws NonFiniteError, InvalidArgumentError naming the entry.
  explicit WeightedTraceLoss(VectorX weights) : weights_(std::move(weights)) {
    require_finite("weights", weights_);
    for (Index i = 0; i < weights_.size(); ++i) {
      require_non_negative(fmt::format("weights({})", i), weights_(i));
    }
    if (!(weights_.sum() > 0.0)) {
      throw InvalidArgumentError("weights",
                                 "weights: all entries are 0; rule: at least one "
                                 "weight must be > 0");
    }
  }

  [[nodiscard]] const VectorX& weights() const noexcept { return weights_; }

  /// (1/d)·sqrt(Σ_i W_ii P⁺_ii).
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError (negative result).
  template <typename Derived>
  [[nodiscard]] double operator()(const Eigen::MatrixBase<Derived>& posterior_covariance) const {
    require_square("posterior_covariance", posterior_covariance);
    require_dimension("posterior_covariance", posterior_covariance.rows(), weights_.size(), "rows");
    require_finite("posterior_covariance", posterior_covariance);
    const double weighted_trace = weights_.dot(posterior_covariance.diagonal());
    require_non_negative("tr(W posterior_covariance)", weighted_trace);
    return std::sqrt(weighted_trace) / static_cast<double>(weights_.size());
  }

 private:
  VectorX weights_;
};

}  // namespace twincal
