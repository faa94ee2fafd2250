#pragma once
/// @file
/// `FifthDegreeCubatureSigmaPoints`: Stroud's fifth-degree rule for the Gaussian (as used by the
/// high-degree cubature Kalman filter of Jia, Xin and Cheng, 2013): 2n² + 1 points that
/// integrate every polynomial of total degree <= 5 exactly, where the unscented and third-degree
/// cubature rules stop at 3.
///
/// With L the lower Cholesky factor of P and s_k its columns:
/// - x, weight 2/(n + 2);
/// - x ± √(n + 2)·s_k (k = 1..n), weight (4 − n)/(2(n + 2)²) (negative for n > 4);
/// - x ± √((n + 2)/2)·(s_k ± s_l) (k < l), weight 1/(n + 2)².
/// Mean and covariance weights are equal. The point count grows as 2n², so fixed sizes are meant
/// for small n (the largest fixed-size set must fit Eigen's stack allocation limit).

#include <cmath>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

class FifthDegreeCubatureSigmaPoints {
 public:
  static constexpr int degree = 5;
  static constexpr bool is_symmetric = true;

  [[nodiscard]] static constexpr int points_at_compile_time(int n) noexcept {
    return n == Dynamic ? Dynamic : 2 * n * n + 1;
  }

  [[nodiscard]] Index num_points(Index n) const noexcept { return 2 * n * n + 1; }

  /// @throws InvalidArgumentError unless n >= 1.
  void weights(Index n, Eigen::Ref<VectorX> mean_weights,
               Eigen::Ref<VectorX> covariance_weights) const {
    require_positive("n", static_cast<double>(n));
    require_dimension("mean_weights", mean_weights.size(), num_points(n));
    require_dimension("covariance_weights", covariance_weights.size(), num_points(n));
    const double np2 = static_cast<double>(n + 2);
    for (Eigen::Ref<VectorX>* w : {&mean_weights, &covariance_weights}) {
      (*w)(0) = 2.0 / np2;
      w->segment(1, 2 * n).setConstant((4.0 - static_cast<double>(n)) / (2.0 * np2 * np2));
      w->tail(2 * n * (n - 1)).setConstant(1.0 / (np2 * np2));
    }
  }

  template <typename Mean, typename Lower, typename Points>
  void generate(const Eigen::MatrixBase<Mean>& mean, const Eigen::MatrixBase<Lower>& lower,
                Eigen::MatrixBase<Points>& points) const {
    const Index n = mean.size();
    const double axis = std::sqrt(static_cast<double>(n + 2));
    const double pair = std::sqrt(0.5 * static_cast<double>(n + 2));
    points.col(0) = mean;
    for (Index k = 0; k < n; ++k) {
      points.col(1 + k) = mean + axis * lower.col(k);
      points.col(1 + n + k) = mean - axis * lower.col(k);
    }
    Index j = 1 + 2 * n;
    for (Index k = 0; k < n; ++k) {
      for (Index l = k + 1; l < n; ++l) {
        points.col(j++) = mean + pair * (lower.col(k) + lower.col(l));
        points.col(j++) = mean - pair * (lower.col(k) + lower.col(l));
        points.col(j++) = mean + pair * (lower.col(k) - lower.col(l));
        points.col(j++) = mean - pair * (lower.col(k) - lower.col(l));
      }
    }
  }
};

}  // namespace twincal
