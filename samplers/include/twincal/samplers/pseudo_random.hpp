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

namespace twincal {

struct PseudoRandomOptions {
  std::uint64_t seed = 0;

  [[nodiscard]] std::optional<std::string> validate() const { return std::nullopt; }
};

/// Independent U[0, 1)^d points as a Sampler.
class PseudoRandom {
 public:
  using Options = PseudoRandomOptions;

  /// Throws InvalidArgumentError unless dimension >= 1.
  explicit PseudoRandom(Index dimension, PseudoRandomOptions options = {});

  [[nodiscard]] Index dimension() const noexcept { return dimension_; }
  [[nodiscard]] const PseudoRandomOptions& options() const noexcept { return options_; }

  /// Restarts the stream from `value` (stored as options().seed).
  void seed(std::uint64_t value);
  /// Skips `count` points (count · d engine draws). Throws InvalidArgumentError if count · d
  /// overflows.
  void discard(std::uint64_t count);
  /// Fills the d × count matrix with the next count points. Throws DimensionMismatchError unless
  /// rows == dimension().
  void fill(Eigen::Ref<MatrixX> points);

  /// The stream the points come from: the sampler's whole state (controller snapshots save it).
  [[nodiscard]] const RandomStream& stream() const noexcept { return stream_; }
  /// Continues from `stream`, a stream() saved earlier: the next points are the ones the saved
  /// sampler would have drawn. options().seed becomes the stream's seed.
  void set_stream(const RandomStream& stream) {
    options_.seed = stream.seed();
    stream_ = stream;
  }

 private:
  Index dimension_;
  PseudoRandomOptions options_;
  RandomStream stream_;
};

}  // namespace twincal
