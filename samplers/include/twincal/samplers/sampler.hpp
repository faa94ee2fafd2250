#pragma once
/// @file
/// The `Sampler` concept: an engine of points in the unit cube [0, 1)^d, in the style of
/// Boost.Random's quasi-random engines: a dimension, a seed, discard, and a batch fill.
/// Points are the columns of the filled matrix (d × count, column-major), so one point is
/// contiguous and a Gaussian transform is one product L·Z.

#include <concepts>
#include <cstdint>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"

namespace twincal {

template <typename S>
concept Sampler = requires(S& sampler, const S& const_sampler, std::uint64_t value,
                           Eigen::Ref<MatrixX> points) {
  /// Number of coordinates d of every point.
  { const_sampler.dimension() } -> std::convertible_to<Index>;
  /// Restart the stream from `value` (the randomization for scrambled or random samplers;
  /// deterministic sequences restart from their first point).
  sampler.seed(value);
  /// Skip `value` points.
  sampler.discard(value);
  /// Fill the d × count matrix with the next count points; rows must equal dimension().
  sampler.fill(points);
};

}  // namespace twincal
