#pragma once
/// @file
/// Symmetrization of covariance matrices. Round-off in P − K S Kᵀ leaves covariances slightly
/// asymmetric; filters symmetrize as a documented option (filterpy does not, so parity runs
/// leave it off).

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

/// Replaces a square `m` by (m + mᵀ)/2 in place, without a temporary (no allocation).
template <typename Derived>
void symmetrize(Eigen::MatrixBase<Derived>& m) {
  require_square("m", m);
  for (Index c = 0; c < m.cols(); ++c) {
    for (Index r = c + 1; r < m.rows(); ++r) {
      const double mean = 0.5 * (m(r, c) + m(c, r));
      m(r, c) = mean;
      m(c, r) = mean;
    }
  }
}

/// (m + mᵀ)/2 as a new matrix.
template <typename Derived>
[[nodiscard]] typename Derived::PlainObject symmetrized(const Eigen::MatrixBase<Derived>& m) {
  typename Derived::PlainObject copy(m);
  symmetrize(copy);
  return copy;
}

}  // namespace twincal
