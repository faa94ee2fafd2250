#pragma once
/// @file
/// `PseudoRandom`: independent uniform points, the Monte Carlo baseline. The engine is
/// RandomStream's std::mt19937_64 (fully specified by the C++ standard); each coordinate takes
/// one 64-bit draw r and is (r >> 11) · 2^-53, so coordinates are multiples of 2^-53 in [0, 1),
/// every platform gives the same points for the same seed, and discard(n) skips exactly n·d
/// draws.

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/samplers/random_stream_sampler.hpp"

namespace twincal {

struct PseudoRandomOptions {
  std::uint64_t seed = 0;

  [[nodiscard]] std::optional<std::string> validate() const { return std::nullopt; }
};

/// How PseudoRandom draws: one engine draw per coordinate (see the file comment).
struct UniformDraws {
  using Options = PseudoRandomOptions;

  /// Fills the d × count matrix with the next count points.
  void fill(RandomStream& stream, const Options& options, Eigen::Ref<MatrixX> points) const;
  /// Skips `count` points (count · d engine draws). Throws InvalidArgumentError if count · d
  /// overflows.
  void discard(RandomStream& stream, const Options& options, Index dimension,
               std::uint64_t count) const;
};

/// Independent U[0, 1)^d points as a Sampler.
using PseudoRandom = RandomStreamSampler<UniformDraws>;

}  // namespace twincal
