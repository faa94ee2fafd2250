#pragma once
/// @file
/// `MaxEigenvalueLoss`: E-optimal exploration, the longest axis of the posterior uncertainty
/// ellipsoid, on the common scale of exploration_loss.hpp: sqrt(λ_max(P⁺)) / √d.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

struct MaxEigenvalueLoss {
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError (asymmetric),
  ///         NotPositiveDefiniteError (a negative eigenvalue).
  template <typename Derived>
  [[nodiscard]] double operator()(const Eigen::MatrixBase<Derived>& posterior_covariance) const {
    // Filters leave round-off asymmetry in P⁺ (filterpy does not symmetrize): allow it.
    require_positive_definite("posterior_covariance", posterior_covariance,
                              /*allow_semidefinite=*/true, /*symmetry_tolerance=*/1e-9);
    const double lambda_max = eigenvalue_range(posterior_covariance).second;
    const auto d = static_cast<double>(posterior_covariance.rows());
    return std::sqrt(std::max(lambda_max, 0.0)) / std::sqrt(d);
  }
};

}  // namespace twincal
