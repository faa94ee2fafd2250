#pragma once
/// @file
/// `Halton`: the Halton sequence (Halton 1960), coordinate j the radical inverse of the point
/// index in the j-th prime base b_j, x_kj = Σ_i a_i(k) b_j^-(i+1) for k = Σ_i a_i(k) b_j^i. The
/// sum is accumulated exactly as SciPy's `qmc.Halton` does (digit by digit from the least
/// significant, with b2r ← b2r / b), so unscrambled points are bit-identical to SciPy's; the
/// first point is 0.
///
/// Random-permutation scrambling (`HaltonOptions::scramble`): the digit a_i in base b_j is
/// replaced by π_ji(a_i), with an independent uniformly random permutation π_ji of {0, …, b_j−1}
/// for every coordinate j and digit position i, over the ⌈54 / log2 b_j⌉ − 1 digit positions
/// a double resolves (SciPy's scheme; the trailing zero digits are permuted too, so each point
/// is uniform on [0, 1)). Memory: Σ_j b_j · (⌈54 / log2 b_j⌉ − 1) integers.
///
/// Halton points have no power-of-two balance property; any batch size is fine.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"

namespace twincal {

struct HaltonOptions {
  /// Random-permutation scrambling of the digits.
  bool scramble = false;
  /// Seed of the permutations (ignored without scrambling).
  std::uint64_t seed = 0;

  [[nodiscard]] std::optional<std::string> validate() const { return std::nullopt; }
};

/// The Halton sequence as a Sampler (see the file comment).
class Halton {
 public:
  using Options = HaltonOptions;

  /// Largest supported dimension (the bases are the first max_dimension primes).
  static constexpr Index max_dimension = 100000;

  /// Throws InvalidArgumentError unless 1 <= dimension <= max_dimension.
  explicit Halton(Index dimension, HaltonOptions options = {});

  [[nodiscard]] Index dimension() const noexcept { return static_cast<Index>(bases_.size()); }
  [[nodiscard]] const HaltonOptions& options() const noexcept { return options_; }
  /// Index of the next point.
  [[nodiscard]] std::uint64_t position() const noexcept { return position_; }
  /// The prime base of each coordinate.
  [[nodiscard]] const std::vector<std::uint32_t>& bases() const noexcept { return bases_; }

  /// Draws new permutations from `value` (stored as options().seed) and restarts at point 0.
  void seed(std::uint64_t value);
  /// Skips `count` points (O(1)). Throws InvalidArgumentError if the index would overflow.
  void discard(std::uint64_t count);
  /// Moves to point `position` (O(1)): restores a saved position() (controller snapshots).
  void seek(std::uint64_t position) noexcept { position_ = position; }
  /// Fills the d × count matrix with the next count points. Throws DimensionMismatchError unless
  /// rows == dimension().
  void fill(Eigen::Ref<MatrixX> points);

 private:
  void draw_permutations();

  HaltonOptions options_;
  std::vector<std::uint32_t> bases_;
  // Scrambling: coordinate j uses digit_count_[j] permutations of bases_[j] entries each,
  // stored consecutively from permutation_offset_[j].
  std::vector<std::uint32_t> digit_count_;
  std::vector<std::size_t> permutation_offset_;
  std::vector<std::uint32_t> permutations_;
  std::uint64_t position_ = 0;
};

}  // namespace twincal
