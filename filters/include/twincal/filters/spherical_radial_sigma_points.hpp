#pragma once
/// @file
/// `SphericalRadialSigmaPoints`: the third-degree spherical-radial cubature rule of Arasaratnam
/// and Haykin (2009), the points of the cubature Kalman filter (filterpy's CKF).
///
/// points: x + √n·L_k, then x − √n·L_k (k = 1..n), L the lower Cholesky factor of P;
/// weights: 1/(2n) each, for the mean and the covariance.

#include <cmath>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/symmetric_pairs.hpp"

namespace twincal {

class SphericalRadialSigmaPoints {
 public:
  static constexpr int degree = 3;
  static constexpr bool is_symmetric = true;

  [[nodiscard]] static constexpr int points_at_compile_time(int n) noexcept {
    return size_product(2, n);
  }

  [[nodiscard]] Index num_points(Index n) const noexcept { return 2 * n; }

  /// @throws InvalidArgumentError unless n >= 1.
  void weights(Index n, Eigen::Ref<VectorX> mean_weights,
               Eigen::Ref<VectorX> covariance_weights) const {
    require_positive("n", static_cast<double>(n));
    require_dimension("mean_weights", mean_weights.size(), num_points(n));
    require_dimension("covariance_weights", covariance_weights.size(), num_points(n));
    mean_weights.setConstant(1.0 / static_cast<double>(2 * n));
    covariance_weights.setConstant(1.0 / static_cast<double>(2 * n));
  }

  template <typename Mean, typename Lower, typename Points>
  void generate(const Eigen::MatrixBase<Mean>& mean, const Eigen::MatrixBase<Lower>& lower,
                Eigen::MatrixBase<Points>& points) const {
    const Index n = mean.size();
    const double c = std::sqrt(static_cast<double>(n));
    write_symmetric_pairs(mean, lower, c, 0, points);
  }
};

}  // namespace twincal
