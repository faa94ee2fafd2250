#pragma once
/// @file
/// `LogDetLoss`: D-optimal exploration, the volume of the posterior uncertainty ellipsoid.
/// Computed from log det P⁺ (stable where det underflows) and reported on the common scale of
/// exploration_loss.hpp: det(P⁺)^(1/(2d)) / √d, which is σ/√d for P⁺ = σ²I. The transform is
/// monotone, so with w = 1 the choice is exactly the D-optimal one.

#include <cmath>

#include <Eigen/Core>

#include "twincal/core/cholesky.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

struct LogDetLoss {
  /// @throws DimensionMismatchError, NonFiniteError, NotPositiveDefiniteError (a singular or
  ///         indefinite P⁺ has no finite log-determinant).
  template <typename Derived>
  [[nodiscard]] double operator()(const Eigen::MatrixBase<Derived>& posterior_covariance) const {
    const CholeskyResult<Derived::RowsAtCompileTime> factored =
        cholesky(posterior_covariance, {}, "posterior_covariance");
    const auto d = static_cast<double>(posterior_covariance.rows());
    return std::exp(factored.factor.log_determinant() / (2.0 * d)) / std::sqrt(d);
  }
};

}  // namespace twincal
