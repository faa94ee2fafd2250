#pragma once
/// @file
/// `LatinHypercube`: Latin hypercube designs (McKay, Beckman & Conover 1979). A fill of n points
/// is one design: in every coordinate j the n points occupy the n cells [i/n, (i+1)/n) once
/// each, x_kj = (π_j(k) + U_kj) / n with independent uniform permutations π_j and U_kj ~ U[0, 1)
/// (or U_kj = 1/2, `centered`). Unlike a sequence, a design is a property of the whole batch:
/// two fills are two independent designs, and discard(n) draws and drops an n-point design so
/// the stream stays reproducible.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal {

struct LatinHypercubeOptions {
  std::uint64_t seed = 0;
  /// Put every point at the centre of its cell instead of uniformly inside it.
  bool centered = false;

  [[nodiscard]] std::optional<std::string> validate() const { return std::nullopt; }
};

/// Latin hypercube designs as a Sampler (see the file comment).
class LatinHypercube {
 public:
  using Options = LatinHypercubeOptions;

  /// Throws InvalidArgumentError unless dimension >= 1.
  explicit LatinHypercube(Index dimension, LatinHypercubeOptions options = {});

  [[nodiscard]] Index dimension() const noexcept { return dimension_; }
  [[nodiscard]] const LatinHypercubeOptions& options() const noexcept { return options_; }

  /// Restarts the stream from `value` (stored as options().seed).
  void seed(std::uint64_t value);
  /// Draws and drops a design of `count` points.
  void discard(std::uint64_t count);
  /// Fills the d × count matrix with one new design of count points. Throws
  /// DimensionMismatchError unless rows == dimension().
  void fill(Eigen::Ref<MatrixX> points);

  /// The stream the designs come from: the sampler's whole state (controller snapshots save
  /// it; the permutation buffer is rebuilt by every fill).
  [[nodiscard]] const RandomStream& stream() const noexcept { return stream_; }
  /// Continues from `stream`, a stream() saved earlier: the next designs are the ones the saved
  /// sampler would have drawn. options().seed becomes the stream's seed.
  void set_stream(const RandomStream& stream) {
    options_.seed = stream.seed();
    stream_ = stream;
  }

 private:
  Index dimension_;
  LatinHypercubeOptions options_;
  RandomStream stream_;
  std::vector<Index> permutation_;  // reused between fills
};

}  // namespace twincal
