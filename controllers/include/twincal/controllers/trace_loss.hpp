#pragma once
/// @file
/// `TraceLoss`: the paper's exploration loss, eq. (12): L_explore = (1/d)·sqrt(tr P⁺), where P⁺
/// is the posterior covariance the filter would have after measuring at the candidate control.

#include <cmath>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

struct TraceLoss {
  /// (1/d)·sqrt(tr P⁺) for the d × d previewed posterior covariance.
  /// @throws DimensionMismatchError (not square or empty), NonFiniteError,
  ///         InvalidArgumentError (negative trace: not a covariance).
  template <typename Derived>
  [[nodiscard]] double operator()(const Eigen::MatrixBase<Derived>& posterior_covariance) const {
    require_square("posterior_covariance", posterior_covariance);
    if (posterior_covariance.rows() == 0) {
      throw DimensionMismatchError(
          "posterior_covariance", "posterior_covariance: is 0x0; rule: must be at least 1x1", 0, 1);
    }
    require_finite("posterior_covariance", posterior_covariance);
    const double trace = posterior_covariance.trace();
    require_non_negative("trace(posterior_covariance)", trace);
    return std::sqrt(trace) / static_cast<double>(posterior_covariance.rows());
  }
};

}  // namespace twincal
