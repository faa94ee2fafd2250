#pragma once
/// @file
/// `Sobol`: the Sobol' low-discrepancy sequence (Sobol' 1967, the paper's ref. [30]) with Joe &
/// Kuo's direction numbers for up to 21201 dimensions, in Gray-code order (Antonov & Saleev
/// 1979) with first point 0, as SciPy's `qmc.Sobol` and Boost.Random's `sobol` (which skips the
/// zero point) generate it. The paper draws its candidate controls from this sequence mapped to
/// N(û*, P) (Sec. 2.3.2, eq. (14)); see GaussianTransform and draw_candidates.
///
/// Coordinate j of point k is x_kj = 2^-B · (g_1 v_j1 ⊕ g_2 v_j2 ⊕ …), g = k ⊕ (k >> 1) the Gray
/// code of k and v_ji = m_ji · 2^(B−i) the direction numbers (B = `bits`). Consecutive points
/// differ by one direction number, so a batch costs one XOR and one conversion per coordinate.
///
/// Randomizations (`SobolOptions::randomization`), all seeded and reproducible:
/// - `linear_matrix_scramble`: a random lower-triangular binary matrix with unit diagonal per
///   coordinate applied to the digits, then a random digital shift (Matoušek 1998; SciPy's
///   default scrambling). Costs nothing per point: it is folded into the direction numbers.
/// - `owen`: nested uniform scrambling (Owen 1995): digit i is flipped by a random bit that
///   depends on the dimension and on all the digits before it. The random bits are a hash of
///   (seed, dimension, digit prefix), so the B-level permutation tree is never stored.
/// Both preserve the (t, m, s)-net structure, so every 2^m-aligned block stays balanced.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/samplers/balance_check.hpp"

namespace twincal {

/// How a Sobol sequence is randomized.
enum class SobolRandomization {
  none,                    ///< the plain sequence (bit-identical to SciPy, scramble=False)
  linear_matrix_scramble,  ///< random linear matrix scramble + digital shift
  owen,                    ///< Owen's nested uniform scrambling
};

[[nodiscard]] constexpr std::string_view to_string(SobolRandomization r) noexcept {
  switch (r) {
    case SobolRandomization::none:
      return "none";
    case SobolRandomization::linear_matrix_scramble:
      return "linear_matrix_scramble";
    case SobolRandomization::owen:
      return "owen";
  }
  return "unknown";
}

struct SobolOptions {
  SobolRandomization randomization = SobolRandomization::none;
  /// Seed of the randomization (ignored by `none`).
  std::uint64_t seed = 0;
  /// Resolution: coordinates are multiples of 2^-bits and the sequence has 2^bits points.
  /// At most 52, so every point converts to a double exactly.
  int bits = 32;
  /// What a fill or discard that breaks the power-of-two balance property does.
  BalanceCheck balance = BalanceCheck::warn;
  /// Receives balance warnings; empty: standard error.
  WarningHandler warning_handler{};

  [[nodiscard]] std::optional<std::string> validate() const;
};

/// The Sobol' sequence as a Sampler (see the file comment).
class Sobol {
 public:
  using Options = SobolOptions;

  /// Largest supported dimension (Joe & Kuo's table).
  static constexpr Index max_dimension = 21201;
  /// Largest supported `bits`.
  static constexpr int max_bits = 52;

  /// Throws InvalidArgumentError unless 1 <= dimension <= max_dimension and the options are
  /// valid.
  explicit Sobol(Index dimension, SobolOptions options = {});

  [[nodiscard]] Index dimension() const noexcept { return dimension_; }
  [[nodiscard]] const SobolOptions& options() const noexcept { return options_; }
  /// Index of the next point.
  [[nodiscard]] std::uint64_t position() const noexcept { return position_; }
  /// Number of points in the sequence, 2^bits.
  [[nodiscard]] std::uint64_t size() const noexcept { return std::uint64_t{1} << options_.bits; }

  /// Draws a new randomization from `value` (stored as options().seed) and restarts at point 0.
  void seed(std::uint64_t value);

  /// Skips `count` points in O(bits · d) (Gray-code jump). Subject to the balance check: the
  /// skipped points must be an aligned power-of-two block. Throws InvalidArgumentError if the
  /// sequence would run past size() points.
  void discard(std::uint64_t count);

  /// Moves to point `position` (at most size()) in O(bits · d), whatever the current position
  /// and without the balance check: restoring a saved position() (controller snapshots) is not
  /// a draw. Throws InvalidArgumentError past size(); nothing changes then.
  void seek(std::uint64_t position);

  /// Fills the d × count matrix with the next count points (one per column). Throws
  /// DimensionMismatchError unless rows == dimension(), InvalidArgumentError if the sequence
  /// would run past size() points or (BalanceCheck::refuse) the batch is not an aligned
  /// power-of-two block; nothing changes when it throws.
  void fill(Eigen::Ref<MatrixX> points);

  /// Direction number i (0-based; v_(i+1) in the file comment) of coordinate j, after any linear
  /// matrix scramble.
  [[nodiscard]] std::uint64_t direction(Index j, int i) const;

 private:
  void randomize();
  void jump_to(std::uint64_t position);
  void require_available(std::string_view argument, std::uint64_t count) const;
  [[nodiscard]] std::uint64_t owen_scramble(std::uint64_t x, std::uint64_t key) const noexcept;

  Index dimension_;
  SobolOptions options_;
  double scale_;                           // 2^-bits
  std::vector<std::uint64_t> plain_;       // unscrambled directions, bits × d, direction-major
  std::vector<std::uint64_t> directions_;  // directions in use (scrambled for the linear matrix)
  std::vector<std::uint64_t> shift_;       // digital shift per coordinate (zero unless scrambled)
  std::vector<std::uint64_t> owen_keys_;   // per-coordinate hash keys (Owen only)
  std::vector<std::uint64_t> state_;       // integer coordinates of the point at position_
  std::uint64_t position_ = 0;
};

}  // namespace twincal
