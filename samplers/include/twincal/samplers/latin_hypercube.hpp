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
#include "twincal/samplers/random_stream_sampler.hpp"

namespace twincal {

struct LatinHypercubeOptions {
  std::uint64_t seed = 0;
  /// Put every point at the centre of its cell instead of uniformly inside it.
  bool centered = false;

  [[nodiscard]] std::optional<std::string> validate() const { return std::nullopt; }
};

/// How LatinHypercube draws: one design per fill (see the file comment). Its permutation buffer
/// is rebuilt by every fill, so the stream stays the sampler's whole state.
class LatinHypercubeDesigns {
 public:
  using Options = LatinHypercubeOptions;

  /// Fills the d × n matrix with one new design of n points.
  void fill(RandomStream& stream, const Options& options, Eigen::Ref<MatrixX> points);
  /// Draws and drops a design of `count` points.
  void discard(RandomStream& stream, const Options& options, Index dimension, std::uint64_t count);

 private:
  std::vector<Index> permutation_;  // reused between fills
};

/// Latin hypercube designs as a Sampler (see the file comment).
using LatinHypercube = RandomStreamSampler<LatinHypercubeDesigns>;

}  // namespace twincal
