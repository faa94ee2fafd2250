#pragma once
/// @file
/// The `Sampler` concept: an engine of points in the unit cube [0, 1)^d, in the style of
/// Boost.Random's quasi-random engines: a dimension, a seed, discard, and a batch fill.
/// Points are the columns of the filled matrix (d × count, column-major), so one point is
/// contiguous and a Gaussian transform is one product L·Z.
///
/// twincal's samplers (Sobol, Halton, PseudoRandom, LatinHypercube) also share a constructor
/// `S(Index dimension, typename S::Options options)`, the options carrying the seed, so a class
/// template taking a sampler policy can build one for its dimension: `ConstructibleSampler`.

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

/// A Sampler that can be built from a dimension and its options aggregate.
template <typename S>
concept ConstructibleSampler = Sampler<S> && std::constructible_from<S, Index, typename S::Options>;

}  // namespace twincal
