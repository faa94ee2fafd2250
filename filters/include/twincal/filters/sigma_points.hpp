#pragma once
/// @file
/// `SigmaPoints<N, M>`: a weighted point set standing in for a Gaussian (the paper's S_t with
/// weights W(s_t) in eq. (11)), the weighted moments that the unscented transform takes of it,
/// and `draw_sigma_points`, which asks a scheme for the set of N(x, L Lᵀ).

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/sigma_point_scheme.hpp"

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

/// The sigma points of `scheme` for N(mean, lower·lowerᵀ), with their weights.
/// @throws DimensionMismatchError (lower not n × n), InvalidArgumentError (the scheme does not
///         admit dimension n).
template <SigmaPointScheme Scheme, int N>
[[nodiscard]] SigmaPoints<N, Scheme::points_at_compile_time(N)> draw_sigma_points(
    const Scheme& scheme, const Vector<N>& mean, const SquareMatrix<N>& lower) {
  const Index n = mean.size();
  require_shape("lower", lower, n, n);
  const Index m = scheme.num_points(n);
  SigmaPoints<N, Scheme::points_at_compile_time(N)> set{
      Matrix<N, Scheme::points_at_compile_time(N)>(n, m),
      Vector<Scheme::points_at_compile_time(N)>(m), Vector<Scheme::points_at_compile_time(N)>(m)};
  scheme.weights(n, set.mean_weights, set.covariance_weights);
  scheme.generate(mean, lower, set.points);
  return set;
}

}  // namespace twincal
