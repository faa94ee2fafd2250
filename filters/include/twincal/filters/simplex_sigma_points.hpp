#pragma once
/// @file
/// `SimplexSigmaPoints`: the n + 1 points of a regular simplex (Julier 2003), in the form of
/// filterpy's current SimplexSigmaPoints: the fewest points that reproduce a mean and a
/// covariance, at the price of symmetry (third moments are not zero).
///
/// points: x + L·z_j (j = 0..n) with the standardised simplex Z (n × (n + 1), Σ z_j = 0,
/// Z Zᵀ = (n + 1)·I): row 0 is (−c_1, c_1, 0, …), row r ≥ 1 (d = r + 1) has c_d in the first d
/// columns and −d·c_d in column d, with c_d = √((n + 1)/(d(d + 1)));
/// weights: 1/(n + 1) each. (filterpy's `alpha` argument does not enter its points.)

#include <cmath>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

class SimplexSigmaPoints {
 public:
  static constexpr int degree = 2;
  static constexpr bool is_symmetric = false;

  [[nodiscard]] static constexpr int points_at_compile_time(int n) noexcept {
    return size_sum(n, 1);
  }

  [[nodiscard]] Index num_points(Index n) const noexcept { return n + 1; }

  /// @throws InvalidArgumentError unless n >= 1.
  void weights(Index n, Eigen::Ref<VectorX> mean_weights,
               Eigen::Ref<VectorX> covariance_weights) const {
    require_positive("n", static_cast<double>(n));
    require_dimension("mean_weights", mean_weights.size(), num_points(n));
    require_dimension("covariance_weights", covariance_weights.size(), num_points(n));
    mean_weights.setConstant(1.0 / static_cast<double>(n + 1));
    covariance_weights.setConstant(1.0 / static_cast<double>(n + 1));
  }

  template <typename Mean, typename Lower, typename Points>
  void generate(const Eigen::MatrixBase<Mean>& mean, const Eigen::MatrixBase<Lower>& lower,
                Eigen::MatrixBase<Points>& points) const {
    const Index n = mean.size();
    const double np1 = static_cast<double>(n + 1);
    // points = x + Σ_r L.col(r)·Z(r, j), accumulated row by row of Z so nothing is allocated.
    for (Index j = 0; j <= n; ++j) points.col(j) = mean;
    for (Index r = 0; r < n; ++r) {
      const double d = static_cast<double>(r + 1);
      const double c = std::sqrt(np1 / (d * (d + 1.0)));
      if (r == 0) {
        points.col(0) -= c * lower.col(0);
        points.col(1) += c * lower.col(0);
        continue;
      }
      for (Index j = 0; j <= r; ++j) points.col(j) += c * lower.col(r);
      points.col(r + 1) -= d * c * lower.col(r);
    }
  }
};

}  // namespace twincal
