#pragma once
/// @file
/// `NoNonlinearity`: the affine deviations as they are, so Q² is exactly a quadratic in u (the
/// RmsQuadraticTwin's shape, key_point_twin.hpp).

#include <string_view>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal {

struct NoNonlinearity {
  /// The common constructor of the nonlinearities (key points m, locators d, strength, stream);
  /// nothing to draw.
  NoNonlinearity(Index /*key_points*/, Index /*dimension*/, double /*strength*/,
                 const RandomStream& /*stream*/) {}
  NoNonlinearity() = default;

  static constexpr std::string_view name() { return "none"; }
  void apply(const Eigen::Ref<const VectorX>& /*control*/,
             const Eigen::Ref<const VectorX>& /*error*/, const Eigen::Ref<const VectorX>& /*moved*/,
             Eigen::Ref<VectorX> /*deviations*/) const {}
};

}  // namespace twincal
