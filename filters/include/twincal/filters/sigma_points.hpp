#pragma once
/// @file
/// `SigmaPoints<N, M>`: a weighted point set standing in for a Gaussian (the paper's S_t with
/// weights W(s_t) in eq. (11)), and the weighted moments that the unscented transform takes of
/// it.

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

/// M points of dimension N as the columns of `points`, with mean weights Wm and covariance
/// weights Wc (they differ for the scaled unscented transform).
template <int N, int M>
struct SigmaPoints {
  Matrix<N, M> points;
  Vector<M> mean_weights;
  Vector<M> covariance_weights;

  [[nodiscard]] Index dimension() const noexcept { return points.rows(); }
  [[nodiscard]] Index size() const noexcept { return points.cols(); }

  /// Σ Wm_i χ_i.
  [[nodiscard]] Vector<N> mean() const {
    Vector<N> m = points * mean_weights;
    return m;
  }

  /// Σ Wc_i (χ_i − about)(χ_i − about)ᵀ, the covariance about a given centre (usually mean()).
  [[nodiscard]] SquareMatrix<N> covariance(const Vector<N>& about) const {
    require_dimension("about", about.size(), dimension());
    const Matrix<N, M> centred = points.colwise() - about;
    SquareMatrix<N> p = centred * covariance_weights.asDiagonal() * centred.transpose();
    return p;
  }
};

}  // namespace twincal
