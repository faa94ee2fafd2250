#pragma once
/// @file
/// `KinkNonlinearity`: the kinks of a solver's active sets, RuggedTwin's |e| term moved into the
/// deviations. Each key point gains
///   r_i ← r_i + s κ_i |S_i e − t_i|,    e = u − a(x), S_i ~ N(0, I), κ_i ~ N(0, 1),
///   t_i ~ U(−½, ½), s = strength ≥ 0,
/// so Q is continuous with kinks on hyperplanes that pass within about ½ of the affine optimum.
/// Q²'s departure from a quadratic peaks near s = 1 (at larger s the |·|² terms dominate, and
/// they are quadratic).

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/deviation_nonlinearity.hpp"

namespace twincal {

class KinkNonlinearity {
 public:
  /// Draws S (m × d), κ and t (m each) from `stream`.
  /// @throws InvalidArgumentError unless strength is finite and >= 0.
  KinkNonlinearity(Index key_points, Index dimension, double strength, const RandomStream& stream)
      : directions_(key_points, dimension), coefficients_(key_points), offsets_(key_points) {
    RandomStream draws = nonlinearity_draws(
        stream, name(), strength, std::numeric_limits<double>::max(), "must be finite and >= 0");
    draws.fill_normal(directions_);
    draws.fill_normal(coefficients_);
    coefficients_ *= strength;
    for (double& t : offsets_) t = draws.uniform() - 0.5;
  }

  static constexpr std::string_view name() { return "kink"; }

  void apply(const Eigen::Ref<const VectorX>& /*control*/, const Eigen::Ref<const VectorX>& error,
             const Eigen::Ref<const VectorX>& /*moved*/, Eigen::Ref<VectorX> deviations) const {
    for (Index i = 0; i < deviations.size(); ++i) {
      deviations(i) += coefficients_(i) * std::abs(directions_.row(i).dot(error) - offsets_(i));
    }
  }

 private:
  MatrixX directions_;    // S
  VectorX coefficients_;  // s κ
  VectorX offsets_;       // t
};

}  // namespace twincal
