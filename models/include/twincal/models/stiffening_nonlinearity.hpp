#pragma once
/// @file
/// `StiffeningNonlinearity`: a compliant part that stiffens under large fixture adjustments. Each
/// key point gains a term quadratic in the control itself (not in its error: the stiffening comes
/// from how far the fixture is moved from nominal),
///   r_i ← r_i + s κ_i (S_i u)²,       S_i ~ N(0, I/d), κ_i ~ N(0, 1), s = strength ≥ 0,
/// so Q² is a smooth quartic in u.

#include <cmath>
#include <limits>
#include <string_view>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/deviation_nonlinearity.hpp"

namespace twincal {

class StiffeningNonlinearity {
 public:
  /// Draws S (m × d) and κ (m) from `stream`.
  /// @throws InvalidArgumentError unless strength is finite and >= 0.
  StiffeningNonlinearity(Index key_points, Index dimension, double strength,
                         const RandomStream& stream)
      : directions_(key_points, dimension), coefficients_(key_points) {
    RandomStream draws = nonlinearity_draws(
        stream, name(), strength, std::numeric_limits<double>::max(), "must be finite and >= 0");
    draws.fill_normal(directions_);
    directions_ /= std::sqrt(std::sqrt(static_cast<double>(dimension)));
    draws.fill_normal(coefficients_);
    coefficients_ *= strength;
  }

  static constexpr std::string_view name() { return "stiffening"; }

  void apply(const Eigen::Ref<const VectorX>& control, const Eigen::Ref<const VectorX>& /*error*/,
             const Eigen::Ref<const VectorX>& /*moved*/, Eigen::Ref<VectorX> deviations) const {
    for (Index i = 0; i < deviations.size(); ++i) {
      const double projection = directions_.row(i).dot(control);
      deviations(i) += coefficients_(i) * projection * projection;
    }
  }

 private:
  MatrixX directions_;    // S
  VectorX coefficients_;  // s κ
};

}  // namespace twincal
