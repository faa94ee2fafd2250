#pragma once
/// @file
/// `draw_candidates`: the paper's candidate controls for the look-ahead minimization, eq. (14)
/// (Sec. 2.3.2): points of a Sampler mapped to N(û*, P) by a GaussianTransform, those outside
/// the box U_t disregarded. With `keep_drawing`, further batches of the same size are drawn
/// until `count` candidates survive or `max_batches` batches have been drawn; a batch of 2^m
/// Sobol points then continues the sequence in aligned blocks, keeping the balance property.
/// The result reports how many points were drawn and how many survived, so a caller sees an
/// incomplete set (a box far out in the tails of N(û*, P)) instead of silently getting fewer
/// candidates.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/samplers/box_set.hpp"
#include "twincal/samplers/gaussian_transform.hpp"
#include "twincal/samplers/sampler.hpp"

namespace twincal {

struct CandidateOptions {
  /// Points per batch and the number of candidates wanted (the paper: 2^(2+d)).
  Index count = 32;
  /// Draw further batches until `count` candidates survive (the paper draws one batch).
  bool keep_drawing = false;
  /// Bound on the batches drawn with keep_drawing.
  Index max_batches = 64;

  [[nodiscard]] std::optional<std::string> validate() const {
    if (count < 1) return fmt::format("count is {}; it must be >= 1", count);
    if (max_batches < 1) return fmt::format("max_batches is {}; it must be >= 1", max_batches);
    return std::nullopt;
  }
};

/// Candidates inside the box, one per column, in drawing order.
template <int N>
struct CandidateSet {
  Matrix<N, Dynamic> points;
  Index requested = 0;  ///< CandidateOptions::count
  Index drawn = 0;      ///< points taken from the sampler
  Index survived = 0;   ///< drawn points inside the box (points holds min(survived, requested))

  /// True when `requested` candidates survived.
  [[nodiscard]] bool complete() const noexcept { return survived >= requested; }
};

/// Draws candidates (see the file comment). Throws InvalidArgumentError for invalid options and
/// DimensionMismatchError unless sampler, transform and box have one dimension; the sampler is
/// not advanced when it throws before drawing.
template <Sampler S, int N>
[[nodiscard]] CandidateSet<N> draw_candidates(S& sampler, const GaussianTransform<N>& transform,
                                              const BoxSet<N>& box,
                                              const CandidateOptions& options = {}) {
  require_valid("options", options);
  const Index d = transform.dimension();
  require_dimension("sampler", static_cast<Index>(sampler.dimension()), d, "dimension");
  require_dimension("box", box.dimension(), d, "dimension");

  CandidateSet<N> result;
  result.requested = options.count;
  result.points.resize(d, options.count);
  MatrixX uniform(d, options.count);
  Matrix<N, Dynamic> batch(d, options.count);
  const Index batches = options.keep_drawing ? options.max_batches : 1;
  for (Index b = 0; b < batches && result.survived < options.count; ++b) {
    sampler.fill(uniform);
    transform.transform(uniform, batch);
    const Index kept = box.keep_inside(batch);
    const Index stored = std::min(kept, options.count - result.survived);
    result.points.middleCols(result.survived, stored) = batch.leftCols(stored);
    result.drawn += options.count;
    result.survived += kept;
  }
  result.points.conservativeResize(d, std::min(result.survived, options.count));
  return result;
}

}  // namespace twincal
