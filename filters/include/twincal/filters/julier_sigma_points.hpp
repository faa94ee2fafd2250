#pragma once
/// @file
/// `JulierSigmaPoints`: the original unscented transform of Julier and Uhlmann (1997), as in
/// filterpy's JulierSigmaPoints.
///
/// points: x, x + √(n + κ)·L_k, x − √(n + κ)·L_k (k = 1..n), L the lower Cholesky factor of P;
/// weights (mean = covariance): W0 = κ/(n + κ), W_i = 1/(2(n + κ)).
/// κ = 3 − n matches the Gaussian's fourth moments along the axes.

#include <cmath>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/symmetric_pairs.hpp"

namespace twincal {

class JulierSigmaPoints {
 public:
  static constexpr int degree = 3;
  static constexpr bool is_symmetric = true;

  [[nodiscard]] static constexpr int points_at_compile_time(int n) noexcept {
    return size_sum(size_product(2, n), 1);
  }

  /// κ is required (filterpy's default is 0, 3 − n is Julier's choice).
  /// @throws NonFiniteError when κ is not finite.
  explicit JulierSigmaPoints(double kappa) : kappa_(kappa) { require_finite("kappa", kappa); }

  [[nodiscard]] double kappa() const noexcept { return kappa_; }

  [[nodiscard]] Index num_points(Index n) const noexcept { return 2 * n + 1; }

  /// @throws InvalidArgumentError unless n + κ > 0.
  void weights(Index n, Eigen::Ref<VectorX> mean_weights,
               Eigen::Ref<VectorX> covariance_weights) const {
    const double spread = static_cast<double>(n) + kappa_;
    if (!(spread > 0.0)) {
      throw InvalidArgumentError(
          "kappa", fmt::format("kappa: n + kappa is {} (n = {}, kappa = {}); rule: must be > 0",
                               spread, n, kappa_));
    }
    require_dimension("mean_weights", mean_weights.size(), num_points(n));
    require_dimension("covariance_weights", covariance_weights.size(), num_points(n));
    mean_weights.setConstant(0.5 / spread);
    mean_weights(0) = kappa_ / spread;
    covariance_weights.setConstant(0.5 / spread);
    covariance_weights(0) = kappa_ / spread;
  }

  template <typename Mean, typename Lower, typename Points>
  void generate(const Eigen::MatrixBase<Mean>& mean, const Eigen::MatrixBase<Lower>& lower,
                Eigen::MatrixBase<Points>& points) const {
    const Index n = mean.size();
    const double c = std::sqrt(static_cast<double>(n) + kappa_);
    points.col(0) = mean;
    write_symmetric_pairs(mean, lower, c, 1, points);
  }

 private:
  double kappa_;
};

}  // namespace twincal
