#pragma once
/// @file
/// `MerweScaledSigmaPoints`: the scaled unscented transform of van der Merwe (2004), the
/// points S_t of the paper's UKF (Sec. 2.3.1, eq. (11)) and of filterpy's MerweScaledSigmaPoints.
///
/// λ = α²(n + κ) − n, c = √(n + λ);
/// points: x, x + c·L_k (k = 1..n), x − c·L_k (k = 1..n), L the lower Cholesky factor of P;
/// weights: Wm0 = λ/(n + λ), Wc0 = Wm0 + 1 − α² + β, Wm_i = Wc_i = 1/(2(n + λ)).

#include <cmath>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/symmetric_pairs.hpp"

namespace twincal {

class MerweScaledSigmaPoints {
 public:
  static constexpr int degree = 3;
  static constexpr bool is_symmetric = true;

  [[nodiscard]] static constexpr int points_at_compile_time(int n) noexcept {
    return size_sum(size_product(2, n), 1);
  }

  /// All three parameters are required: α > 0 spreads the points (small α keeps them close to
  /// the mean), β ≥ 0 weights the centre for the covariance (2 is optimal for Gaussians), κ is
  /// the secondary scaling (0 or 3 − n are usual).
  /// @throws NonFiniteError, InvalidArgumentError naming the parameter.
  MerweScaledSigmaPoints(double alpha, double beta, double kappa)
      : alpha_(alpha), beta_(beta), kappa_(kappa) {
    require_finite("alpha", alpha);
    require_finite("beta", beta);
    require_finite("kappa", kappa);
    require_positive("alpha", alpha);
    require_non_negative("beta", beta);
  }

  [[nodiscard]] double alpha() const noexcept { return alpha_; }
  [[nodiscard]] double beta() const noexcept { return beta_; }
  [[nodiscard]] double kappa() const noexcept { return kappa_; }

  /// λ = α²(n + κ) − n.
  [[nodiscard]] double lambda(Index n) const noexcept {
    const double dn = static_cast<double>(n);
    return alpha_ * alpha_ * (dn + kappa_) - dn;
  }

  [[nodiscard]] Index num_points(Index n) const noexcept { return 2 * n + 1; }

  /// @throws InvalidArgumentError unless n + κ > 0 (so that n + λ = α²(n + κ) > 0).
  void weights(Index n, Eigen::Ref<VectorX> mean_weights,
               Eigen::Ref<VectorX> covariance_weights) const {
    require_admissible(n);
    require_dimension("mean_weights", mean_weights.size(), num_points(n));
    require_dimension("covariance_weights", covariance_weights.size(), num_points(n));
    const double lam = lambda(n);
    const double spread = static_cast<double>(n) + lam;
    mean_weights.setConstant(0.5 / spread);
    covariance_weights.setConstant(0.5 / spread);
    mean_weights(0) = lam / spread;
    covariance_weights(0) = lam / spread + 1.0 - alpha_ * alpha_ + beta_;
  }

  template <typename Mean, typename Lower, typename Points>
  void generate(const Eigen::MatrixBase<Mean>& mean, const Eigen::MatrixBase<Lower>& lower,
                Eigen::MatrixBase<Points>& points) const {
    const Index n = mean.size();
    const double c = std::sqrt(static_cast<double>(n) + lambda(n));
    points.col(0) = mean;
    write_symmetric_pairs(mean, lower, c, 1, points);
  }

 private:
  void require_admissible(Index n) const {
    const double spread = static_cast<double>(n) + kappa_;
    if (spread > 0.0) return;
    throw InvalidArgumentError(
        "kappa", fmt::format("kappa: n + kappa is {} (n = {}, kappa = {}); rule: must be > 0 so "
                             "that n + lambda = alpha^2 (n + kappa) > 0",
                             spread, n, kappa_));
  }

  double alpha_;
  double beta_;
  double kappa_;
};

}  // namespace twincal
